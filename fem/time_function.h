// Scalar functions of time for loads: a constant, a linear ramp, a piecewise-
// linear table of (time [s], value) points held constant outside the table, or a
// function another object evaluates (a schedule clock whose column times are
// decided while the simulation runs, actuation/schedule_clock.h).
#pragma once
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace morphfem {

class TimeFunction {
 public:
  TimeFunction() = default;
  static TimeFunction constant(double value) { return TimeFunction({{0.0, value}}); }
  // value(t) = to * clamp(t / duration, 0, 1)
  static TimeFunction ramp(double to, double duration) { return TimeFunction({{0.0, 0.0}, {duration, to}}); }
  // value(t) = evaluate(t); it has no table (points() is empty).
  static TimeFunction of(std::function<double(double)> evaluate);
  // Points must have strictly increasing times (throws std::invalid_argument).
  explicit TimeFunction(std::vector<std::pair<double, double>> points);
  double operator()(double t) const;
  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  std::vector<std::pair<double, double>> points_{{0.0, 0.0}};
  std::function<double(double)> evaluate_;
};

}  // namespace morphfem
