#include "hardware/pressure_watch.h"

#include <cmath>
#include <cstdio>

namespace morphfem::hw {

namespace {

// A number with the given printf precision, e.g. fixed(25000 / 1000.0, 1) = "25.0".
std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

}  // namespace

std::string PressureWatch::add(double sent_t, double read_t, double commanded_pa, double measured_pa) {
  if (!std::isfinite(commanded_pa) || !std::isfinite(measured_pa)) return "";
  hist_.push_back({std::min(sent_t, read_t), read_t, commanded_pa, measured_pa});
  // Keep the newest sample surely window_s before this one as the stall check's anchor.
  while (hist_.size() > 2 && hist_[1].t <= hist_.back().t0 - s_.window_s) hist_.pop_front();
  const double e = commanded_pa - measured_pa;
  if (std::abs(e) <= s_.off_pa) return "";
  const int side = e > 0 ? 1 : -1;  // +1: measured below the setpoint
  std::string why = falling(side);
  return why.empty() ? stalled(side) : why;
}

// Moved away from the setpoint by more than drop_pa within window_s although
// every command since the best reading held the pressure or pushed it towards
// the setpoint (a reading shows the pressure before the command sent with it acts).
std::string PressureWatch::falling(int side) const {
  const Sample& now = hist_.back();
  std::size_t best = hist_.size() - 1;
  for (std::size_t i = hist_.size() - 1; i-- > 0;) {
    const Sample& s = hist_[i];
    if (s.t < now.t - s_.window_s) break;
    if (side * (s.cmd - s.meas) < -s_.hold_band_pa) break;  // this command moved the pressure the other way
    if (side * (now.cmd - s.cmd) < -0.5) break;             // the setpoint has moved back since
    if (side * s.meas > side * hist_[best].meas) best = i;
  }
  const double away = side * (hist_[best].meas - now.meas);
  if (away <= s_.drop_pa) return "";
  return std::string("pressure ") + (side > 0 ? "fell " : "rose ") + fixed(away / 1000, 1) + " kPa in " +
         fixed(now.t - hist_[best].t, 3) + " s to " + fixed(now.meas / 1000, 1) + " kPa while its setpoint held at " +
         fixed(now.cmd / 1000, 1) + " kPa";
}

// Off on the same side since the anchor (at least window_s ago) and approaching
// the setpoint slower than min_rate_pa_per_s.
std::string PressureWatch::stalled(int side) const {
  const Sample& now = hist_.back();
  const Sample& anchor = hist_.front();
  const double span = now.t0 - anchor.t;  // the shortest time the two readings can be apart
  if (span < s_.window_s) return "";
  // Off all along: each reading from its own setpoint, and from the setpoint that
  // acted until the next reading (a reading shows the pressure before its command acts).
  for (std::size_t k = 0; k < hist_.size(); ++k) {
    if (side * (hist_[k].cmd - hist_[k].meas) <= s_.off_pa) return "";
    if (k + 1 < hist_.size() && side * (hist_[k].cmd - hist_[k + 1].meas) <= s_.off_pa) return "";
  }
  const double rate = side * (now.meas - anchor.meas) / span;
  if (rate >= s_.min_rate_pa_per_s) return "";
  return "measured " + fixed(now.meas / 1000, 1) + " kPa, setpoint " + fixed(now.cmd / 1000, 1) +
         " kPa: approaching it at " + fixed(rate / 1000, 1) + " kPa/s over " + fixed(span, 3) +
         " s, expected at least " + fixed(s_.min_rate_pa_per_s / 1000, 1) + " kPa/s";
}

}  // namespace morphfem::hw
