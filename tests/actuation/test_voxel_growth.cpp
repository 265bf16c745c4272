// The voxel study's actuation as growth: its timeline reproduces the lattice's step
// counts (baselines.txt) and the growth reaches the lattice's scale factors.
#include <gtest/gtest.h>

#include "actuation/voxel_growth.h"

using namespace morphfem;

namespace {
Schedule rolling() {
  ScheduleMatrix m(kNumRows, std::vector<int>(8, 0));
  for (int k = 0; k < 8; ++k) m[7 - k][k] = 1;  // bladders 8, 7, ..., 1 one per column
  return Schedule::from_matrix(m, 1.237, 2, 0.0, 12000.0);
}
Schedule empty() { return Schedule::from_matrix(ScheduleMatrix(kNumRows, std::vector<int>(8, 0)), 1.237, 2); }
}  // namespace

TEST(VoxelGrowth, TimelineMatchesTheLatticeStepCounts) {
  const VoxelActuation model;
  EXPECT_EQ(model.swing_steps(), 7667);  // ceil(2.3 / 3e-4)
  // Empty schedule: 16 columns of 1 + 4001 steps = 64032 steps (baselines.txt, exact).
  EXPECT_NEAR(voxel_timeline(empty(), model).duration(), 64032 * model.step_s, 1e-9);
  // Rolling: 16 columns of 7668 + 4001 steps; the lattice took 186719 steps in all
  // (its float32 scale factors need one extra step in 15 of the 32 swings).
  const VoxelTimeline roll = voxel_timeline(rolling(), model);
  EXPECT_NEAR(roll.duration(), 16 * 11669 * model.step_s, 1e-9);
  EXPECT_LT(std::abs(roll.duration() - 186719 * model.step_s) / (186719 * model.step_s), 1e-4);
  EXPECT_NEAR(roll.actuation_end[0], 7668 * model.step_s, 1e-12);
}

TEST(VoxelGrowth, BladderGrowsToTheLatticeScaleAndBack) {
  const VoxelActuation model;
  const double start = 2.0, swing = model.swing_steps() * model.step_s;
  const Schedule s = rolling();
  const VoxelTimeline timeline = voxel_timeline(s, model);
  // Bladder 8 (index 7) inflates in column 0 and deflates in column 1.
  const StretchFunction g8 = voxel_bladder_growth(s, 7, start, 12000.0, model);
  EXPECT_TRUE(g8(start - 0.5).isApprox(Eigen::Vector3d::Ones()));
  const Eigen::Vector3d full = g8(start + swing);
  EXPECT_NEAR(full.x(), 1.0 + 7667 * 3e-4 / 20, 1e-12);
  EXPECT_NEAR(full.y(), 1.0 + 7667 * 3e-4 / 10.0, 1e-12);  // c(12 kPa) = 10
  EXPECT_NEAR(full.z(), 2.5 / 0.2, 1e-12);
  EXPECT_NEAR(g8(start + 0.5 * swing).z(), 1.0 + 0.5 * 11.5, 1e-9);  // linear in time
  EXPECT_TRUE(g8(start + timeline.column_start[1] + swing).isApprox(Eigen::Vector3d::Ones()));
  // At zero core pressure the along-y growth is larger: c(0) = 1.7.
  const StretchFunction g8_flat = voxel_bladder_growth(s, 7, start, 0.0, model);
  EXPECT_NEAR(g8_flat(start + swing).y(), 1.0 + 7667 * 3e-4 / 1.7, 1e-12);
  // Bladder 1 (index 0) inflates only in columns 7 and 15.
  const StretchFunction g1 = voxel_bladder_growth(s, 0, start, 12000.0, model);
  EXPECT_TRUE(g1(start + timeline.column_end[6]).isApprox(Eigen::Vector3d::Ones()));
  EXPECT_NEAR(g1(start + timeline.column_start[7] + swing).z(), 12.5, 1e-9);
}

TEST(VoxelGrowth, FeetFollowTheirRowsOnlyDuringActuationPhases) {
  const VoxelActuation model;
  ScheduleMatrix m(kNumRows, std::vector<int>(8, 0));
  for (int k = 0; k < 8; k += 2) m[0][k] = 1;  // bladder 1 on odd columns (1-based)
  for (int k = 1; k < 8; k += 2) m[8][k] = 1;  // foot A active on even columns
  const Schedule s = Schedule::from_matrix(m, 1.237, 2);
  const VoxelTimeline timeline = voxel_timeline(s, model);
  const TimeFunction mu = voxel_foot_friction(s, kChannelFootA, 1.0, 2.0, 1e-4, model);
  EXPECT_EQ(mu(0.5), 2.0);                                                                 // settling before the gait
  EXPECT_NEAR(mu(1.0 + 0.5 * timeline.actuation_end[0]), 1e-4, 1e-15);                     // column 1: inactive
  EXPECT_EQ(mu(1.0 + 0.5 * (timeline.actuation_end[0] + timeline.column_end[0])), 2.0);    // its settle phase
  EXPECT_EQ(mu(1.0 + 0.5 * (timeline.column_start[1] + timeline.actuation_end[1])), 2.0);  // column 2: active
  EXPECT_EQ(mu(1.0 + timeline.duration() + 1.0), 2.0);
}

// The gap columns' feet (the study's varF[3]): inactive while settling and in column
// 1's actuation phase, active from its settle phase on, also in columns where feet A
// and B are inactive.
TEST(VoxelGrowth, GapColumnFeetStayActiveFromTheFirstSettlePhase) {
  const VoxelActuation model;
  ScheduleMatrix m(kNumRows, std::vector<int>(8, 0));
  for (int k = 0; k < 8; ++k) m[k][k] = 1;  // rolling: feet A and B inactive in every column
  const Schedule s = Schedule::from_matrix(m, 1.237, 2);
  const VoxelTimeline timeline = voxel_timeline(s, model);
  const TimeFunction mu = voxel_gap_foot_friction(s, 1.0, 2.0, 1e-4, model);
  const TimeFunction foot_a = voxel_foot_friction(s, kChannelFootA, 1.0, 2.0, 1e-4, model);
  EXPECT_EQ(mu(0.5), 1e-4);                                            // settling before the gait
  EXPECT_EQ(mu(1.0 + 0.5 * timeline.actuation_end[0]), 1e-4);          // column 1's actuation
  EXPECT_EQ(mu(1.0 + timeline.actuation_end[0] + model.step_s), 2.0);  // its settle phase
  for (size_t k = 1; k < timeline.column_start.size(); ++k) {          // every later actuation phase
    const double t = 1.0 + 0.5 * (timeline.column_start[k] + timeline.actuation_end[k]);
    EXPECT_EQ(mu(t), 2.0) << k;
    EXPECT_NEAR(foot_a(t), 1e-4, 1e-15) << k;  // while feet A and B are inactive
  }
  EXPECT_EQ(mu(1.0 + timeline.duration() + 1.0), 2.0);
}
