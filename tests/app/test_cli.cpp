// One command-line dialect: every command and subcommand answers --help and -h with
// its usage on standard output and status 0, and refuses an unknown option with an
// InputError (exit 2) before doing any work.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <functional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/errors.h"

namespace morphfem {
namespace {

using Args = std::vector<std::string>;
using Command = std::function<int(const Args&)>;

struct Case {
  std::string name;  // as typed: "robot validate"
  Args prefix;       // the words before the options ({"validate"})
  Command run;
};

std::vector<Case> cases() {
  const MPI_Comm comm = PETSC_COMM_WORLD;
  auto with_comm = [comm](int (*f)(const Args&, MPI_Comm)) { return [f, comm](const Args& a) { return f(a, comm); }; };
  std::vector<Case> out = {
      {"run", {}, with_comm(run_command)},
      {"verify", {}, with_comm(verify_command)},
      {"fit-materials", {}, fit_materials_command},
      {"search", {}, with_comm(search_command)},
  };
  out.push_back({"scene-keys", {}, scene_keys_command});
  for (const char* sub :
       {"validate", "ladder", "spread", "morph", "friction-sweep", "friction-drag", "benchmark", "levels"})
    out.push_back({std::string("robot ") + sub, {sub}, with_comm(robot_command)});
  for (const char* sub : {"pull-tests", "synth-pull", "drag", "friction", "materials", "morphing"})
    out.push_back({std::string("calibrate ") + sub, {sub}, with_comm(calibrate_command)});
  return out;
}

Args with(const Args& prefix, const Args& rest) {
  Args a = prefix;
  a.insert(a.end(), rest.begin(), rest.end());
  return a;
}

TEST(CommandLineDialect, EveryCommandAnswersHelpOnStandardOutput) {
  for (const Case& c : cases()) {
    for (const char* help : {"--help", "-h"}) {
      ::testing::internal::CaptureStdout();
      int status = -1;
      EXPECT_NO_THROW(status = c.run(with(c.prefix, {help}))) << c.name << " " << help;
      const std::string out = ::testing::internal::GetCapturedStdout();
      EXPECT_EQ(status, 0) << c.name << " " << help;
      EXPECT_NE(out.find("usage: morphfem " + c.name), std::string::npos) << c.name << " " << help << ":\n" << out;
    }
  }
}

TEST(CommandLineDialect, EveryCommandRefusesAnUnknownOption) {
  for (const Case& c : cases()) {
    try {
      c.run(with(c.prefix, {"--no-such-option", "1"}));
      ADD_FAILURE() << c.name << " accepted --no-such-option";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--no-such-option"), std::string::npos) << c.name << ": " << e.what();
    }
  }
}

TEST(CommandLineDialect, GroupsListTheirCommandsAndRefuseUnknownOnes) {
  for (auto* group : {robot_command, calibrate_command}) {
    ::testing::internal::CaptureStdout();
    EXPECT_EQ(group({"--help"}, PETSC_COMM_WORLD), 0);
    EXPECT_NE(::testing::internal::GetCapturedStdout().find("usage: morphfem"), std::string::npos);
    EXPECT_THROW(group({"no-such-command"}, PETSC_COMM_WORLD), InputError);
  }
}

}  // namespace
}  // namespace morphfem
