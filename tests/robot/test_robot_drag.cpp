// `morphfem robot friction-drag` (robot/robot_drag.cpp): the pull test on the physical
// laminate standing on its foot pads, on a coarse mesh and 6 mm of travel. Checks what
// the physics fixes exactly: the weight is the robot's mass (analytic region volumes x
// densities) x g; once the robot slides, the load cell reads mu W with mu the feet's
// coefficient in that state (all the weight is on the feet); the static peak cannot
// exceed it; the pre-slip slope is the pull spring in series with a stiffer robot. The
// exports are read back by the test-machine reader, as measured ones are.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <filesystem>

#include "core/errors.h"
#include "core/test_machine_export.h"
#include "optim/pull_test.h"
#include "robot/robot_study.h"
#include "robot/studies.h"
#include "tests/support/temp_dir.h"

using namespace morphfem;

namespace {

// Mass of robot_physical with its defaults and foot_pad 0.004 (friction_drag.yaml's
// densities) [kg]; the region volumes as in tests/mesh/test_robot.cpp.
double physical_robot_mass() {
  const double W = 0.10, L = 0.15, t = 0.003, tf = 0.0005, g = 0.001, e = 0.005, s = 0.005, hb = 0.003, w = 0.0008;
  const double bw = 0.02, f = 0.02, pad = 0.004;
  const double fabric = 2 * W * L * tf;
  const double skin = 2 * W * L * (t - tf) + 2 * e * L * g + 2 * (W - 2 * e) * s * g;
  const double chamber = (bw - 2 * w) * (L - 2 * f - 2 * w) * (hb - 2 * w);
  const double bladder = bw * (L - 2 * f) * hb - chamber;
  const double foot = 2 * W * f * pad;
  return 1070 * (skin + foot) + 1500 * fabric + 1080 * 8 * bladder;
}

}  // namespace

TEST(RobotFrictionDrag, FeetSlideAtTheirCoefficientAndTheExportsReadBack) {
  const auto dir = temp_dir("friction_drag");
  FrictionDragOptions o;
  o.travel_mm = "6";
  o.set = {"geometry.mesh_size=0.02"};
  o.out_dir = dir.string();
  ASSERT_EQ(robot_friction_drag(o, PETSC_COMM_WORLD), 0);
  const double weight = physical_robot_mass() * 9.80665;
  for (const auto& [state, mu] : {std::pair<std::string, double>{"inflated", 0.70}, {"deflated", 0.56}}) {
    const auto file = dir / ("wood_" + state + "_sim.csv");
    ASSERT_TRUE(std::filesystem::exists(file)) << file;
    const auto specimens = read_test_machine_export(file.string());
    ASSERT_EQ(specimens.size(), 1u);
    double written_weight = 0;
    ASSERT_TRUE(parse_export_number(specimens[0].header_value("weight"), false, written_weight));
    EXPECT_NEAR(written_weight, weight, 1e-6 * weight) << state;
    const PullCurve curve = pull_curve_from_export(specimens[0]);
    EXPECT_EQ(curve.foot_state, state);
    EXPECT_EQ(curve.surface, "wood");
    EXPECT_NEAR(curve.displacement.back(), 0.006, 1e-6);
    const PullAnalysis a = analyse_pull(curve, weight);
    EXPECT_NEAR(a.mu_kinetic, mu, 0.003 * mu) << state;
    EXPECT_LE(a.mu_peak, 1.005 * mu) << state;
    EXPECT_GE(a.mu_peak, a.mu_kinetic - 1e-3) << state;
    EXPECT_LT(a.mu_linear, a.mu_peak) << state;
    EXPECT_GT(a.slope_N_per_m, 0.9 * 250.0) << state;
    EXPECT_LT(a.slope_N_per_m, 250.0) << state;
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "friction_drag.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / "inflated" / "summary.json"));
}

TEST(RobotFrictionDrag, RefusesBadFeetAndScenesWithoutAMachine) {
  const auto dir = temp_dir("friction_drag_bad");
  FrictionDragOptions wet;
  wet.feet = {"wet"};
  wet.out_dir = dir.string();
  EXPECT_THROW(robot_friction_drag(wet, PETSC_COMM_WORLD), InputError);
  FrictionDragOptions backwards;
  backwards.travel_mm = "-3";
  backwards.out_dir = dir.string();
  EXPECT_THROW(robot_friction_drag(backwards, PETSC_COMM_WORLD), InputError);
  FrictionDragOptions no_machine;
  no_machine.scene = std::string(MORPHFEM_SOURCE_DIR) + "/examples/physical/roll_slice.yaml";
  no_machine.out_dir = dir.string();
  EXPECT_THROW(robot_friction_drag(no_machine, PETSC_COMM_WORLD), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "wood_inflated_sim.csv"));
}
