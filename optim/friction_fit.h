// Least-squares calibration with PETSc TAO, and the pieces of the friction fit.
//
// fit_least_squares: min_p 1/2 sum_i r_i(p)^2 over box bounds with TAO POUNDERS
// (derivative-free trust region on quadratic models of the residuals: the model is
// a simulation, whose derivatives are not available). TAO works on the scaled
// parameters p_j / scale_j (all O(1)); its options take the prefix -calib_ (e.g.
// -calib_tao_pounders_delta 0.1, -calib_tao_monitor).
//
// Uncertainty at the optimum p*: J = dr/dp by central differences (step
// `fd_relative_step` x scale_j, at least one quantum sqrt(12) s_j of the model), sigma^2 = SSE / (m - n) (m residuals,
// n parameters), covariance C = sigma^2 (J^T J)^-1, standard errors sqrt(C_jj), 95 % intervals p*_j +/- t sqrt(C_jj +
// s_j^2) with t the Student quantile (1.96 for large m - n) and s_j the model's own resolution
// (LeastSquaresProblem::model_resolution). Valid for independent residuals of equal variance (load-cell noise);
// correlated model error makes the intervals too narrow.
//
// The friction fit (app/calibrate_cli.cpp): parameters mu_static, mu_kinetic and
// the pull-spring stiffness k [N/m]; residuals of every curve of the group against
// one simulation (PullTarget below).
#pragma once
#include <Eigen/Dense>
#include <functional>
#include <string>
#include <vector>

#include "optim/pull_test.h"

namespace morphfem {

struct LeastSquaresProblem {
  std::vector<std::string> names;
  std::vector<double> start, lower, upper, scale;
  int n_residuals = 0;
  // Fills r (size n_residuals) at parameters p; returns false if the model failed
  // (the fit then sees large residuals there).
  std::function<bool(const std::vector<double>& p, std::vector<double>& r)> residuals;
  // Optional, per parameter: standard uncertainty [parameter unit] of the model itself
  // (e.g. a simulator whose time step quantises the quantity that determines the
  // parameter), added in quadrature to the noise-based standard error. Empty: none.
  std::vector<double> model_resolution;
};

struct LeastSquaresFit {
  std::vector<std::string> names;
  std::vector<double> values, std_error, ci_low, ci_high;
  std::vector<double> residuals;  // at the optimum
  double sse = 0, rms = 0;        // sum of squares, RMS residual
  int evaluations = 0;
  bool converged = false;
  std::string reason;  // TAO's converged reason
  Eigen::MatrixXd jacobian;
};

LeastSquaresFit fit_least_squares(const LeastSquaresProblem& problem, int max_evaluations = 80,
                                  double fd_relative_step = 5e-3);

// Two-sided 95 % Student t quantile for `dof` degrees of freedom.
double student_t95(int dof);

// What a simulated curve is compared with, from one data curve: up to `split` (just
// past the static peak) every sample, r_i = F_sim(x_i) - F_i [N]; beyond it, up to
// the travel, blocks of width `block` [m] with r_b = sqrt(n_b) (mean_b F_sim - mean_b
// F) over the n_b samples of the block. The blocks make the sliding part insensitive
// to the phase of stick-slip oscillations (which no model matches sample by sample)
// while keeping the residuals independent with the noise variance sigma^2 (the mean
// of n_b samples has variance sigma^2 / n_b). Each block also compares the size of
// the force oscillation: r'_b = sqrt(2 n_b) (sd_b F_sim - sqrt(max(0, var_b F -
// sigma^2))) with sigma the data's noise (the sd of n_b samples has standard error
// ~ sigma / sqrt(2 n_b)); without it mu_static and mu_kinetic trade off along a valley
// (a larger mu_static with a smaller mu_kinetic gives the same peak and mean sliding
// force but larger stick-slip). F_sim is linearly interpolated in x (beyond the
// simulated range the end value is held).
struct PullTarget {
  std::vector<double> x, force;              // pointwise part
  std::vector<std::vector<double>> block_x;  // samples of each block [m]
  std::vector<double> block_mean;            // mean data force of each block [N]
  std::vector<double> block_sd;              // noise-corrected sd of the data force in each block [N]
  int size() const { return static_cast<int>(x.size() + 2 * block_mean.size()); }
};
PullTarget make_pull_target(const PullCurve& data, double travel, double split, double block, double noise);
void append_target_residuals(const std::vector<double>& sim_x, const std::vector<double>& sim_force,
                             const PullTarget& target, std::vector<double>& r);

}  // namespace morphfem
