// Resumable runs (morphfem run --resume): a run stopped after some steps, as a
// killed one would be, and resumed from its checkpoint must give what the
// uninterrupted run gives: the same steps, Newton iterations, final state,
// trajectory and result files. Two scenes cover every term with history between
// steps: a block sliding down a slope with friction (inertia, implicit Euler,
// growing steps, ground contact) and a balloon filled through a valve with BDF2
// inertia and Kelvin-Voigt damping (gas amount, strain-rate history).
// Bad resumes (no checkpoint, another scene, nothing left to do) are refused.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <petscsys.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "tests/support/temp_dir.h"
#include "tests/support/tube_scene.h"

using namespace morphfem;
namespace fs = std::filesystem;

namespace {

// Friction, contact and implicit-Euler inertia (shared with kill_resume.cmake).
const std::string kSlide = MORPHFEM_SOURCE_DIR "/tests/sim/scenes/slide.yaml";

// A gas cavity fed through a valve, BDF2 inertia with Kelvin-Voigt damping.
const char* kBalloon = R"(
name: balloon
geometry: {type: spherical_shell, inner_radius: 0.010, outer_radius: 0.012, mesh_size: 0.004, order: 1}
materials:
  body: {model: neo_hookean, mu: 5.0e4, nu: 0.45, density: 1100}
boundary:
  - {surface: sym_x, fix: [x]}
  - {surface: sym_y, fix: [y]}
  - {surface: sym_z, fix: [z]}
loads:
  gas_cavities:
    - {name: bladder, surfaces: [inner], symmetry_factor: 8, supply_pressure: 5000, conductance: 1.7e-8}
dynamics: {scheme: bdf2, shear_viscosity: 20}
solver: {end_time: 0.4, initial_step: 0.01, max_step: 0.05}
output: {directory: out, every: 2, checkpoint_s: 0}
)";

// A valve-fed tube whose schedule plays in settle mode: the column starts the
// schedule clock decided, which the loads follow, are part of the state.
const std::string kSettleTube = "name: settle_tube\n" +
                                quarter_tube("inner_radius: 0.005, outer_radius: 0.01, height: 0.004, mesh_size: 0.004",
                                             "{model: dragon_skin_30}") +
                                R"(actuation:
  schedule: {morphfem_schedule: 1, cadence: {mode: settle, min_hold_s: 0.1},
             matrix: ["101", "000", "000", "000", "000", "000", "000", "000", "000", "000"],
             pressures: {feet: {inflate_pa: 0, deflate_pa: 0}}}
  start: 0.05
  bladders: {b1: inner}
  volume_axes: [x, y]
  valves: {fill_time_s: 0.05}
solver: {end_time: 0.8, initial_step: 0.005, max_step: 0.005}
output: {directory: out, every: 5, checkpoint_s: 0}
)";

struct SceneFile {
  fs::path dir, out;
  YAML::Node doc;
  // `source`: a scene's text, or (ending in .yaml) its file. Output goes to a fresh directory.
  SceneFile(const std::string& name, const std::string& source) {
    dir = temp_dir("resume_" + name);
    out = dir / "out";
    doc =
        source.size() > 5 && source.substr(source.size() - 5) == ".yaml" ? YAML::LoadFile(source) : YAML::Load(source);
    doc["output"]["directory"] = out.string();
  }
  Scene scene(const std::string& set_end_time = "") const {
    YAML::Node d = YAML::Clone(doc);
    if (!set_end_time.empty()) d["solver"]["end_time"] = set_end_time;
    return scene_from_yaml(d, (dir / "scene.yaml").string());
  }
  RunOptions options(bool resume, int stop_after = 0) const {
    RunOptions o;
    o.progress = false;
    o.resume = resume;
    o.stop_after_steps = stop_after;
    o.scene_text = scene_identity(doc);
    return o;
  }
};

// Rows x columns of a /tables dataset, or the number of /steps groups (table "").
std::vector<double> read_table(const fs::path& h5, const std::string& table, size_t& columns) {
  hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << h5;
  std::vector<double> values;
  if (table.empty()) {
    hid_t g = H5Gopen2(f, "/steps", H5P_DEFAULT);
    H5G_info_t info;
    H5Gget_info(g, &info);
    values.push_back(static_cast<double>(info.nlinks));
    H5Gclose(g);
  } else {
    hid_t d = H5Dopen2(f, ("/tables/" + table).c_str(), H5P_DEFAULT);
    hid_t space = H5Dget_space(d);
    hsize_t dims[2] = {0, 0};
    H5Sget_simple_extent_dims(space, dims, nullptr);
    columns = dims[1];
    values.resize(dims[0] * dims[1]);
    if (!values.empty()) H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
    H5Sclose(space);
    H5Dclose(d);
  }
  H5Fclose(f);
  return values;
}

