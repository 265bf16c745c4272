// Scene files: a good scene runs; bad ones fail with file, line and key, and
// leave no output behind.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>

#include "core/errors.h"
#include "fem/material.h"
#include "mesh/geometry.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "tests/support/tube_scene.h"

using namespace morphfem;
namespace fs = std::filesystem;

namespace {

const char* kGood = R"(name: cube
geometry: {type: block, lx: 0.01, ly: 0.01, lz: 0.01, mesh_size: 0.005, order: 1}
materials:
  body: {model: neo_hookean, mu: 1.0e5, kappa: 1.0e6, density: 1000}
boundary:
  - {surface: zmin, fix: [x, y, z]}
  - {surface: zmax, displacement: [0, 0, -0.001]}
solver: {end_time: 1, initial_step: 0.5}
output: {directory: OUT}
)";

struct TempScene {
  fs::path dir;
  fs::path file;
  explicit TempScene(const std::string& text, const std::string& name = "scene.yaml") {
    dir = fs::temp_directory_path() / ("morphfem_scene_test_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    file = dir / name;
    std::string t = text;
    const auto pos = t.find("OUT");
    if (pos != std::string::npos) t.replace(pos, 3, (dir / "out").string());
    std::ofstream(file) << t;
  }
  ~TempScene() { fs::remove_all(dir); }
};

std::string error_of(const std::string& text) {
  TempScene s(text);
  try {
    Scene scene = read_scene(s.file.string());
    run_scene(scene, PETSC_COMM_WORLD, {true, false});
  } catch (const InputError& e) {
    EXPECT_FALSE(fs::exists(s.dir / "out")) << "bad input left output behind";
    EXPECT_FALSE(fs::exists(s.dir / "out.partial")) << "bad input left output behind";
    return e.what();
  }
  return "";
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return text.replace(pos, from.size(), to);
}

}  // namespace

TEST(Scene, GoodSceneRunsAndWritesResults) {
  TempScene s(kGood);
  Scene scene = read_scene(s.file.string());
  auto r = run_scene(scene, PETSC_COMM_WORLD, {true, false});
  EXPECT_TRUE(r.stats.completed);
  EXPECT_TRUE(fs::exists(s.dir / "out" / "cube.xdmf"));
  EXPECT_TRUE(fs::exists(s.dir / "out" / "cube.h5"));
  EXPECT_TRUE(fs::exists(s.dir / "out" / "summary.json"));
  EXPECT_FALSE(fs::exists(s.dir / "out.partial"));
  // Top face moved down by the prescribed 1 mm.
  double uz = 0;
  auto nodes = r.mesh.nodes_of_surface("zmax");
  for (int n : nodes) uz += r.u(n, 2);
  EXPECT_NEAR(uz / nodes.size(), -0.001, 1e-12);
}

TEST(Scene, UnknownKeyNamesFileLineAndKey) {
  std::string e = error_of(replace(kGood, "solver: {end_time: 1", "solver: {end_tme: 1"));
  EXPECT_NE(e.find("scene.yaml:8:"), std::string::npos) << e;
  EXPECT_NE(e.find("end_tme"), std::string::npos) << e;
}

TEST(Scene, UnknownRegionIsNamedWithTheKnownOnes) {
  std::string e = error_of(replace(kGood, "surface: zmin", "surface: bottom"));
  EXPECT_NE(e.find("bottom"), std::string::npos) << e;
  EXPECT_NE(e.find("zmin"), std::string::npos) << e;
  EXPECT_NE(e.find("scene.yaml:6:"), std::string::npos) << e;
}

TEST(Scene, BadNumberNamesTheLine) {
  std::string e = error_of(replace(kGood, "mu: 1.0e5", "mu: soft"));
  EXPECT_NE(e.find("scene.yaml:4:"), std::string::npos) << e;
}

TEST(Scene, BadSolverChoicesNameTheKeyAndTheAllowedValues) {
  std::string e = error_of(replace(kGood, "solver: {end_time: 1", "solver: {hessian_projection: never, end_time: 1"));
  EXPECT_NE(e.find("scene.yaml:8:"), std::string::npos) << e;
  EXPECT_NE(e.find("solver.hessian_projection"), std::string::npos) << e;
  EXPECT_NE(e.find("one of 'adaptive', 'always'"), std::string::npos) << e;
  e = error_of(replace(kGood, "solver: {end_time: 1", "solver: {linear_solver: superlu, end_time: 1"));
  EXPECT_NE(e.find("solver.linear_solver"), std::string::npos) << e;
  EXPECT_NE(e.find("one of 'mumps', 'mumps_lu', 'gamg'"), std::string::npos) << e;
  e = error_of(replace(kGood, "solver: {end_time: 1", "solver: {easy_newton_its: 2.5, end_time: 1"));
  EXPECT_NE(e.find("solver.easy_newton_its"), std::string::npos) << e;
  EXPECT_NE(e.find("positive integer"), std::string::npos) << e;
  TempScene s(
      replace(kGood, "solver: {end_time: 1", "solver: {hessian_projection: always, easy_newton_its: 9, end_time: 1"));
  const Scene scene = read_scene(s.file.string());
  EXPECT_EQ(scene.solver.hessian_projection, HessianProjection::always);
  EXPECT_EQ(scene.solver.easy_newton_its, 9);
}

