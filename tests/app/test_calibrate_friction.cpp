// Friction calibration with the simulator: synthetic pull tests made by the drag
// scene with known parameters plus load-cell noise are fitted back (TAO POUNDERS);
// the coefficients come back within 2 % and the 95 % intervals cover them. Also the
// `loads.pulls` scene key and the pull force in the output tables and summary.json.
#include <gtest/gtest.h>
#include <petscsys.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "app/commands.h"
#include "core/calibration_file.h"
#include "core/errors.h"
#include "optim/friction_calibration.h"
#include "sim/drag_scene.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "tests/support/temp_dir.h"

namespace morphfem {
namespace {

TEST(CalibrateFriction, RecoversSimulatedCoefficientsWithinTwoPercent) {
  // Acrylic, uninflated foot (ROBOT.md: 0.38), kinetic 15 % lower, spring 300 N/m.
  DragParameters truth;
  truth.mu_static = 0.38;
  truth.mu_kinetic = 0.323;
  truth.stiffness = 300.0;
  truth.weight_N = 1.2;
  truth.travel = 0.005;
  const DragCurve clean = run_drag_test(truth, PETSC_COMM_WORLD);
  ASSERT_TRUE(clean.completed);
  EXPECT_NEAR(clean.mass_kg * 9.81, truth.weight_N, 1e-9);  // the block's density is W / (g V)
  std::vector<PullCurve> curves;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.003);  // load-cell noise [N]
  for (int repeat = 0; repeat < 3; ++repeat) {
    PullCurve c;
    c.file = "synthetic";
    c.label = "repeat " + std::to_string(repeat);
    c.displacement = clean.displacement;
    c.time = clean.time;
    for (double f : clean.force) c.force.push_back(f + noise(rng));
    curves.push_back(c);
  }
  FrictionFitOptions options;
  options.travel = truth.travel;
  const FrictionFitResult r = fit_friction(curves, truth.weight_N, options, PETSC_COMM_WORLD);
  const auto& f = r.fit;
  ASSERT_EQ(f.names.size(), 3u);
  const std::vector<double> expected = {truth.mu_static, truth.mu_kinetic, truth.stiffness};
  for (size_t j = 0; j < 3; ++j) {
    SCOPED_TRACE(f.names[j]);
    EXPECT_NEAR(f.values[j], expected[j], 0.02 * expected[j]);
    EXPECT_LE(f.ci_low[j], expected[j]);
    EXPECT_GE(f.ci_high[j], expected[j]);
    EXPECT_GT(f.std_error[j], 0.0);
    EXPECT_LT(f.std_error[j], 0.02 * expected[j]);  // the fit is sure to better than 2 %
  }
  // The start (peak / W from the pull-test analysis) is further off than the fit.
  EXPECT_LT(std::abs(f.values[0] - truth.mu_static), std::abs(r.start[0] - truth.mu_static));
  EXPECT_NEAR(f.rms, 0.003, 0.001);  // residuals at the noise level
  EXPECT_TRUE(r.best.completed);
}

TEST(CalibrateFriction, CommandWritesCalibrationFileWithChecksums) {
  const auto dir = temp_dir("morphfem_calibrate_friction");
  for (int s = 1; s <= 2; ++s)
    ASSERT_EQ(calibrate_command(
                  {"drag", "--out", (dir / ("wood_uninflated_0" + std::to_string(s) + ".csv")).string(), "--mu-static",
                   "0.56", "--mu-kinetic", "0.5", "--stiffness", "250", "--travel-mm", "5", "--noise-N", "0.003",
                   "--seed", std::to_string(s), "--surface", "wood", "--foot", "uninflated"},
                  PETSC_COMM_WORLD),
              0);
  ASSERT_EQ(calibrate_command({"friction", "--weight-N", "1", dir.string(), "--travel-mm", "5", "--max-evals", "25",
                               "--out", (dir / "out").string()},
                              PETSC_COMM_WORLD),
            0);
  const Calibration c = read_calibration_file((dir / "out" / "friction_wood_uninflated.yaml").string());
  EXPECT_EQ(c.kind, "friction");
  EXPECT_EQ(c.group.at("surface"), "wood");
  EXPECT_EQ(c.group.at("foot_state"), "uninflated");
  EXPECT_NEAR(c.parameter("mu_static").value, 0.56, 0.02 * 0.56);
  EXPECT_NEAR(c.parameter("mu_kinetic").value, 0.5, 0.02 * 0.5);
  EXPECT_NE(c.command.find("calibrate friction"), std::string::npos);
  ASSERT_EQ(c.data.size(), 2u);
  EXPECT_TRUE(verify_calibration_data(c).empty());
  std::ofstream(c.data[0].file, std::ios::app) << "\n";  // the data changed after the fit
  EXPECT_EQ(verify_calibration_data(c).size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "friction_overlay.csv"));
  // Several groups without --surface/--foot, or none matching, are errors.
  ASSERT_EQ(calibrate_command({"drag", "--out", (dir / "acrylic_inflated_01.csv").string(), "--travel-mm", "5",
                               "--surface", "acrylic", "--foot", "inflated"},
                              PETSC_COMM_WORLD),
            0);
  EXPECT_THROW(calibrate_command({"friction", "--weight-N", "1", dir.string()}, PETSC_COMM_WORLD), InputError);
  EXPECT_THROW(
      calibrate_command({"friction", "--weight-N", "1", dir.string(), "--surface", "gravel"}, PETSC_COMM_WORLD),
      InputError);
  EXPECT_THROW(calibrate_command({"bogus"}, PETSC_COMM_WORLD), InputError);
  std::filesystem::remove_all(dir);
}

