// TAO POUNDERS least squares with Jacobian-based intervals on an analytic model, and
// the pull-curve residuals of the friction fit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "optim/friction_fit.h"

namespace morphfem {
namespace {

TEST(CalibrationLsq, RecoversAnExponentialWithHonestIntervals) {
  // y = a exp(-b x) + noise, a = 2, b = 0.7, sigma = 0.01, 200 samples.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<double> x, y;
  for (int i = 0; i < 200; ++i) {
    x.push_back(0.025 * i);
    y.push_back(2.0 * std::exp(-0.7 * x.back()) + noise(rng));
  }
  LeastSquaresProblem pb;
  pb.names = {"a", "b"};
  pb.start = {1.5, 1.0};
  pb.scale = {1.5, 1.0};
  pb.lower = {0.1, 0.01};
  pb.upper = {10.0, 10.0};
  pb.n_residuals = 200;
  pb.residuals = [&](const std::vector<double>& p, std::vector<double>& r) {
    for (int i = 0; i < 200; ++i) r[i] = p[0] * std::exp(-p[1] * x[i]) - y[i];
    return true;
  };
  const LeastSquaresFit f = fit_least_squares(pb, 200);
  EXPECT_TRUE(f.converged) << f.reason;
  EXPECT_NEAR(f.values[0], 2.0, 0.01);
  EXPECT_NEAR(f.values[1], 0.7, 0.01);
  EXPECT_NEAR(f.rms, 0.01, 0.002);
  for (int j = 0; j < 2; ++j) {
    EXPECT_LE(f.ci_low[j], j == 0 ? 2.0 : 0.7);
    EXPECT_GE(f.ci_high[j], j == 0 ? 2.0 : 0.7);
  }
  // The analytic Jacobian gives the same standard errors as the finite differences.
  Eigen::MatrixXd J(200, 2);
  for (int i = 0; i < 200; ++i) {
    const double e = std::exp(-f.values[1] * x[i]);
    J(i, 0) = e;
    J(i, 1) = -f.values[0] * x[i] * e;
  }
  const Eigen::MatrixXd cov = (f.sse / 198.0) * (J.transpose() * J).inverse();
  EXPECT_NEAR(f.std_error[0], std::sqrt(cov(0, 0)), 1e-3 * std::sqrt(cov(0, 0)));
  EXPECT_NEAR(f.std_error[1], std::sqrt(cov(1, 1)), 1e-3 * std::sqrt(cov(1, 1)));
  EXPECT_NEAR(student_t95(10), 2.228, 1e-9);
  EXPECT_NEAR(student_t95(1000), 1.962, 1e-3);
}

TEST(CalibrationLsq, PullTargetResidualsVanishForTheSameCurve) {
  PullCurve c;
  for (int i = 0; i <= 300; ++i) {
    const double x = 1e-5 * i;  // 0 .. 3 mm
    c.displacement.push_back(x);
    c.force.push_back(x < 1e-3 ? 500.0 * x : 0.4 + 0.05 * std::sin(6283.0 * x));  // stick-slip-like
  }
  const PullTarget t = make_pull_target(c, 2.5e-3, 1.0e-3, 0.5e-3, 0.0);
  EXPECT_EQ(t.x.size(), 101u);         // 0 .. 1 mm pointwise
  EXPECT_EQ(t.block_mean.size(), 3u);  // (1, 1.5], (1.5, 2], (2, 2.5] mm
  std::vector<double> r;
  append_target_residuals(c.displacement, c.force, t, r);
  ASSERT_EQ(static_cast<int>(r.size()), t.size());
  for (double v : r) EXPECT_NEAR(v, 0.0, 1e-12);
  // A simulated curve 0.01 N higher in the sliding part: block residuals sqrt(n) 0.01.
  std::vector<double> shifted = c.force;
  for (size_t i = 0; i < shifted.size(); ++i)
    if (c.displacement[i] > 1e-3) shifted[i] += 0.01;
  r.clear();
  append_target_residuals(c.displacement, shifted, t, r);
  EXPECT_NEAR(r[101], std::sqrt(static_cast<double>(t.block_x[0].size())) * 0.01, 1e-9);
  EXPECT_NEAR(r[102], 0.0, 1e-9);  // same oscillation size
}

}  // namespace
}  // namespace morphfem