TEST(Scene, NegativeModulusIsRejected) {
  std::string e = error_of(replace(kGood, "mu: 1.0e5", "mu: -1.0e5"));
  EXPECT_NE(e.find("mu"), std::string::npos) << e;
}

TEST(Scene, UnknownMaterialModelListsTheKnownOnes) {
  std::string e = error_of(replace(kGood, "model: neo_hookean", "model: rubber"));
  EXPECT_NE(e.find("rubber"), std::string::npos) << e;
  EXPECT_NE(e.find("yeoh"), std::string::npos) << e;
}

TEST(Scene, YamlSyntaxErrorNamesTheLine) {
  std::string e = error_of(replace(kGood, "boundary:", "boundary: [unclosed"));
  EXPECT_NE(e.find("scene.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("YAML"), std::string::npos) << e;
}

TEST(Scene, MissingMeshFileIsNamed) {
  std::string e =
      error_of(replace(kGood, "geometry: {type: block, lx: 0.01, ly: 0.01, lz: 0.01, mesh_size: 0.005, order: 1}",
                       "mesh: {file: nowhere.msh}"));
  EXPECT_NE(e.find("nowhere.msh"), std::string::npos) << e;
}

TEST(Scene, GravityWithoutDensityIsRejected) {
  std::string text = replace(kGood, ", density: 1000", "");
  text = replace(text, "solver:", "loads: {gravity: [0, 0, -9.81]}\nsolver:");
  std::string e = error_of(text);
  EXPECT_NE(e.find("density"), std::string::npos) << e;
}

// A stiff incompressible neo-Hookean sheet (mu t = 100 N/m) on top of a block 2500x
// softer (mu h = 0.04 N/m), pulled to lambda = 1.5 along x and free across: the sheet
// contracts to the plane-stress closed form lambda_2 = lambda^(-1/2) = 0.8165 (the block's
// resistance changes it by at most O(4e-4)), and the homogeneous state is exact on P1.
TEST(Scene, MembraneStretchesAsTheIncompressibleClosedForm) {
  const char* kSheet = R"(name: sheet
geometry: {type: block, lx: 0.04, ly: 0.02, lz: 0.004, mesh_size: 0.01, order: 1}
materials:
  body: {model: neo_hookean, mu: 10, nu: 0.3}
membranes:
  zmax: {model: neo_hookean, thickness: 1.0e-3, mu: 1.0e5}
boundary:
  - {surface: xmin, fix: [x]}
  - {surface: xmax, displacement: [0.02, 0, 0]}
  - {surface: ymin, fix: [y]}
  - {surface: zmin, fix: [z]}
solver: {end_time: 1, initial_step: 0.25}
)";
  TempScene s(kSheet);
  Scene scene = read_scene(s.file.string());
  ASSERT_EQ(scene.membranes.size(), 1u);
  scene.boundary[1].components = {true, false, false};  // xmax: only u_x prescribed (free across)
  const auto r = run_scene(scene, PETSC_COMM_WORLD, {false, false});
  ASSERT_TRUE(r.stats.completed);
  double y_max = 0;
  for (int n : r.mesh.nodes_of_surface("zmax")) y_max = std::max(y_max, r.mesh.X(n, 1) + r.u(n, 1));
  std::printf("sheet contraction %.8f, closed form %.8f\n", y_max / 0.02, 1.0 / std::sqrt(1.5));
  EXPECT_NEAR(y_max / 0.02, 1.0 / std::sqrt(1.5), 2e-4);
  // Without the sheet the soft block (nu 0.3) contracts much less: the sheet decides.
  scene.membranes.clear();
  const auto bare = run_scene(scene, PETSC_COMM_WORLD, {false, false});
  double y_bare = 0;
  for (int n : bare.mesh.nodes_of_surface("zmax")) y_bare = std::max(y_bare, bare.mesh.X(n, 1) + bare.u(n, 1));
  EXPECT_GT(y_bare / 0.02, 0.85);
}

TEST(Scene, MembraneOnAnUnknownSurfaceOrWithoutThicknessIsRejected) {
  const std::string sheet = "membranes:\n  top: {model: neo_hookean, thickness: 1.0e-3, mu: 1.0e5}\nboundary:";
  std::string e = error_of(replace(kGood, "boundary:", sheet));
  EXPECT_NE(e.find("top"), std::string::npos) << e;
  EXPECT_NE(e.find("zmax"), std::string::npos) << e;  // the known surfaces
  e = error_of(replace(kGood, "boundary:", "membranes:\n  zmax: {model: neo_hookean, mu: 1.0e5}\nboundary:"));
  EXPECT_NE(e.find("thickness"), std::string::npos) << e;
  EXPECT_NE(e.find("scene.yaml:6:"), std::string::npos) << e;
}

TEST(Scene, MissingFileIsAnInputError) { EXPECT_THROW(read_scene("/nonexistent/scene.yaml"), InputError); }

TEST(Scene, GamgWithRigidBodyNearNullspaceMatchesMumps) {
  const std::string text = replace(kGood, "mu: 1.0e5, kappa: 1.0e6, density: 1000}",
                                   "mu: 1.0e5, kappa: 1.0e6, density: 1000}\nloads: {gravity: [3.0, 0, -9.81]}");
  TempScene direct(text);
  TempScene iterative(replace(text, "initial_step: 0.5}", "initial_step: 0.5, linear_solver: gamg}"), "gamg.yaml");
  auto a = run_scene(read_scene(direct.file.string()), PETSC_COMM_WORLD, {false, false});
  auto b = run_scene(read_scene(iterative.file.string()), PETSC_COMM_WORLD, {false, false});
  ASSERT_TRUE(a.stats.completed && b.stats.completed);
  EXPECT_LT((a.u - b.u).cwiseAbs().maxCoeff(), 1e-7 * a.u.cwiseAbs().maxCoeff());
}

// Every example scene parses and runs to completion (without writing results).
TEST(Scene, EveryExampleSceneRuns) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(MORPHFEM_SOURCE_DIR) / "examples")) {
    if (entry.path().extension() != ".yaml") continue;
    Scene scene = read_scene(entry.path().string());
    auto r = run_scene(scene, PETSC_COMM_WORLD, {false, false});
    EXPECT_TRUE(r.stats.completed) << entry.path() << ": " << r.stats.failure;
    EXPECT_GT(r.min_J, 0.0) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 3);
}

