// `morphfem robot spread` (robot/robot_spread.cpp): the --vary parser, the ensemble
// statistics, and one cheap ensemble end to end (the varied key reaches every run).
#include <gtest/gtest.h>
#include <petscsys.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/errors.h"
#include "robot/robot_study.h"
#include "robot/studies.h"
#include "tests/support/temp_dir.h"

using namespace morphfem;

TEST(RobotSpread, VaryIsAKeyAndTwoOrMoreDistinctValues) {
  const auto [key, values] = parse_variation("environment.heading_deg=-1,-0.5,0,0.5,1");
  EXPECT_EQ(key, "environment.heading_deg");
  ASSERT_EQ(values.size(), 5u);
  EXPECT_EQ(values[0], "-1");
  EXPECT_EQ(values[4], "1");
  EXPECT_THROW(parse_variation("environment.heading_deg"), InputError);       // no '='
  EXPECT_THROW(parse_variation("=1,2"), InputError);                          // no key
  EXPECT_THROW(parse_variation("solver.max_step=0.1"), InputError);           // one value is no spread
  EXPECT_THROW(parse_variation("solver.max_step=0.1,0.05,0.1"), InputError);  // repeated value
  try {
    parse_variation("solver.max_step=0.1");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--vary solver.max_step"), std::string::npos) << e.what();
  }
}

TEST(RobotSpread, StatisticsLeaveFailedRunsOut) {
  auto run = [](double v, bool ok) {
    CaseOutcome o;
    o.speed = v;
    o.completed = ok ? 1 : 0;
    return o;
  };
  // Completed: -1, 2, 3, 4 -> mean 2, sum of squares 9 + 0 + 1 + 4 = 14, std sqrt(14/3).
  const SpreadStats s = spread_stats({run(-1, true), run(2, true), run(100, false), run(3, true), run(4, true)});
  EXPECT_EQ(s.n, 4);
  EXPECT_EQ(s.failed, 1);
  EXPECT_EQ(s.forward, 3);
  EXPECT_DOUBLE_EQ(s.mean, 2.0);
  EXPECT_NEAR(s.std, std::sqrt(14.0 / 3.0), 1e-14);
  EXPECT_NEAR(s.standard_error(), std::sqrt(14.0 / 3.0) / 2.0, 1e-14);
  EXPECT_DOUBLE_EQ(s.median, 2.5);  // sorted -1, 2, 3, 4: the two middle ones' mean
  EXPECT_DOUBLE_EQ(s.min, -1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
  const SpreadStats one = spread_stats({run(0.5, true)});
  EXPECT_EQ(one.n, 1);
  EXPECT_TRUE(std::isnan(one.std));
  EXPECT_DOUBLE_EQ(one.median, 0.5);
  const SpreadStats odd = spread_stats({run(-2.3, true), run(-0.9, true), run(-1.0, true)});
  EXPECT_DOUBLE_EQ(odd.median, -1.0);  // the outlier -2.3 moves the mean, not the median
  const SpreadStats none = spread_stats({run(1, false)});
  EXPECT_EQ(none.n, 0);
  EXPECT_TRUE(std::isnan(none.mean));
}

TEST(RobotSpread, BadCommandLinesAreRefused) {
  auto spread = [](const std::string& name, const std::string& vary, const std::string& preset = "voxel",
                   const std::vector<std::string>& levels = {}) {
    SpreadOptions o;
    o.case_name = name;
    o.vary = vary;
    o.preset = preset;
    o.levels = levels;
    return robot_spread(o, PETSC_COMM_WORLD);
  };
  EXPECT_THROW(spread("roll_flat", ""), InputError);  // no --vary
  EXPECT_THROW(spread("no_such_case", "solver.max_step=0.1,0.05"), InputError);
  EXPECT_THROW(spread("roll_flat", "solver.max_step=0.1,0.05", "lattice"), InputError);  // not a preset's name
  EXPECT_THROW(spread("roll_flat", "solver.max_step=0.1,0.05", "physical", {"0"}), InputError);
}

// A lattice-mechanics ensemble keeps the preset's keys, then the --set keys, then the varied value.
TEST(RobotSpread, JobsKeepThePresetsKeysBeforeTheSetAndVariedOnes) {
  const RobotCase base = find_case(lattice_mechanics_cases(MORPHFEM_SOURCE_DIR), "roll_hill15");
  const std::vector<RobotFidelity> levels = {find_robot_fidelity("0.02:2:0.05"), find_robot_fidelity("0")};
  const auto jobs = spread_jobs(base, {"solver.max_step=0.04"}, "environment.heading_deg", {"-1", "1"}, levels);
  ASSERT_EQ(jobs.size(), 4u);
  const auto preset = lattice_mechanics_overrides();
  for (size_t j = 0; j < jobs.size(); ++j) {
    const RobotCase& c = jobs[j].first;
    EXPECT_EQ(c.name, "roll_hill15_v" + std::to_string(j % 2));
    EXPECT_TRUE(c.lattice_mechanics);
    ASSERT_EQ(c.overrides.size(), preset.size() + 2);
    EXPECT_TRUE(std::equal(preset.begin(), preset.end(), c.overrides.begin()));
    EXPECT_EQ(c.overrides[preset.size()], "solver.max_step=0.04");
    EXPECT_EQ(c.overrides.back(), std::string("environment.heading_deg=") + (j % 2 ? "1" : "-1"));
    EXPECT_EQ(jobs[j].second.name, levels[j / 2].name);
  }
}

// The cheapest case (empty schedule, flat, level 0, about 20 s a run) with the largest
// time step varied: each run must have taken its own value (different step counts),
// both must stay put (|v| < 0.005 BL/s, the bound), and the summary's
// statistics must be those of the runs it lists.
TEST(RobotSpread, EnsembleRunsEachValueAndSummarisesThem) {
  const auto dir = temp_dir("robot_spread");
  SpreadOptions o;
  o.case_name = "empty_0deg_0kPa_flat";
  o.vary = "solver.max_step=0.1,0.2";
  o.out_dir = dir.string();
  ASSERT_EQ(robot_spread(o, PETSC_COMM_WORLD), 0);
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  if (rank != 0) return;
  const YAML::Node summary = YAML::LoadFile((dir / "empty_0deg_0kPa_flat_spread.json").string());
  EXPECT_EQ(summary["varied_key"].as<std::string>(), "solver.max_step");
  ASSERT_EQ(summary["levels"].size(), 1u);
  const YAML::Node level = summary["levels"][0];
  EXPECT_EQ(level["n"].as<int>(), 2);
  EXPECT_EQ(level["failed"].as<int>(), 0);
  const YAML::Node runs = level["runs"];
  ASSERT_EQ(runs.size(), 2u);
  EXPECT_EQ(runs[0]["value"].as<std::string>(), "0.1");
  EXPECT_NE(runs[0]["steps"].as<double>(), runs[1]["steps"].as<double>());
  const double v0 = runs[0]["speed_bl_per_s"].as<double>(), v1 = runs[1]["speed_bl_per_s"].as<double>();
  EXPECT_LT(std::abs(v0), 0.005);
  EXPECT_LT(std::abs(v1), 0.005);
  EXPECT_NEAR(level["mean_bl_per_s"].as<double>(), 0.5 * (v0 + v1), 1e-12);
  EXPECT_NEAR(level["std_bl_per_s"].as<double>(), std::abs(v0 - v1) / std::sqrt(2.0), 1e-12);
  for (const auto& r : runs) EXPECT_TRUE(std::filesystem::exists(dir / r["folder"].as<std::string>() / "scene.yaml"));
}
