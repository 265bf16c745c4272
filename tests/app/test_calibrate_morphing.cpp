// The morphing fit end to end on a small scene: a balloon octant filled through a
// valve, quasi-static, so that its history is a function of C t alone and the fill
// time scales as 1/C (up to the time discretization). The fit must land on the target
// time within its tolerance from a start 67 % off in at most 3 runs, write a
// calibration file that a scene can load, and refuse scenes without a gas cavity.
#include <gtest/gtest.h>
#include <petscsys.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "app/commands.h"
#include "core/calibration_file.h"
#include "core/errors.h"
#include "sim/scene.h"
#include "tests/support/temp_dir.h"

namespace morphfem {
namespace {

std::string balloon_scene(const std::filesystem::path& dir, const std::string& cavity) {
  const std::string path = (dir / "balloon.yaml").string();
  std::ofstream(path) << "name: balloon\n"
                         "geometry: {type: spherical_shell, inner_radius: 0.010, outer_radius: 0.012, "
                         "mesh_size: 0.004, order: 1}\n"
                         "materials: {body: {model: neo_hookean, mu: 3.0e4, nu: 0.45}}\n"
                         "boundary:\n"
                         "  - {surface: sym_x, fix: [x]}\n"
                         "  - {surface: sym_y, fix: [y]}\n"
                         "  - {surface: sym_z, fix: [z]}\n"
                         "loads:\n"
                      << cavity
                      << "solver: {end_time: 4.0, initial_step: 0.02, max_step: 0.02}\n"
                         "output: {directory: "
                      << (dir / "unused").string() << "}\n";
  return path;
}

TEST(CalibrateMorphing, ValveConductanceLandsOnTheTargetTime) {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  const auto dir = temp_dir("morphfem_calibrate_morphing");
  const std::string scene = balloon_scene(dir,
                                          "  gas_cavities:\n"
                                          "    - {name: core, surfaces: [inner], symmetry_factor: 8,\n"
                                          "       supply_pressure: [[0, 0], [0.1, 0], [0.11, 6000]], "
                                          "conductance: 8.0e-8}\n");
  const std::string out = (dir / "fit").string();
  const int status = calibrate_command(
      {"morphing", "--scene", scene, "--out", out, "--inflate-s", "0.6", "--tolerance", "0.02", "--max-runs", "4"},
      PETSC_COMM_WORLD);
  ASSERT_EQ(status, 0) << "the fit must converge";
  if (rank != 0) return;
  const Calibration c = read_calibration_file(out + "/morphing.yaml");
  EXPECT_EQ(c.kind, "morphing");
  const double C = c.parameter("conductance_supply").value;
  EXPECT_GT(C, 0);
  EXPECT_NE(C, 8.0e-8);                                         // the start was off: the fit moved
  EXPECT_THROW(c.parameter("conductance_vacuum"), InputError);  // no vacuum phase, no vacuum value
  EXPECT_NEAR(std::stod(c.fit.at("inflate_time_s")), 0.6, 0.02 * 0.6);
  // t ~ C^-b with b = 1 for a quasi-static body (up to the time discretization: the
  // steps do not scale with C): b from the first two runs (morphing_runs.csv).
  std::ifstream runs(out + "/morphing_runs.csv");
  std::string line;
  std::getline(runs, line);  // header
  std::vector<std::pair<double, double>> Ct;
  while (std::getline(runs, line)) {
    std::stringstream row(line);
    std::string cell;
    std::vector<std::string> v;  // run, C_supply, C_vacuum, inflate_s, ... (null: not simulated)
    while (std::getline(row, cell, ',')) v.push_back(cell);
    Ct.emplace_back(std::stod(v.at(1)), std::stod(v.at(3)));
  }
  ASSERT_GE(Ct.size(), 2u);
  EXPECT_LE(Ct.size(), 3u);
  const double b = -std::log(Ct[1].second / Ct[0].second) / std::log(Ct[1].first / Ct[0].first);
  EXPECT_NEAR(b, 1.0, 0.1) << "t ~ C^-b";
  // A scene takes the fitted value from the file.
  const std::string loaded =
      balloon_scene(dir,
                    "  gas_cavities:\n"
                    "    - {name: core, surfaces: [inner], symmetry_factor: 8, supply_pressure: 3000,\n"
                    "       conductance: {calibration: fit/morphing.yaml, parameter: conductance_supply}}\n");
  const Scene s = read_scene(loaded);
  EXPECT_DOUBLE_EQ(s.gas_cavities.at(0).conductance(1.0), C);
  std::filesystem::remove_all(dir);
}

// Both halves: the supply turns negative at t = 3 s (the "vacuum" phase), so the fit
// sets the supply and the vacuum conductance together, each from its own phase time.
TEST(CalibrateMorphing, SupplyAndVacuumConductancesLandOnBothTimes) {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  const auto dir = temp_dir("morphfem_calibrate_morphing_cycle");
  const std::string scene =
      balloon_scene(dir,
                    "  gas_cavities:\n"
                    "    - {name: core, surfaces: [inner], symmetry_factor: 8,\n"
                    "       supply_pressure: [[0, 0], [0.1, 0], [0.11, 6000], [3.0, 6000], [3.01, -1000]],\n"
                    "       conductance: 8.0e-8, vacuum_conductance: 8.0e-8}\n");
  const std::string out = (dir / "fit").string();
  const int status = calibrate_command({"morphing", "--scene", scene, "--out", out, "--inflate-s", "0.6", "--deflate-s",
                                        "0.3", "--tolerance", "0.02", "--max-runs", "5"},
                                       PETSC_COMM_WORLD);
  ASSERT_EQ(status, 0) << "the fit must converge";
  if (rank != 0) return;
  const Calibration c = read_calibration_file(out + "/morphing.yaml");
  EXPECT_NE(c.parameter("conductance_supply").value, 8.0e-8);
  EXPECT_NE(c.parameter("conductance_vacuum").value, 8.0e-8);
  EXPECT_NEAR(std::stod(c.fit.at("inflate_time_s")), 0.6, 0.02 * 0.6);
  EXPECT_NEAR(std::stod(c.fit.at("deflate_time_s")), 0.3, 0.02 * 0.3);
  // A scene takes both values from the file.
  const std::string loaded =
      balloon_scene(dir,
                    "  gas_cavities:\n"
                    "    - {name: core, surfaces: [inner], symmetry_factor: 8, supply_pressure: [[0, 1000], [1, 1000], "
                    "[1.01, -1000]],\n"
                    "       conductance: {calibration: fit/morphing.yaml, parameter: conductance_supply},\n"
                    "       vacuum_conductance: {calibration: fit/morphing.yaml, parameter: conductance_vacuum}}\n");
  const Scene s = read_scene(loaded);
  EXPECT_DOUBLE_EQ(s.gas_cavities.at(0).conductance_at(0.5), c.parameter("conductance_supply").value);
  EXPECT_DOUBLE_EQ(s.gas_cavities.at(0).conductance_at(1.5), c.parameter("conductance_vacuum").value);
  std::filesystem::remove_all(dir);
}

TEST(CalibrateMorphing, RefusesScenesWithoutAGasCavity) {
  const auto dir = temp_dir("morphfem_calibrate_morphing_bad");
  const std::string scene = balloon_scene(dir,
                                          "  cavities:\n"
                                          "    - {name: core, surfaces: [inner], pressure: 3000}\n");
  try {
    calibrate_command({"morphing", "--scene", scene, "--out", (dir / "fit").string()}, PETSC_COMM_WORLD);
    FAIL() << "a scene without a gas cavity must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gas cavity"), std::string::npos) << e.what();
  }
  EXPECT_THROW(calibrate_command({"morphing", "--scene", scene, "--fraction", "1.5"}, PETSC_COMM_WORLD), InputError);
  EXPECT_THROW(calibrate_command({"morphing", "--scene", scene, "--bogus", "1"}, PETSC_COMM_WORLD), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "fit"));  // nothing written on bad input
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace morphfem
