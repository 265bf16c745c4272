// The gait examples (examples/gaits/*.yaml) are the converged scenes of the voxel
// study's four hand-designed gaits, the first thing a user runs: each must be the
// scene `morphfem robot scene` writes for its case (so that it cannot drift from the
// preset the validation uses), and each must move the way its header says on its
// first push or stroke.
#include <gtest/gtest.h>
#include <petscsys.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>
#include <vector>

#include "robot/robot_study.h"
#include "sim/scene.h"
#include "sim/simulation.h"

namespace morphfem {
namespace {

// Every gait's first push or stroke moves the body forward along its heading (uphill on
// the hill): measured at this level 3.7 mm (roll_flat), 46 mm (roll_hill15, which later
// tumbles back down the hill: -0.77 BL/s over the gait), 29 mm (inch_flat) and 17 mm
// (inch_hill15) in the first column.
const std::vector<std::string>& gait_examples() {
  static const std::vector<std::string> examples = {"roll_flat", "roll_hill15", "inch_flat", "inch_hill15"};
  return examples;
}

std::string example_path(const std::string& name) {
  return std::string(MORPHFEM_SOURCE_DIR) + "/examples/gaits/" + name + ".yaml";
}

TEST(GaitExamples, AreTheScenesTheirCasesRun) {
  const RobotFidelity& level = find_robot_fidelity("0.02:2:0.1");
  const auto cases = preset_cases("lattice-mechanics", {"lattice-mechanics"});
  for (const auto& name : gait_examples()) {
    const YAML::Node generated = robot_scene_yaml(find_case(cases, name), level, "results/" + name);
    const YAML::Node file = load_scene_yaml(example_path(name));
    EXPECT_EQ(YAML::Dump(file), YAML::Dump(generated))
        << name << ": rewrite it with morphfem robot scene --case " << name
        << " --preset lattice-mechanics --fidelity 0.02:2:0.1 --out examples/gaits/" << name << ".yaml";
  }
}

// Displacement of the mean node position along the scene's heading [m] from the
// gait's start to the end of the run.
double displacement_along_heading(const Scene& scene, const SimulationResult& r) {
  double start = NAN, end = NAN;
  for (const auto& [t, x, y, z] : r.trajectory) {
    const double along = Eigen::Vector3d(x, y, z).dot(scene.gait.heading);
    if (std::isnan(start) && t >= scene.gait.start - 1e-9) start = along;
    end = along;
  }
  return end - start;
}

class GaitExample : public ::testing::TestWithParam<std::string> {};

// The example itself, run to the end of its first column (2.74 s of 21.3 s).
TEST_P(GaitExample, FirstColumnMovesForward) {
  const std::string& name = GetParam();
  YAML::Node doc = load_scene_yaml(example_path(name));
  const double first_column_end =
      doc["actuation"]["start"].as<double>() + doc["actuation"]["schedule"]["column_s"].as<double>();
  set_scene_key(doc, "solver.end_time=" + std::to_string(first_column_end), "test");
  const Scene scene = scene_from_yaml(doc, example_path(name));
  const SimulationResult r = run_scene(scene, PETSC_COMM_WORLD, RunOptions(false, false));
  ASSERT_TRUE(r.stats.completed) << name << ": " << r.stats.failure;
  const double moved = displacement_along_heading(scene, r);
  EXPECT_GT(moved, 1e-3) << name << " moved " << moved << " m along its heading in its first column";
}

INSTANTIATE_TEST_SUITE_P(Examples, GaitExample, ::testing::ValuesIn(gait_examples()),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace morphfem
