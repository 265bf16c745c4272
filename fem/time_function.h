// Scalar functions of time for loads: a constant, a linear ramp, or a piecewise-
// linear table of (time [s], value) points held constant outside the table.
#pragma once
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
  // Points must have strictly increasing times (throws std::invalid_argument).
  explicit TimeFunction(std::vector<std::pair<double, double>> points);
  double operator()(double t) const;
  const std::vector<std::pair<double, double>>& points() const { return points_; }

 private:
  std::vector<std::pair<double, double>> points_{{0.0, 0.0}};
};

}  // namespace morphfem