// The robot scenes (examples/voxel, examples/physical) are too big to run in the suite,
// but every one must read: keys, schedules, calibration files they load.
TEST(Scene, EveryRobotSceneReads) {
  int count = 0;
  for (const char* folder : {"voxel", "physical"})
    for (const auto& entry : fs::directory_iterator(fs::path(MORPHFEM_SOURCE_DIR) / "examples" / folder)) {
      if (entry.path().extension() != ".yaml") continue;
      EXPECT_NO_THROW(read_scene(entry.path().string())) << entry.path();
      ++count;
    }
  EXPECT_GE(count, 10);
}

TEST(Scene, GasCavityFillsTowardsTheSupplyPressure) {
  Scene scene = read_scene(std::string(MORPHFEM_SOURCE_DIR) + "/examples/balloon_valve.yaml");
  std::vector<double> pressure;
  RunOptions options{false, false};
  options.on_step = [&](double, const Mesh&, const RowMatrixXd&, const SimulationResult& r) {
    pressure.push_back(r.cavity_pressure.at(0));
  };
  auto r = run_scene(scene, PETSC_COMM_WORLD, options);
  ASSERT_TRUE(r.stats.completed);
  for (size_t i = 1; i < pressure.size(); ++i) EXPECT_GE(pressure[i], pressure[i - 1] - 1e-9);
  EXPECT_GT(pressure.back(), 1000.0);
  EXPECT_LT(pressure.back(), 5000.0);  // below the 5 kPa supply
}

// An octant of a thin neo-Hookean balloon, H/R = 0.05 (the scenes add name and loads).
constexpr const char* kThinBalloon =
    R"(geometry: {type: spherical_shell, inner_radius: 0.010, outer_radius: 0.0105, mesh_size: 0.003, order: 2}
materials:
  body: {model: neo_hookean, mu: 1.0e5, kappa: 1.0e8}
boundary:
  - {surface: sym_x, fix: [x]}
  - {surface: sym_y, fix: [y]}
  - {surface: sym_z, fix: [z]}
)";

// A thin neo-Hookean balloon under pressure control past its maximum
// (1.239 mu H/R): the run stops with a diagnostic, keeps the last converged state
// in the output (status "failed" in summary.json) and writes no NaN.
TEST(Scene, PressureControlPastTheLimitPointFailsGracefully) {
  TempScene s("name: balloon\n" + std::string(kThinBalloon) + R"(loads:
  cavities:
    - {name: inside, surfaces: [inner], pressure: 9000}
solver: {end_time: 1, initial_step: 0.1, max_step: 0.1, min_step: 1.0e-3, formulation: mean_dilatation}
output: {directory: OUT}
)");
  Scene scene = read_scene(s.file.string());
  auto r = run_scene(scene, PETSC_COMM_WORLD, {true, false});
  EXPECT_FALSE(r.stats.completed);
  EXPECT_NE(r.stats.failure.find("no convergence"), std::string::npos) << r.stats.failure;
  EXPECT_NE(r.stats.failure.find("t = "), std::string::npos) << r.stats.failure;
  // The last converged pressure is below the thin-shell maximum (about 6 kPa here) and the state is finite.
  ASSERT_EQ(r.cavity_pressure.size(), 1u);
  EXPECT_LT(r.cavity_pressure[0], 6600.0);
  EXPECT_GT(r.cavity_pressure[0], 4000.0);
  EXPECT_TRUE(r.u.allFinite());
  std::ifstream summary(s.dir / "out" / "summary.json");
  std::string text((std::istreambuf_iterator<char>(summary)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"status\": \"failed\""), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(s.dir / "out" / "balloon.xdmf"));
}