TEST(CalibrateFriction, PullsSceneKeyIsParsedCheckedAndReported) {
  const auto dir = temp_dir("morphfem_pull_scene");
  const auto write = [&](const std::string& name, const std::string& text) {
    const auto path = dir / name;
    std::ofstream(path) << text;
    return path.string();
  };
  const std::string base =
      "name: pull\n"
      "geometry: {type: block, lx: 0.02, ly: 0.02, lz: 0.01, mesh_size: 0.01, order: 1}\n"
      "materials:\n  body: {model: neo_hookean, mu: 1e5, kappa: 1e6}\n"
      "boundary:\n  - {surface: xmin, fix: [x, y, z]}\n"
      "solver: {end_time: 1, initial_step: 0.25, max_step: 0.25}\n";
  const std::string good =
      write("good.yaml", base + "loads:\n  pulls:\n    - {surface: xmax, stiffness: 1000, velocity: [1e-3, 0, 0]}\n" +
                             "output: {directory: " + (dir / "out").string() + "}\n");
  const Scene s = read_scene(good);
  ASSERT_EQ(s.pulls.size(), 1u);
  EXPECT_EQ(s.pulls[0].surface, "xmax");
  EXPECT_DOUBLE_EQ(s.pulls[0].stiffness, 1000.0);
  EXPECT_DOUBLE_EQ(s.pulls[0].velocity.x(), 1e-3);
  const SimulationResult r = run_scene(s, PETSC_COMM_WORLD, {true, false});
  ASSERT_TRUE(r.stats.completed);
  // A clamped elastic block pulled 1 mm through a 1000 N/m spring: the spring force
  // k (a - xbar) is below k * 1 mm = 1 N (the block stretches) and positive.
  std::ifstream summary(dir / "out" / "summary.json");
  std::stringstream text;
  text << summary.rdbuf();
  EXPECT_NE(text.str().find("\"pulls\""), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("\"force_N\""), std::string::npos) << text.str();

  EXPECT_THROW(read_scene(write("typo.yaml", base + "loads:\n  pulls:\n    - {surface: xmax, stifness: 1, "
                                                    "velocity: [1, 0, 0]}\n")),
               InputError);
  EXPECT_THROW(read_scene(write("zero.yaml", base + "loads:\n  pulls:\n    - {surface: xmax, stiffness: 1, "
                                                    "velocity: [0, 0, 0]}\n")),
               InputError);
  const Scene unknown = read_scene(
      write("unknown.yaml", base + "loads:\n  pulls:\n    - {surface: nowhere, stiffness: 1, velocity: [1, 0, 0]}\n"));
  EXPECT_THROW(run_scene(unknown, PETSC_COMM_WORLD, {false, false}), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace morphfem