double max_abs_diff(const RowMatrixXd& a, const RowMatrixXd& b) { return (a - b).cwiseAbs().maxCoeff(); }

// Uninterrupted run against one stopped after `stop` steps and resumed (twice if stop2 > 0).
void expect_resume_matches(const std::string& name, const std::string& text, int stop, int stop2) {
  SceneFile whole(name + "_whole", text), parts(name + "_parts", text);
  const auto a = run_scene(whole.scene(), PETSC_COMM_WORLD, whole.options(false));
  ASSERT_TRUE(a.stats.completed) << a.stats.failure;

  const auto s1 = run_scene(parts.scene(), PETSC_COMM_WORLD, parts.options(false, stop));
  ASSERT_TRUE(s1.stopped);
  EXPECT_TRUE(fs::exists(parts.out.string() + ".partial/checkpoint.h5"));
  EXPECT_FALSE(fs::exists(parts.out)) << "a stopped run must not commit its output";
  if (stop2 > 0) {
    const auto s2 = run_scene(parts.scene(), PETSC_COMM_WORLD, parts.options(true, stop2));
    ASSERT_TRUE(s2.stopped);
    EXPECT_GT(s2.resumed_at, 0.0);
  }
  const auto b = run_scene(parts.scene(), PETSC_COMM_WORLD, parts.options(true));
  ASSERT_TRUE(b.stats.completed) << b.stats.failure;
  EXPECT_GT(b.resumed_at, 0.0);
  EXPECT_LT(b.resumed_at, 0.9 * whole.scene().solver.t_end) << "the stops should come before the end";

  // The same sequence of steps and iterations, the same state.
  EXPECT_EQ(a.stats.steps, b.stats.steps);
  EXPECT_EQ(a.stats.newton_its, b.stats.newton_its);
  EXPECT_EQ(a.stats.step_cuts, b.stats.step_cuts);
  EXPECT_EQ(a.stats.cuts_by_cause, b.stats.cuts_by_cause);  // kept in the checkpoint
  int by_cause = 0;
  for (const auto& [cause, n] : b.stats.cuts_by_cause) by_cause += n;
  EXPECT_EQ(by_cause, b.stats.step_cuts);
  const double scale = a.u.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  EXPECT_LE(max_abs_diff(a.u, b.u), 1e-12 * scale) << "final displacement";
  ASSERT_EQ(a.cavity_pressure.size(), b.cavity_pressure.size());
  for (size_t i = 0; i < a.cavity_pressure.size(); ++i)
    EXPECT_NEAR(a.cavity_pressure[i], b.cavity_pressure[i], 1e-10 * std::abs(a.cavity_pressure[i]));
  EXPECT_EQ(a.trajectory.size(), b.trajectory.size());
  EXPECT_EQ(a.column_starts, b.column_starts);

  // The same result files: as many steps, and the same energy table row by row.
  const fs::path ha = whole.out / (name + ".h5"), hb = parts.out / (name + ".h5");
  ASSERT_TRUE(fs::exists(hb));
  EXPECT_FALSE(fs::exists(parts.out.string() + ".partial"));
  size_t ca = 0, cb = 0;
  EXPECT_EQ(read_table(ha, "", ca), read_table(hb, "", cb));
  const auto ea = read_table(ha, "energy", ca), eb = read_table(hb, "energy", cb);
  ASSERT_EQ(ca, cb);
  ASSERT_EQ(ea.size(), eb.size());
  for (size_t i = 0; i < ea.size(); ++i)
    EXPECT_NEAR(ea[i], eb[i], 1e-9 * std::max(1e-12, std::abs(ea[i]))) << "energy table entry " << i;
}

}  // namespace

TEST(Resume, SlidingBlockWithFrictionContinuesExactly) { expect_resume_matches("slide", kSlide, 7, 0); }

TEST(Resume, ValveFedBalloonWithBdf2AndDampingContinuesExactly) { expect_resume_matches("balloon", kBalloon, 4, 3); }

TEST(Resume, SettleCadenceContinuesWithItsColumnStarts) {
  SceneFile probe("settle_probe", kSettleTube);
  const auto whole = run_scene(probe.scene(), PETSC_COMM_WORLD, probe.options(false));
  ASSERT_TRUE(whole.gait_complete) << "the gait should end within the run";
  ASSERT_EQ(whole.column_starts.size(), 4u);
  EXPECT_GT(whole.column_starts[1], 0.05 + 0.1) << "the first column lasts past its hold: the valve decides";
  expect_resume_matches("settle_tube", kSettleTube, 40, 50);  // stops in the first and the second column
}

