#include "actuation/schedule_loads.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace morphfem {

namespace {
// Sorted, strictly increasing (time, value) points.
TimeFunction from_samples(std::vector<std::pair<double, double>> points) {
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::pair<double, double>> unique;
  for (const auto& p : points)
    if (unique.empty() || p.first > unique.back().first + 1e-12) unique.push_back(p);
  return TimeFunction(unique);
}
}  // namespace

std::array<ChannelLevels, kNumChannels> load_levels(const Schedule& schedule, double step_s) {
  std::array<ChannelLevels, kNumChannels> levels = schedule.levels;
  // Bladder and foot steps get a short ramp so the load is continuous:
  // rate = swing / step_s. The core is held at its pressure from the start of
  // settling (schedule.h), so it keeps its own levels.
  for (int c = 0; c < kNumChannels; ++c) {
    if (c == kChannelCore) continue;
    if (levels[c].inflate_ramp_s <= 0) levels[c].inflate_ramp_s = step_s;
    if (levels[c].deflate_ramp_s <= 0) levels[c].deflate_ramp_s = step_s;
  }
  return levels;
}

TimeFunction channel_pressure(const Schedule& schedule, int channel, double start, double step_s) {
  if (channel < 0 || channel >= kNumChannels) throw std::invalid_argument("channel out of range");
  const std::array<ChannelLevels, kNumChannels> levels = load_levels(schedule, step_s);
  const ChannelLevels& lv = levels[channel];
  std::vector<double> times{-1.0};
  const int n = schedule.total_columns();
  for (int k = 0; k <= n; ++k) {
    const double boundary = k * schedule.column_s;
    times.push_back(boundary);
    // Where the ramp that starts at this boundary ends (if within the column).
    const double value = schedule.at(boundary - 1e-12, levels).pressure_pa[channel];
    const double target = schedule.target_pa(channel, k < n ? k : -1, levels);
    const double rate = target > value ? lv.rise_rate() : lv.fall_rate();
    if (std::isfinite(rate) && rate > 0 && target != value) times.push_back(boundary + std::abs(target - value) / rate);
  }
  std::vector<std::pair<double, double>> points;
  for (double t : times) points.emplace_back(start + t, schedule.at(t, levels).pressure_pa[channel]);
  return from_samples(points);
}

TimeFunction foot_friction(const Schedule& schedule, int foot_channel, double start, double mu_active,
                           double mu_inactive, double switch_s) {
  if (foot_channel != kChannelFootA && foot_channel != kChannelFootB)
    throw std::invalid_argument("foot_friction needs a foot channel");
  auto mu_at = [&](double t) {
    const ScheduleState s = schedule.at(t);
    return (foot_channel == kChannelFootA ? s.foot_a_active : s.foot_b_active) ? mu_active : mu_inactive;
  };
  std::vector<std::pair<double, double>> points{{start - 1.0, mu_at(-1.0)}};
  const int n = schedule.total_columns();
  for (int k = 0; k <= n; ++k) {
    const double boundary = k * schedule.column_s;
    points.emplace_back(start + boundary, mu_at(boundary - 1e-9));
    points.emplace_back(start + boundary + switch_s, mu_at(boundary + 1e-9));
  }
  return from_samples(points);
}

}  // namespace morphfem