// The same balloon under volume control (loads.volume_cavities, V*/V_ref to 1.8^3):
// the run goes through the pressure maximum that stops pressure control, the
// volume follows V*, and the maximum is the thin-shell one, p = 2 mu H/R (la^-1 -
// la^-7) with its peak 1.2394 mu H/R at la = 7^(1/6) = 1.383 (R the mid radius).
TEST(Scene, VolumeControlTracesTheBalloonThroughItsPressureMaximum) {
  const std::string text = "name: balloon_volume\n" + std::string(kThinBalloon) + R"(loads:
  volume_cavities:
    - {name: inside, surfaces: [inner], volume_ratio: [[0, 1], [1, 5.832]], penalty_modulus: 2.0e4}
solver: {end_time: 1, initial_step: 0.02, max_step: 0.02, formulation: mean_dilatation}
)";
  for (const auto& [from, to, message] : std::vector<std::array<std::string, 3>>{
           {"[[0, 1], [1, 5.832]]", "[[0, 1], [1, -2]]", "volume ratios must be positive"},
           {"[[0, 1], [1, 5.832]]", "3.0", "expected a table"},
           {", penalty_modulus: 2.0e4", "", "missing key 'penalty_modulus'"},
           {"2.0e4", "-1", "loads.volume_cavities.penalty_modulus"},
           {"[inner]", "[nowhere]", "nowhere"}}) {
    const std::string e = error_of(replace(text, from, to));
    EXPECT_NE(e.find(message), std::string::npos) << to << ": " << e;
  }
  TempScene s(text);
  Scene scene = read_scene(s.file.string());
  ASSERT_EQ(scene.volume_cavities.size(), 1u);
  std::vector<std::pair<double, double>> curve;  // (inner stretch, gauge pressure)
  double worst = 0, V_ref = 0;
  RunOptions options{false, false};
  options.on_step = [&](double t, const Mesh&, const RowMatrixXd&, const SimulationResult& r) {
    if (t == 0.0) V_ref = r.cavity_volume.at(0);  // the first record is the reference state
    const double ratio = r.cavity_volume.at(0) / V_ref;
    worst = std::max(worst, std::abs(ratio / (1 + 4.832 * t) - 1));
    curve.emplace_back(std::cbrt(ratio), r.cavity_pressure.at(0));
  };
  auto r = run_scene(scene, PETSC_COMM_WORLD, options);
  ASSERT_TRUE(r.stats.completed) << r.stats.failure;
  auto peak = std::max_element(curve.begin(), curve.end(), [](auto& a, auto& b) { return a.second < b.second; });
  const double mu = 1e5, H = 0.0005, R = 0.01025, p_max = 1.2394 * mu * H / R;
  std::cout << "peak " << peak->second << " Pa at stretch " << peak->first << " (thin shell " << p_max
            << " Pa at 1.383); end " << curve.back().second << " Pa; worst |V/V* - 1| " << worst << "\n";
  EXPECT_LT(worst, 1e-5);
  EXPECT_NEAR(peak->second, p_max, 0.03 * p_max);
  EXPECT_NEAR(peak->first, 1.383, 0.03);
  EXPECT_LT(curve.back().second, 0.9 * peak->second);  // past the maximum the pressure falls
}

// A quarter of a thick DS10 tube in plane strain whose bore is bladder 1 of the
// rolling schedule (gait from t = 0.5 s); `extra` goes into the actuation map.
static std::string scheduled_tube(const std::string& extra) {
  const std::string schedule = std::string(MORPHFEM_SOURCE_DIR) + "/examples/schedules/rolling.yaml";
  return quarter_tube("inner_radius: 0.005, outer_radius: 0.02, mesh_size: 0.004, order: 1",
                      "{model: dragon_skin_10}") +
         "actuation: {schedule: " + schedule + ", start: 0.5, bladders: {b1: inner}, volume_axes: [x, y]" + extra +
         "}\n";
}

