#include "actuation/schedule_clock.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "actuation/schedule_loads.h"
#include "core/errors.h"

namespace morphfem {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The value at t of a quantity that, from each column start starts[k] on, moves
// towards target(k) at the given rates [unit/s], from `rest` before the first.
template <class Target>
double follow_columns(const std::vector<double>& starts, double t, double rest, const Target& target, double rise,
                      double fall) {
  double value = rest;
  for (std::size_t k = 0; k < starts.size() && starts[k] < t; ++k) {
    const double until = k + 1 < starts.size() ? std::min(t, starts[k + 1]) : t;
    value = ramp_towards(value, target(static_cast<int>(k)), rise, fall, until - starts[k]);
  }
  return value;
}

}  // namespace

ScheduleClock::ScheduleClock(Schedule schedule, double start, const std::array<double, kNumChannels>& tolerance_pa,
                             double step_s, double switch_s)
    : schedule_(std::move(schedule)),
      start_(start),
      tolerance_pa_(tolerance_pa),
      levels_(load_levels(schedule_, step_s)),
      switch_s_(switch_s) {
  for (double tolerance : tolerance_pa_)
    if (!(tolerance > 0)) throw std::invalid_argument("schedule clock: tolerances must be positive");
}

double ScheduleClock::setpoint_pa(int channel, double t) const {
  if (channel < 0 || channel >= kNumChannels) throw std::invalid_argument("channel out of range");
  const ChannelLevels& lv = levels_[channel];
  const auto target = [&](int k) { return schedule_.target_pa(channel, k, levels_); };
  return follow_columns(starts_, t, target(-1), target, lv.rise_rate(), lv.fall_rate());
}

double ScheduleClock::foot_mu(int foot_channel, double t, double mu_active, double mu_inactive) const {
  if (foot_channel != kChannelFootA && foot_channel != kChannelFootB)
    throw std::invalid_argument("foot_mu needs a foot channel");
  const int row = channel_row(foot_channel), columns = schedule_.total_columns();
  const auto target = [&](int k) {  // active at rest (k < 0, k >= columns), as the schedule says
    return k < 0 || k >= columns || schedule_.active(row, k) ? mu_active : mu_inactive;
  };
  const double rate = std::abs(mu_active - mu_inactive) / switch_s_;
  return follow_columns(starts_, t, mu_active, target, rate, rate);
}

bool ScheduleClock::end_of_step(double t, const std::vector<Reading>& readings) {
  const int k = column();
  if (k >= schedule_.total_columns() || timed_out_column_ >= 0) return false;
  bool settled = true;
  for (const Reading& r : readings)
    settled = settled && channel_settled(r.pressure_pa, r.setpoint_pa, schedule_.target_pa(r.channel, k),
                                         tolerance_pa_[r.channel]);
  const double held = t - (k < 0 ? 0.0 : starts_[k]);  // the rest phase began with the run
  if (schedule_.cadence.may_end(k, held, start_, settled)) {
    starts_.push_back(t);
    return true;
  }
  if (schedule_.cadence.timed_out(k, held)) timed_out_column_ = k;
  return false;
}

double ScheduleClock::gait_start() const { return starts_.empty() ? kNaN : starts_.front(); }

double ScheduleClock::gait_end() const {
  const std::size_t columns = static_cast<std::size_t>(schedule_.total_columns());
  return starts_.size() > columns ? starts_[columns] : kNaN;
}

void ScheduleClock::save(StateRecord& state, const std::string& prefix) const {
  state.arrays[prefix + "column_starts"] = starts_;
  state.integers[prefix + "timed_out_column"] = timed_out_column_;
}

void ScheduleClock::load(const StateRecord& state, const std::string& prefix, const std::string& where) {
  starts_ = state.array(prefix + "column_starts", where);
  timed_out_column_ = static_cast<int>(state.integer(prefix + "timed_out_column", where));
  if (starts_.size() > static_cast<std::size_t>(schedule_.total_columns()) + 1)
    throw InputError(where, "the checkpoint's schedule has more columns than this scene's");
}

}  // namespace morphfem
