// The command-line dialect shared by every command (core/command_line.h).
#include <gtest/gtest.h>

#include <sstream>

#include "core/command_line.h"
#include "core/errors.h"

namespace morphfem {
namespace {

CommandLine example() {
  CommandLine cl("morphfem demo", "SCENE.yaml [options]", "Runs a demo.");
  cl.flag("--resume", "continue")
      .value("--out", "DIR", "where results go")
      .value("--level", "N", "a level")
      .repeated("--set", "KEY=VALUE", "sets a key")
      .positionals(1, 1, "SCENE.yaml")
      .petsc_options();
  return cl;
}

std::string error_of(CommandLine cl, const std::vector<std::string>& args) {
  std::ostringstream out;
  try {
    cl.parse(args, out);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(CommandLine, ReadsFlagsValuesRepeatsAndPositionals) {
  CommandLine cl = example();
  std::ostringstream out;
  ASSERT_TRUE(cl.parse({"s.yaml", "--set", "a=1", "--out=o", "--resume", "--set", "b=2", "--level", "3"}, out));
  EXPECT_TRUE(out.str().empty());
  EXPECT_TRUE(cl.has("--resume"));
  EXPECT_EQ(cl.get("--out", "x"), "o");
  EXPECT_EQ(cl.all("--set"), (std::vector<std::string>{"a=1", "b=2"}));
  EXPECT_EQ(cl.positional(), std::vector<std::string>{"s.yaml"});
  EXPECT_EQ(cl.integer("--level", 0, 0, 5), 3);
}

TEST(CommandLine, HelpAnywherePrintsTheDeclaredOptionsAndStops) {
  for (const auto& args : std::vector<std::vector<std::string>>{{"--help"}, {"s.yaml", "-h"}, {"--bogus", "--help"}}) {
    CommandLine cl = example();
    std::ostringstream out;
    EXPECT_FALSE(cl.parse(args, out));
    EXPECT_NE(out.str().find("usage: morphfem demo SCENE.yaml [options]"), std::string::npos);
    EXPECT_NE(out.str().find("--set KEY=VALUE"), std::string::npos);
    EXPECT_NE(out.str().find("sets a key (repeatable)"), std::string::npos);
  }
}

TEST(CommandLine, RefusesMalformedCommandLines) {
  EXPECT_NE(error_of(example(), {"s.yaml", "--bogus"}).find("unknown option '--bogus'"), std::string::npos);
  EXPECT_NE(error_of(example(), {"s.yaml", "--out"}).find("--out needs a value"), std::string::npos);
  EXPECT_NE(error_of(example(), {"s.yaml", "--out", "--resume"}).find("--out needs a value"), std::string::npos);
  EXPECT_NE(error_of(example(), {"s.yaml", "--resume=yes"}).find("takes no value"), std::string::npos);
  EXPECT_NE(error_of(example(), {"s.yaml", "--out", "a", "--out", "b"}).find("more than once"), std::string::npos);
  EXPECT_NE(error_of(example(), {}).find("missing SCENE.yaml"), std::string::npos);
  EXPECT_NE(error_of(example(), {"a.yaml", "b.yaml"}).find("unexpected argument 'b.yaml'"), std::string::npos);
  CommandLine no_petsc("morphfem hw", "", "x");
  EXPECT_NE(error_of(no_petsc, {"-snes_monitor"}).find("unknown option '-snes_monitor'"), std::string::npos);
}

TEST(CommandLine, LetsPetscOptionsAndTheirValuesThrough) {
  CommandLine cl = example();
  std::ostringstream out;
  ASSERT_TRUE(cl.parse({"s.yaml", "-snes_monitor", "-ksp_type", "preonly", "--out", "o", "-log_view"}, out));
  EXPECT_EQ(cl.positional(), std::vector<std::string>{"s.yaml"});
  EXPECT_EQ(cl.get("--out", ""), "o");
  // A PETSc option's bare value is its value: the scene comes first.
  EXPECT_NE(error_of(example(), {"-snes_monitor", "s.yaml"}).find("missing SCENE.yaml"), std::string::npos);
}

TEST(CommandLine, NumbersAreCheckedAgainstTheirRange) {
  CommandLine cl = example();
  std::ostringstream out;
  ASSERT_TRUE(cl.parse({"s.yaml", "--level", "7"}, out));
  EXPECT_THROW(cl.integer("--level", 0, 0, 5), InputError);
  ASSERT_TRUE(cl.parse({"s.yaml", "--level", "2.5"}, out));
  EXPECT_THROW(cl.integer("--level", 0, 0, 5), InputError);
  EXPECT_DOUBLE_EQ(cl.number("--level", 0, 0, 5), 2.5);
  ASSERT_TRUE(cl.parse({"s.yaml", "--level", "two"}, out));
  EXPECT_THROW(cl.number("--level", 0, 0, 5), InputError);
  EXPECT_EQ(split_list("a,b,,c"), (std::vector<std::string>{"a", "b", "c"}));
}

}  // namespace
}  // namespace morphfem