// A schedule file drives a cavity: bladder 1 of the rolling schedule (inflated in
// the 8th column of each repeat) inflates a tube only while the schedule says so.
TEST(Scene, ScheduleDrivesTheBladderPressure) {
  TempScene s("name: scheduled_tube\n" + scheduled_tube("") + R"(
solver: {end_time: 10.4, initial_step: 0.3, max_step: 0.3}
)");
  Scene scene = read_scene(s.file.string());
  ASSERT_EQ(scene.cavities.size(), 1u);
  std::vector<std::pair<double, double>> volume;  // (gait time, volume)
  RunOptions options{false, false};
  options.on_step = [&](double t, const Mesh&, const RowMatrixXd&, const SimulationResult& r) {
    volume.emplace_back(t - 0.5, r.cavity_volume.at(0));
  };
  scene.solver.output_times = {0.5 + 3.5 * 1.237, 0.5 + 7.5 * 1.237};
  auto r = run_scene(scene, PETSC_COMM_WORLD, options);
  ASSERT_TRUE(r.stats.completed) << r.stats.failure;
  const double v0 = volume.front().second;
  int checked = 0;
  for (const auto& [t, v] : volume) {
    if (std::abs(t - 3.5 * 1.237) < 1e-9) {
      EXPECT_NEAR(v, v0, 1e-9 * v0);  // column 4: b1 deflated
      ++checked;
    }
    if (std::abs(t - 7.5 * 1.237) < 1e-9) {
      EXPECT_GT(v, 1.05 * v0);  // column 8: b1 inflated
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2);
}

// actuation.valves: the scheduled cavity holds gas fed through a valve whose supply
// is the schedule's setpoint. With a fast valve (fill time 5 ms) the tube in column
// 8 (b1 inflated, 0.2 s ramp) sits at the setpoint and at the pressure-controlled
// volume; a slow one (2 s, the rigid tube's time constant) lags well behind. Bad
// valve keys name their key.
TEST(Scene, ValvesFeedTheScheduledCavityFromItsSetpoint) {
  const std::string text = "name: valve_tube\n" + scheduled_tube("VALVES") + R"(
solver: {end_time: 10.4, initial_step: 0.05, max_step: 0.05}
)";
  const double t8 = 0.5 + 7.5 * 1.237;  // middle of column 8 (0.42 s after its ramp ended)
  auto at_column_8 = [&](const std::string& valves, double& pressure, double& volume) {
    TempScene s(replace(text, "VALVES", valves));
    Scene scene = read_scene(s.file.string());
    RunOptions options{false, false};
    options.on_step = [&](double t, const Mesh&, const RowMatrixXd&, const SimulationResult& r) {
      if (std::abs(t - t8) < 1e-9) {
        pressure = r.cavity_pressure.at(0);
        volume = r.cavity_volume.at(0);
      }
    };
    scene.solver.output_times = {t8};
    scene.solver.t_end = t8;
    auto r = run_scene(scene, PETSC_COMM_WORLD, options);
    EXPECT_TRUE(r.stats.completed) << r.stats.failure;
    return scene;
  };
  double p_set = 0, v_set = 0, p_fast = 0, v_fast = 0, p_slow = 0, v_slow = 0;
  const Scene controlled = at_column_8("", p_set, v_set);
  const Scene fast = at_column_8(", valves: {fill_time_s: 0.005}", p_fast, v_fast);
  at_column_8(", valves: {fill_time_s: 2.0}", p_slow, v_slow);
  ASSERT_EQ(controlled.cavities.size(), 1u);
  ASSERT_TRUE(controlled.gas_cavities.empty());
  ASSERT_EQ(fast.gas_cavities.size(), 1u);
  ASSERT_TRUE(fast.cavities.empty());
  for (double t : {0.0, 0.6, 2.0, t8})
    EXPECT_DOUBLE_EQ(fast.gas_cavities[0].supply_gauge_pressure(t), controlled.cavities[0].pressure(t)) << t;
  std::cout << "column 8: setpoint " << p_set << " Pa, V " << v_set << " m^3; fast valve " << p_fast << " Pa, V "
            << v_fast << " m^3; slow valve " << p_slow << " Pa, V " << v_slow << " m^3\n";
  EXPECT_NEAR(p_set, 25e3, 1e-6);
  EXPECT_NEAR(p_fast, 25e3, 0.01 * 25e3);
  EXPECT_NEAR(v_fast, v_set, 0.01 * v_set);
  EXPECT_LT(p_slow, 0.5 * 25e3);
  EXPECT_LT(v_slow, v_set);
  const std::string bad = replace(text, "VALVES", ", valves: {KEY}");
  std::string e = error_of(replace(bad, "KEY", "fill_time_s: 0.1, conductance: 1e-8"));
  EXPECT_NE(e.find("exactly one of fill_time_s"), std::string::npos) << e;
  e = error_of(replace(bad, "KEY", "temperature: 300"));
  EXPECT_NE(e.find("exactly one of fill_time_s"), std::string::npos) << e;
  e = error_of(replace(bad, "KEY", "fill_time_s: -1"));
  EXPECT_NE(e.find("actuation.valves.fill_time_s"), std::string::npos) << e;
  EXPECT_NE(e.find("must be positive"), std::string::npos) << e;
  e = error_of(replace(bad, "KEY", "fill_time: 0.1"));
  EXPECT_NE(e.find("actuation.valves"), std::string::npos) << e;
}

