// Schedules as loads: the pressure and friction time functions reproduce the
// schedule's own setpoints.
#include <gtest/gtest.h>

#include "actuation/schedule_loads.h"

using namespace morphfem;

namespace {
Schedule rolling_with_ramps() {
  ScheduleMatrix m(kNumRows, std::vector<int>(8, 0));
  for (int k = 0; k < 8; ++k) m[7 - k][k] = 1;  // bladders 8, 7, ..., 1 one per column
  Schedule s = Schedule::from_matrix(m, 1.237, 2, 0.0, 12000.0);
  for (int b = 0; b < kNumBladders; ++b) {
    s.levels[b].inflate_pa = 25000;
    s.levels[b].inflate_ramp_s = 0.3;
    s.levels[b].deflate_ramp_s = 0.2;
  }
  return s;
}
}  // namespace

// The bladders have finite ramps, so the schedule's own setpoint is continuous and
// the time function must reproduce it exactly; the core is held.
TEST(ScheduleLoads, ChannelPressureIsTheSchedulesSetpointEverywhere) {
  const Schedule s = rolling_with_ramps();
  const double start = 0.5;
  for (int channel : {0, 3, 7, kChannelCore}) {
    const TimeFunction p = channel_pressure(s, channel, start);
    for (double t = -0.4; t < s.duration() + 1.0; t += 0.0037)
      EXPECT_NEAR(p(start + t), s.at(t).pressure_pa[channel], 1e-6) << "channel " << channel << " t " << t;
  }
}

TEST(ScheduleLoads, FootFrictionFollowsTheFootRows) {
  ScheduleMatrix m(kNumRows, std::vector<int>(8, 0));
  for (int k = 0; k < 8; ++k) {
    m[8][k] = k % 2;      // foot A on even (1-based) columns
    m[9][k] = 1 - k % 2;  // foot B on odd columns
  }
  const Schedule s = Schedule::from_matrix(m, 1.0, 1);
  const TimeFunction mu_a = foot_friction(s, kChannelFootA, 2.0, 2.0, 1e-4);
  const TimeFunction mu_b = foot_friction(s, kChannelFootB, 2.0, 2.0, 1e-4);
  EXPECT_DOUBLE_EQ(mu_a(1.0), 2.0);  // settling: all feet active
  for (int k = 0; k < 8; ++k) {
    const double t = 2.0 + k + 0.5;
    EXPECT_DOUBLE_EQ(mu_a(t), k % 2 ? 2.0 : 1e-4) << k;
    EXPECT_DOUBLE_EQ(mu_b(t), k % 2 ? 1e-4 : 2.0) << k;
  }
  EXPECT_DOUBLE_EQ(mu_a(11.0), 2.0);  // after the gait: at rest, active
}
