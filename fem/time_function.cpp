#include "fem/time_function.h"

#include <stdexcept>

namespace morphfem {

TimeFunction::TimeFunction(std::vector<std::pair<double, double>> points) : points_(std::move(points)) {
  if (points_.empty()) throw std::invalid_argument("a time function needs at least one point");
  for (size_t i = 1; i < points_.size(); ++i)
    if (!(points_[i].first > points_[i - 1].first))
      throw std::invalid_argument("time function points must have strictly increasing times");
}

TimeFunction TimeFunction::of(std::function<double(double)> evaluate) {
  TimeFunction f;
  f.points_.clear();
  f.evaluate_ = std::move(evaluate);
  return f;
}

double TimeFunction::operator()(double t) const {
  if (evaluate_) return evaluate_(t);
  if (t <= points_.front().first) return points_.front().second;
  if (t >= points_.back().first) return points_.back().second;
  for (size_t i = 1; i < points_.size(); ++i) {
    if (t <= points_[i].first) {
      const auto& [t0, v0] = points_[i - 1];
      const auto& [t1, v1] = points_[i];
      return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
    }
  }
  return points_.back().second;
}

}  // namespace morphfem
