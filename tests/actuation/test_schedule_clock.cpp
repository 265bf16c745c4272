// The settle-mode column clock (actuation/schedule_clock.h): with columns started
// at the fixed cadence's times it commands what the fixed-time loads command; a
// column starts only once every watched channel has settled and the column has
// lasted min_hold_s; a timeout stops it; a checkpoint restores it.
#include <gtest/gtest.h>

#include <cmath>

#include "actuation/schedule_clock.h"
#include "actuation/schedule_loads.h"

using namespace morphfem;

namespace {

// Bladders 8, 7, ..., 1 one per column (ramps 0.3 s up, 0.2 s down on b1..b4,
// steps on the others); feet alternating.
Schedule alternating_feet_rolling(int repeats) {
  ScheduleMatrix m(kNumRows, std::vector<int>(8, 0));
  for (int k = 0; k < 8; ++k) {
    m[7 - k][k] = 1;
    m[8][k] = k % 2;
    m[9][k] = 1 - k % 2;
  }
  Schedule s = Schedule::from_matrix(m, 1.237, repeats, 0.0, 12000.0);
  for (int b = 0; b < 4; ++b) {
    s.levels[b].inflate_ramp_s = 0.3;
    s.levels[b].deflate_ramp_s = 0.2;
  }
  s.cadence.mode = Cadence::Mode::settle;
  return s;
}

std::array<double, kNumChannels> tolerances(double pa) {
  std::array<double, kNumChannels> t;
  t.fill(pa);
  return t;
}

}  // namespace

// Started at start + k column_s, the clock's setpoints and foot friction are the
// fixed cadence's load functions (channel_pressure, foot_friction) at every time.
TEST(ScheduleClock, AtTheFixedTimesItCommandsTheFixedLoads) {
  const Schedule s = alternating_feet_rolling(2);
  const double start = 0.5;
  ScheduleClock clock(s, start, tolerances(2000));
  EXPECT_FALSE(clock.end_of_step(0.25, {})) << "the rest phase lasts until start";
  for (int k = 0; k <= s.total_columns(); ++k) EXPECT_TRUE(clock.end_of_step(start + k * s.column_s, {}));
  ASSERT_EQ(clock.column(), s.total_columns());
  EXPECT_DOUBLE_EQ(clock.gait_start(), start);
  EXPECT_DOUBLE_EQ(clock.gait_end(), start + s.duration());
  EXPECT_FALSE(clock.end_of_step(start + s.duration() + 1.0, {})) << "nothing after the gait";
  for (int channel : {0, 3, 4, 7, kChannelFootA}) {
    const TimeFunction fixed = channel_pressure(s, channel, start);
    for (double t = 0.0; t < start + s.duration() + 1.0; t += 0.0037)
      EXPECT_NEAR(clock.setpoint_pa(channel, t), fixed(t), 1e-6) << channel_name(channel) << " t " << t;
  }
  for (int foot : {kChannelFootA, kChannelFootB}) {
    const TimeFunction fixed = foot_friction(s, foot, start, 0.7, 0.56);
    for (double t = 0.0; t < start + s.duration() + 1.0; t += 0.0037)
      EXPECT_NEAR(clock.foot_mu(foot, t, 0.7, 0.56), fixed(t), 1e-9) << channel_name(foot) << " t " << t;
  }
}

// A column ends at the first step end where every watched channel is within its
// tolerance of a setpoint at the column's level, and min_hold_s has passed.
TEST(ScheduleClock, AColumnEndsWhenSettledAndHeld) {
  Schedule s = alternating_feet_rolling(1);
  s.cadence.min_hold_s = 0.4;
  s.cadence.timeout_s = 5.0;
  std::array<double, kNumChannels> tol = tolerances(2000);
  tol[7] = 500;  // b8
  ScheduleClock clock(s, 1.0, tol);
  // Rest: b8 deflated (0 Pa); the core held at 12 kPa.
  EXPECT_FALSE(clock.end_of_step(1.0, {{7, 0, 0}, {kChannelCore, 9000, 12000}})) << "core 3 kPa off";
  EXPECT_TRUE(clock.end_of_step(1.1, {{7, 0, 0}, {kChannelCore, 10500, 12000}}));
  EXPECT_EQ(clock.column(), 0);
  // Column 1 inflates b8 to 25 kPa.
  EXPECT_FALSE(clock.end_of_step(1.2, {{7, 24800, 25000}})) << "settled, but held 0.1 s < 0.4 s";
  EXPECT_FALSE(clock.end_of_step(1.6, {{7, 24400, 25000}})) << "600 Pa off, tolerance 500 Pa";
  EXPECT_FALSE(clock.end_of_step(1.7, {{7, 24900, 24000}})) << "the setpoint is still ramping";
  EXPECT_FALSE(clock.end_of_step(1.8, {{7, 24600, 25000}, {6, 0, 3000}})) << "b7 off its level";
  EXPECT_TRUE(clock.end_of_step(1.9, {{7, 24600, 25000}, {6, 1900, 0}}));
  EXPECT_EQ(clock.column(), 1);
  EXPECT_DOUBLE_EQ(clock.column_starts()[1], 1.9);
  // The setpoints follow the realised start: b8 falls from 1.9 s, b7 rises.
  EXPECT_DOUBLE_EQ(clock.setpoint_pa(7, 1.9), 25000);
  EXPECT_DOUBLE_EQ(clock.setpoint_pa(7, 1.9 + 2e-3), 0);
  EXPECT_DOUBLE_EQ(clock.setpoint_pa(6, 1.9 + 2e-3), 25000);
  // Column 2 never settles: after timeout_s it times out and the clock stops.
  EXPECT_FALSE(clock.end_of_step(6.8, {{6, 10000, 25000}}));
  EXPECT_EQ(clock.timed_out_column(), -1);
  EXPECT_FALSE(clock.end_of_step(7.0, {{6, 10000, 25000}}));
  EXPECT_EQ(clock.timed_out_column(), 1);
  EXPECT_FALSE(clock.end_of_step(7.1, {{6, 25000, 25000}})) << "a timed-out clock stays stopped";
  EXPECT_TRUE(std::isnan(clock.gait_end()));
}

// A checkpoint holds the column starts and the timeout: a clock loaded from it
// commands and decides as the saved one.
TEST(ScheduleClock, ACheckpointRestoresTheColumnStarts) {
  const Schedule s = alternating_feet_rolling(1);
  ScheduleClock a(s, 0.5, tolerances(2000)), b(s, 0.5, tolerances(2000));
  for (double t : {0.5, 1.3, 2.45, 3.0}) a.end_of_step(t, {});
  StateRecord state;
  a.save(state, "run.cadence.");
  b.load(state, "run.cadence.", "checkpoint.h5");
  EXPECT_EQ(a.column_starts(), b.column_starts());
  EXPECT_EQ(b.column(), 3);
  for (double t = 0; t < 4; t += 0.01) EXPECT_EQ(a.setpoint_pa(5, t), b.setpoint_pa(5, t));
  EXPECT_EQ(a.end_of_step(3.5, {}), b.end_of_step(3.5, {}));
}