// Open-sleeve and weightless keys: bad values name their key; the open axis sets the
// volume axes to the other two.
TEST(Scene, OpenSleeveAndWeightlessKeys) {
  const std::string cavity =
      "loads:\n  cavities:\n    - {name: core, surfaces: [zmax], open_axis: AXIS, pressure: 1}\n";
  std::string e = error_of(std::string(kGood) + replace(cavity, "AXIS", "w"));
  EXPECT_NE(e.find("loads.cavities.open_axis"), std::string::npos) << e;
  {
    TempScene s(std::string(kGood) + replace(cavity, "AXIS", "y"));
    const Scene scene = read_scene(s.file.string());
    ASSERT_EQ(scene.cavities.size(), 1u);
    EXPECT_EQ(scene.cavities[0].open_axis, 1);
    EXPECT_EQ(scene.cavities[0].axes, (std::array<bool, 3>{true, false, true}));
  }
  e = error_of(std::string(kGood) + replace(cavity, "AXIS", "y, volume_axes: [x, y]"));
  EXPECT_NE(e.find("loads.cavities.volume_axes"), std::string::npos) << e;
  const std::string schedule = std::string(MORPHFEM_SOURCE_DIR) + "/examples/schedules/rolling.yaml";
  const std::string actuation = "actuation: {schedule: " + schedule + ", bladders: {b1: zmax}, KEY}\n";
  e = error_of(std::string(kGood) + replace(actuation, "KEY", "weightless_inflated: true"));
  EXPECT_NE(e.find("needs growth actuation"), std::string::npos) << e;
  e = error_of(std::string(kGood) + replace(actuation, "KEY", "core_open_axis: y"));
  EXPECT_NE(e.find("actuation.core_open_axis"), std::string::npos) << e;
  {  // chambers without end walls: every bladder cavity an open sleeve
    TempScene s(std::string(kGood) + replace(actuation, "KEY", "bladders_open_axis: y"));
    const Scene scene = read_scene(s.file.string());
    ASSERT_EQ(scene.cavities.size(), 1u);
    EXPECT_EQ(scene.cavities[0].open_axis, 1);
    EXPECT_EQ(scene.cavities[0].axes, (std::array<bool, 3>{true, false, true}));
  }
  e = error_of(std::string(kGood) + replace(actuation, "KEY", "bladders_open_axis: q"));
  EXPECT_NE(e.find("actuation.bladders_open_axis"), std::string::npos) << e;
  e = error_of(std::string(kGood) + "actuation: {schedule: " + schedule + ", core: zmax, bladders_open_axis: y}\n");
  EXPECT_NE(e.find("needs 'bladders'"), std::string::npos) << e;
}

// The default barrier stiffness comes from the material under the contact surface,
// not the stiffest in the body: in the physical laminate the 100 MPa fabric sheet's
// edges reach the outer surface, but the skin lies under nearly all of it.
TEST(Scene, ContactStiffnessFollowsTheMaterialUnderTheSurface) {
  ParamSet geometry("geometry");
  geometry.set_string("type", "robot_physical");
  geometry.set("mesh_size", 0.02);
  const Mesh mesh = build_geometry(geometry);
  auto neo_hookean = [](double mu) {
    ParamSet p("material");
    p.set_string("model", "neo_hookean");
    p.set("mu", mu);
    p.set("nu", 0.45);
    return std::shared_ptr<const Material>(make_material(p));
  };
  std::vector<std::shared_ptr<const Material>> materials(mesh.regions.size());
  for (const auto& r : mesh.regions) {
    if (r.dim != 3) continue;
    materials[r.id] = neo_hookean(r.name == "skin" ? 4.3e4 : r.name == "fabric" ? 1.0e8 : 1.5e5);
  }
  // The stiffest-material rule would pick the fabric here: it touches the outer surface.
  const auto outer = mesh.nodes_of_surface("outer");
  const std::set<int> outer_nodes(outer.begin(), outer.end());
  bool fabric_touches = false;
  for (int c : mesh.cells_of("fabric"))
    for (int a = 0; a < mesh.nodes_per_cell(); ++a)
      fabric_touches = fabric_touches || outer_nodes.count(mesh.cells(c, a));
  ASSERT_TRUE(fabric_touches);
  EXPECT_EQ(contact_shear_modulus(mesh, materials, {"bottom", "outer"}), 4.3e4);
  EXPECT_EQ(contact_shear_modulus(mesh, materials, {"bladder_1_wall"}), 1.5e5);  // the chamber's own DS30
}

