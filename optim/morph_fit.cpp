#include "optim/morph_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace morphfem {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A sample's field linearly interpolated at t (held constant outside the samples).
template <class Field>
double at_time(const std::vector<ShapeSample>& s, double t, Field field) {
  if (s.empty()) throw std::invalid_argument("no shape samples");
  if (t <= s.front().t) return field(s.front());
  if (t >= s.back().t) return field(s.back());
  const auto hi = std::lower_bound(s.begin(), s.end(), t, [](const ShapeSample& a, double v) { return a.t < v; });
  const auto lo = hi - 1;
  const double w = (t - lo->t) / (hi->t - lo->t);
  return (1 - w) * field(*lo) + w * field(*hi);
}

double height_at(const std::vector<ShapeSample>& s, double t) {
  return at_time(s, t, [](const ShapeSample& a) { return a.height; });
}
double width_at(const std::vector<ShapeSample>& s, double t) {
  return at_time(s, t, [](const ShapeSample& a) { return a.width; });
}

// h moved less than 1 % of the phase's change over its last 10 %.
bool settled(const std::vector<ShapeSample>& s, double from, double to) {
  const double change = std::abs(height_at(s, to) - height_at(s, from));
  const double tail = std::abs(height_at(s, to) - height_at(s, to - 0.1 * (to - from)));
  return change > 0 && tail < 0.01 * change;
}

}  // namespace

MorphPhases morph_phases(const std::vector<std::pair<double, double>>& supply, double end_time) {
  MorphPhases p;
  p.end = end_time;
  // p_s is piecewise linear: the first time it is > 0 (< 0) is a table point or the
  // crossing on the segment into it.
  auto first = [&](double after, bool positive) {
    for (size_t i = 0; i < supply.size(); ++i) {
      const auto [t, v] = supply[i];
      if (t < after || !(positive ? v > 0 : v < 0)) continue;
      if (i == 0 || supply[i - 1].first < after) return std::max(t, after);
      const auto [t0, v0] = supply[i - 1];
      const double crossing = t0 + (t - t0) * (0 - v0) / (v - v0);  // v0 on the other side or 0
      return std::max(crossing, after);
    }
    return kNaN;
  };
  p.inflate = first(-std::numeric_limits<double>::infinity(), true);
  if (std::isnan(p.inflate))
    throw std::invalid_argument("the core's supply pressure never turns positive (no inflation phase)");
  if (!(p.inflate < end_time)) throw std::invalid_argument("the inflation starts after the end of the run");
  p.deflate = first(p.inflate, false);  // NaN: no vacuum phase (an inflation-only run)
  if (!(p.deflate < end_time)) p.deflate = kNaN;
  return p;
}

double shape_change_time(const std::vector<ShapeSample>& s, double from, double to, double fraction) {
  const double h0 = height_at(s, from), h1 = height_at(s, to);
  if (h1 == h0) return kNaN;  // no change to time (h is continuous: any other goal is reached)
  const double goal = h0 + fraction * (h1 - h0);
  const double sign = h1 >= h0 ? 1.0 : -1.0;
  double t_prev = from, h_prev = h0;
  for (const ShapeSample& x : s) {
    if (x.t <= from) continue;
    if (x.t > to) break;
    if (sign * (x.height - goal) >= 0) {
      const double w = x.height == h_prev ? 1.0 : (goal - h_prev) / (x.height - h_prev);
      return t_prev + w * (x.t - t_prev);
    }
    t_prev = x.t;
    h_prev = x.height;
  }
  return kNaN;
}

MorphMeasures measure_morphing(const std::vector<ShapeSample>& s, const MorphPhases& p, double fraction) {
  if (!(fraction > 0 && fraction < 1)) throw std::invalid_argument("the shape-change fraction must be in (0, 1)");
  MorphMeasures m;
  const bool vacuum = !std::isnan(p.deflate);
  const double inflated = vacuum ? p.deflate : p.end;  // the end of the inflation phase
  m.inflate_time = shape_change_time(s, p.inflate, inflated, fraction) - p.inflate;
  m.start_height = height_at(s, p.inflate);
  m.inflated_width = width_at(s, inflated);
  m.inflated_height = height_at(s, inflated);
  m.inflated_diameter = 0.5 * (m.inflated_width + m.inflated_height);
  m.inflate_settled = settled(s, p.inflate, inflated);
  if (vacuum) {
    m.deflate_time = shape_change_time(s, p.deflate, p.end, fraction) - p.deflate;
    m.flat_height = height_at(s, p.end);
    m.deflate_settled = settled(s, p.deflate, p.end);
  } else {
    m.deflate_time = m.flat_height = kNaN;
  }
  return m;
}

double next_conductance(const std::vector<std::pair<double, double>>& history, double target_time) {
  if (history.empty()) throw std::invalid_argument("next_conductance needs at least one run");
  const auto [C, t] = history.back();
  if (!(C > 0 && t > 0 && target_time > 0)) throw std::invalid_argument("conductances and times must be positive");
  double b = 1.0;  // t ~ C^-b
  if (history.size() >= 2) {
    const auto [C0, t0] = history[history.size() - 2];
    const double dlogC = std::log(C / C0);
    // Trust the secant only when the runs differ and it gives a plausible exponent.
    if (std::abs(dlogC) > 1e-6) {
      const double slope = -std::log(t / t0) / dlogC;
      if (slope > 0.25 && slope < 4) b = slope;
    }
  }
  return C * std::pow(t / target_time, 1.0 / b);
}

}  // namespace morphfem