// The sliding block with at most six Newton iterations per step has its steps
// cut: the counts by cause continue across the checkpoints as the other counters do.
TEST(Resume, StepCutsKeepTheirCausesAcrossCheckpoints) {
  SceneFile once("cuts_once", kSlide);
  once.doc["solver"]["max_newton_its"] = 6;
  const auto a = run_scene(once.scene(), PETSC_COMM_WORLD, once.options(false));
  ASSERT_TRUE(a.stats.completed) << a.stats.failure;
  ASSERT_GT(a.stats.step_cuts, 0);
  EXPECT_EQ(a.stats.cuts_by_cause.count("DIVERGED_MAX_IT"), 1u);
  YAML::Node doc = YAML::LoadFile(kSlide);
  doc["name"] = "slide_cuts";
  doc["solver"]["max_newton_its"] = 6;
  expect_resume_matches("slide_cuts", YAML::Dump(doc), 30, 40);
}

// A finished run extended to a later end time takes the same steps as a run
// straight to that time that also lands a step on the old end time.
TEST(Resume, FinishedRunExtendsToALaterEndTime) {
  SceneFile once("extend_once", kSlide), twice("extend_twice", kSlide);
  Scene straight = once.scene("0.5");
  straight.solver.output_times.push_back(0.3);  // a step ends exactly at 0.3 s, as in the first part
  const auto a = run_scene(straight, PETSC_COMM_WORLD, once.options(false));
  const auto first = run_scene(twice.scene("0.3"), PETSC_COMM_WORLD, twice.options(false));
  ASSERT_TRUE(a.stats.completed && first.stats.completed);
  EXPECT_TRUE(fs::exists(twice.out / "checkpoint.h5")) << "a finished run keeps its final checkpoint";
  const auto b = run_scene(twice.scene("0.5"), PETSC_COMM_WORLD, twice.options(true));
  ASSERT_TRUE(b.stats.completed) << b.stats.failure;
  EXPECT_NEAR(b.resumed_at, 0.3, 1e-12);
  EXPECT_EQ(a.stats.steps, b.stats.steps);
  EXPECT_LE(max_abs_diff(a.u, b.u), 1e-12 * a.u.cwiseAbs().maxCoeff());
}

TEST(Resume, BadResumesAreRefusedWithAClearMessage) {
  SceneFile s("bad", kSlide);
  auto message = [&](const Scene& scene, const RunOptions& options) -> std::string {
    try {
      run_scene(scene, PETSC_COMM_WORLD, options);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message(s.scene(), s.options(true)).find("no checkpoint"), std::string::npos);
  EXPECT_FALSE(fs::exists(s.out.string() + ".partial")) << "a refused resume must not leave output behind";

  ASSERT_TRUE(run_scene(s.scene(), PETSC_COMM_WORLD, s.options(false, 5)).stopped);
  // Another scene: a changed material.
  RunOptions other = s.options(true);
  YAML::Node changed = YAML::Clone(s.doc);
  changed["materials"]["body"]["mu"] = 2.0e6;
  other.scene_text = scene_identity(changed);
  const std::string diff = message(scene_from_yaml(changed, "changed.yaml"), other);
  EXPECT_NE(diff.find("the scene differs"), std::string::npos) << diff;
  EXPECT_NE(diff.find("mu"), std::string::npos) << diff;
  // The checkpoint is still there after the refusals, and resumes.
  EXPECT_TRUE(fs::exists(s.out.string() + ".partial/checkpoint.h5"));
  ASSERT_TRUE(run_scene(s.scene(), PETSC_COMM_WORLD, s.options(true)).stats.completed);
  // Nothing left to do at the same end time.
  EXPECT_NE(message(s.scene(), s.options(true)).find("later solver.end_time"), std::string::npos);
  EXPECT_TRUE(fs::exists(s.out / "slide.h5")) << "a refused extension must keep the finished results";
}

TEST(Resume, SceneIdentityIgnoresOnlyTheEndTimeAndTheCheckpointInterval) {
  const YAML::Node a = YAML::Load("solver: {end_time: 1, max_step: 0.1}\nname: x\noutput: {every: 2}\n");
  const YAML::Node b =
      YAML::Load("solver: {end_time: 7, max_step: 0.1}\nname: x\noutput: {every: 2, checkpoint_s: 5}\n");
  const YAML::Node c = YAML::Load("solver: {end_time: 1, max_step: 0.2}\nname: x\noutput: {every: 2}\n");
  const YAML::Node d = YAML::Load("solver: {end_time: 1, max_step: 0.1}\nname: x\noutput: {every: 3}\n");
  EXPECT_EQ(scene_identity(a), scene_identity(b));
  EXPECT_NE(scene_identity(a), scene_identity(c));
  EXPECT_NE(scene_identity(a), scene_identity(d));
  EXPECT_EQ(a["solver"]["end_time"].as<double>(), 1.0) << "the document itself is not changed";
}