// contact.lattice_floor (a diagnostic, contact/lattice_floor.h): bad keys are named,
// and the voxel preset's slice falls onto the lattice's spheres and rests on them,
// its lowest face held up by the protrusion of the deflated bladder voxels' spheres
// (L (1 + 1 + 0.2)/6 - 1 mm = 2.67 mm beyond the face): no face touches the floor.
TEST(Scene, LatticeFloorHoldsTheVoxelSliceOnItsSpheres) {
  std::string e = error_of(std::string(kGood) + "contact: {lattice_floor: {mu: {body: 1}}}\n");
  EXPECT_NE(e.find("contact.lattice_floor"), std::string::npos) << e;
  EXPECT_NE(e.find("kappa"), std::string::npos) << e;
  e = error_of(std::string(kGood) + "contact: {lattice_floor: {kappa: 1.0e6, mu: {body: 1}}}\n");
  EXPECT_NE(e.find("robot_voxel"), std::string::npos) << e;
  e = error_of(std::string(kGood) + "contact: {lattice_floor: {kappa: 1.0e6, mu: [1]}}\n");
  EXPECT_NE(e.find("contact.lattice_floor.mu"), std::string::npos) << e;

  std::ifstream in(std::string(MORPHFEM_SOURCE_DIR) + "/examples/voxel/roll_slice.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto from = text.find("\ncontact:"), to = text.find("\ndynamics:");
  ASSERT_NE(from, std::string::npos);
  ASSERT_NE(to, std::string::npos);
  const double floor_z = -0.003;
  const std::string mu =
      "mu: {skin: 2.0, bladder_1: 0.6667, bladder_2: 0.6667, bladder_3: 0.6667, bladder_4: 0.6667, "
      "bladder_5: 0.6667, bladder_6: 0.6667, bladder_7: 0.6667";
  const std::string contact =
      "\ncontact:\n  lattice_floor: {point: [0, 0, -0.003], dhat: 5.0e-4, kappa: 6.0e5, " + mu + "}}";
  text.replace(from, to - from, contact);
  text = replace(text, "end_time: 21.3", "end_time: 0.3");
  text =
      replace(text, "../schedules/rolling.yaml", std::string(MORPHFEM_SOURCE_DIR) + "/examples/schedules/rolling.yaml");
  text = replace(text, "output: {directory: results/voxel/roll_slice, every: 2}", "output: {directory: OUT}");
  e = error_of(text);  // bladder_8 has no coefficient
  EXPECT_NE(e.find("no friction coefficient for volume region 'bladder_8'"), std::string::npos) << e;
  text = replace(text, "bladder_7: 0.6667}", "bladder_7: 0.6667, bladder_8: 0.6667}");
  TempScene s(text);
  Scene scene = read_scene(s.file.string());
  ASSERT_TRUE(scene.lattice_floor);
  const SimulationResult r = run_scene(scene, PETSC_COMM_WORLD, {false, false});
  ASSERT_TRUE(r.stats.completed);
  double lowest = 1e300;
  for (int a = 0; a < r.mesh.n_nodes(); ++a) lowest = std::min(lowest, r.mesh.X(a, 2) + r.u(a, 2));
  // Resting on faces would leave less than dhat (0.5 mm); falling freely, 0.44 m
  // below the start after 0.3 s; the spheres hold the faces 1.9 mm up (their 2.7 mm
  // protrusion less the barrier gap and the soft bladders' indentation).
  EXPECT_GT(lowest - floor_z, 0.0012);
  EXPECT_LT(lowest - floor_z, 0.0031);
}

// The 3D voxel preset's lattice points: the study's 1428 voxels; skin voxels over a
// foot's y range (both layers) take the foot's friction over time (active before the
// gait, inactive in the rolling gait's actuation phases), other skin voxels the skin's,
// bladder voxels theirs; a deflated bladder voxel's sphere has radius L 2.2/6, a skin
// voxel's L/2, and an inflated one's L (s_x + s_y + 2.5)/6.
namespace {
// examples/voxel/roll_flat.yaml at 2 cm on the lattice floor; `extra` adds keys to it.
std::string voxel_lattice_scene(const std::string& extra = "") {
  std::ifstream in(std::string(MORPHFEM_SOURCE_DIR) + "/examples/voxel/roll_flat.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto from = text.find("\ncontact:"), to = text.find("\ndynamics:");
  if (from == std::string::npos) return "";
  text.replace(from, to - from,
               "\ncontact:\n  lattice_floor: {point: [0, 0, -0.003], kappa: 6.0e5, mu: {skin: 2.0, bladder_1: 0.5, "
               "bladder_2: 0.5, bladder_3: 0.5, bladder_4: 0.5, bladder_5: 0.5, bladder_6: 0.5, bladder_7: 0.5, "
               "bladder_8: 0.5}" +
                   extra + "}");
  text =
      replace(text, "../schedules/rolling.yaml", std::string(MORPHFEM_SOURCE_DIR) + "/examples/schedules/rolling.yaml");
  return replace(text, "mesh_size: 0.015", "mesh_size: 0.02");
}
}  // namespace

TEST(Scene, LatticePointsOfTheVoxelPresetCarryFeetAndGrowingRadii) {
  const std::string text = voxel_lattice_scene();
  ASSERT_FALSE(text.empty());
  TempScene s(text);
  const Scene scene = read_scene(s.file.string());
  ASSERT_TRUE(scene.lattice_floor);
  ASSERT_FALSE(scene.friction);  // the feet went to the lattice floor
  ASSERT_EQ(scene.lattice_floor->feet.size(), 2u);
  const Mesh mesh = build_scene_mesh(scene, PETSC_COMM_WORLD);
  const std::vector<LatticePoint> points = lattice_points(scene, mesh);
  ASSERT_EQ(points.size(), 1428u);
  const double t_gait = 1.5 + 0.1;  // in column 1's actuation phase (rolling: feet inactive)
  const double t_inflated = 30.0;   // after the gait: every bladder deflated again, feet active
  int feet = 0, skin = 0, bladders = 0, grown = 0;
  for (const LatticePoint& p : points) {
    Eigen::Vector3d X = Eigen::Vector3d::Zero();
    for (size_t a = 0; a < p.nodes.size(); ++a) X += p.weights[a] * mesh.X.row(p.nodes[a]).transpose();
    const double r0 = p.radius(0.0);
    if (std::abs(r0 - 0.005) < 1e-12) {  // skin
      if (X.y() < 0.03 || X.y() > 0.19) {
        ++feet;
        EXPECT_EQ(p.mu(0.0), 2.0);
        EXPECT_NEAR(p.mu(t_gait), 1e-4, 1e-12);
        EXPECT_EQ(p.mu(t_inflated), 2.0);
      } else {
        ++skin;
        EXPECT_EQ(p.mu(t_gait), 2.0);
      }
    } else {
      ++bladders;
      EXPECT_NEAR(r0, 0.01 * 2.2 / 6.0, 1e-12);
      EXPECT_EQ(p.mu(t_gait), 0.5);
      if (p.radius(1.5 + 0.9) > 0.0075) ++grown;  // bladder 8 inflates in column 1 (0.81 s swing)
    }
  }
  EXPECT_EQ(feet, 2 * 2 * 15 * 3);  // two feet, both layers, 15 x 3 voxels each
  EXPECT_EQ(skin, 660 - feet);
  EXPECT_EQ(bladders, 768);
  EXPECT_EQ(grown, 3 * 16 * 2);  // bladder 8's voxels
}

// gap_foot_columns: the feet's skin voxels in the columns without a bladder (x = 4, 8,
// 12 of 15) take the study's third foot material: inactive while settling and in column
// 1, active from column 1's settle phase on even while feet A and B are inactive, and
// a sphere of radius L (0.9 + 1 + 1)/6. Bad combinations are refused.
TEST(Scene, LatticeGapFootColumnsStayActiveAfterTheFirstSettlePhase) {
  TempScene s(voxel_lattice_scene(", gap_foot_columns: true"));
  const Scene scene = read_scene(s.file.string());
  const Mesh mesh = build_scene_mesh(scene, PETSC_COMM_WORLD);
  const std::vector<LatticePoint> points = lattice_points(scene, mesh);
  ASSERT_EQ(points.size(), 1428u);
  const double t_column1 = 1.5 + 0.1, t_column2 = 1.5 + 1.237 + 0.1;  // actuation phases, feet A, B inactive
  int gap = 0, feet = 0;
  for (const LatticePoint& p : points) {
    Eigen::Vector3d X = Eigen::Vector3d::Zero();
    for (size_t a = 0; a < p.nodes.size(); ++a) X += p.weights[a] * mesh.X.row(p.nodes[a]).transpose();
    if (std::abs(p.radius(0.0) - 0.01 * 2.9 / 6.0) < 1e-12) {
      ++gap;
      EXPECT_TRUE(X.y() < 0.03 || X.y() > 0.19) << X.transpose();
      const int column = static_cast<int>(std::floor(X.x() / 0.01)) + 1;
      EXPECT_TRUE(column == 4 || column == 8 || column == 12) << column;
      EXPECT_EQ(p.mu(0.0), 1e-4);
      EXPECT_EQ(p.mu(t_column1), 1e-4);
      EXPECT_EQ(p.mu(t_column2), 2.0);
    } else if (std::abs(p.radius(0.0) - 0.005) < 1e-12 && (X.y() < 0.03 || X.y() > 0.19)) {
      ++feet;
      EXPECT_NEAR(p.mu(t_column2), 1e-4, 1e-12);
    }
  }
  EXPECT_EQ(gap, 2 * 2 * 3 * 3);  // two feet, both layers, 3 columns x 3 rows
  EXPECT_EQ(feet, 2 * 2 * 12 * 3);

  // Without actuation.feet there is nothing to take the timing from.
  std::string text = voxel_lattice_scene(", gap_foot_columns: true");
  const auto feet_key = text.find("  feet:");
  ASSERT_NE(feet_key, std::string::npos);
  text.erase(feet_key, text.find('\n', feet_key) + 1 - feet_key);
  TempScene no_feet(text);
  const Scene bare = read_scene(no_feet.file.string());
  const Mesh bare_mesh = build_scene_mesh(bare, PETSC_COMM_WORLD);
  try {
    lattice_points(bare, bare_mesh);
    ADD_FAILURE() << "gap_foot_columns without feet was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gap_foot_columns"), std::string::npos) << e.what();
  }
  const std::string bad = error_of(voxel_lattice_scene(", gap_foot_columns: maybe"));
  EXPECT_NE(bad.find("contact.lattice_floor.gap_foot_columns"), std::string::npos) << bad;
}
