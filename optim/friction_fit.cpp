// TAO least squares with Jacobian-based confidence intervals (friction_fit.h).
#include "optim/friction_fit.h"

#include <petsctao.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace morphfem {

namespace {

struct TaoContext {
  const LeastSquaresProblem* problem;
  int evaluations = 0;
  double failure_value = 0;
  std::vector<double> r;
};

PetscErrorCode residual_routine(Tao, Vec x, Vec F, void* ctx_ptr) {
  auto* ctx = static_cast<TaoContext*>(ctx_ptr);
  const auto& pb = *ctx->problem;
  const PetscScalar* xs;
  PetscCall(VecGetArrayRead(x, &xs));
  std::vector<double> p(pb.names.size());
  for (size_t j = 0; j < p.size(); ++j) p[j] = xs[j] * pb.scale[j];
  PetscCall(VecRestoreArrayRead(x, &xs));
  ctx->r.assign(pb.n_residuals, 0.0);
  ++ctx->evaluations;
  if (!pb.residuals(p, ctx->r) || static_cast<int>(ctx->r.size()) != pb.n_residuals)
    ctx->r.assign(pb.n_residuals, ctx->failure_value);
  PetscScalar* f;
  PetscCall(VecGetArray(F, &f));
  for (int i = 0; i < pb.n_residuals; ++i) f[i] = std::isfinite(ctx->r[i]) ? ctx->r[i] : ctx->failure_value;
  PetscCall(VecRestoreArray(F, &f));
  return 0;
}

#define TAO_CHECK(call)                                                         \
  do {                                                                          \
    if ((call) != 0) throw std::runtime_error("PETSc TAO call failed: " #call); \
  } while (0)

}  // namespace

double student_t95(int dof) {
  // Table for small dof, then the expansion t ~ z + (z^3 + z)/(4 dof) (z = 1.959964).
  static const double table[] = {0,     12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                 2.201, 2.179,  2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086};
  if (dof < 1) return std::numeric_limits<double>::infinity();
  if (dof <= 20) return table[dof];
  const double z = 1.959964;
  return z + (z * z * z + z) / (4.0 * dof);
}

LeastSquaresFit fit_least_squares(const LeastSquaresProblem& pb, int max_evaluations, double fd_relative_step) {
  const int n = static_cast<int>(pb.names.size()), m = pb.n_residuals;
  if (n == 0 || m < n || pb.start.size() != size_t(n) || pb.lower.size() != size_t(n) || pb.upper.size() != size_t(n) ||
      pb.scale.size() != size_t(n) || !pb.residuals)
    throw std::invalid_argument(
        "fit_least_squares: inconsistent problem (need m >= n residuals, n start/bounds/scale)");
  TaoContext ctx;
  ctx.problem = &pb;
  {
    // Residual of a failed model evaluation: 10 x the largest start residual.
    std::vector<double> r0(m);
    pb.residuals(pb.start, r0);
    double big = 0;
    for (double v : r0)
      if (std::isfinite(v)) big = std::max(big, std::abs(v));
    ctx.failure_value = 10.0 * std::max(big, 1.0);
  }
  Tao tao;
  Vec x, F, lo, hi;
  TAO_CHECK(TaoCreate(PETSC_COMM_SELF, &tao));
  TAO_CHECK(TaoSetType(tao, TAOPOUNDERS));
  TAO_CHECK(VecCreateSeq(PETSC_COMM_SELF, n, &x));
  TAO_CHECK(VecCreateSeq(PETSC_COMM_SELF, m, &F));
  TAO_CHECK(VecDuplicate(x, &lo));
  TAO_CHECK(VecDuplicate(x, &hi));
  for (int j = 0; j < n; ++j) {
    TAO_CHECK(VecSetValue(x, j, pb.start[j] / pb.scale[j], INSERT_VALUES));
    TAO_CHECK(VecSetValue(lo, j, pb.lower[j] / pb.scale[j], INSERT_VALUES));
    TAO_CHECK(VecSetValue(hi, j, pb.upper[j] / pb.scale[j], INSERT_VALUES));
  }
  for (Vec v : {x, lo, hi}) {
    TAO_CHECK(VecAssemblyBegin(v));
    TAO_CHECK(VecAssemblyEnd(v));
  }
  TAO_CHECK(TaoSetSolution(tao, x));
  TAO_CHECK(TaoSetResidualRoutine(tao, F, residual_routine, &ctx));
  TAO_CHECK(TaoSetVariableBounds(tao, lo, hi));
  TAO_CHECK(TaoSetMaximumFunctionEvaluations(tao, max_evaluations));
  TAO_CHECK(TaoSetMaximumIterations(tao, max_evaluations));
  TAO_CHECK(TaoSetTolerances(tao, 1e-10, 1e-8, 0.0));
  TAO_CHECK(TaoSetOptionsPrefix(tao, "calib_"));
  TAO_CHECK(TaoSetFromOptions(tao));
  TAO_CHECK(TaoSolve(tao));
  TaoConvergedReason reason;
  TAO_CHECK(TaoGetConvergedReason(tao, &reason));
  LeastSquaresFit fit;
  fit.names = pb.names;
  fit.reason = TaoConvergedReasons[reason];
  fit.converged = reason > 0;
  {
    const PetscScalar* xs;
    TAO_CHECK(VecGetArrayRead(x, &xs));
    for (int j = 0; j < n; ++j) fit.values.push_back(xs[j] * pb.scale[j]);
    TAO_CHECK(VecRestoreArrayRead(x, &xs));
  }
  TAO_CHECK(VecDestroy(&x));
  TAO_CHECK(VecDestroy(&F));
  TAO_CHECK(VecDestroy(&lo));
  TAO_CHECK(VecDestroy(&hi));
  TAO_CHECK(TaoDestroy(&tao));

  // Residuals, Jacobian and intervals at the optimum.
  fit.residuals.assign(m, 0.0);
  if (!pb.residuals(fit.values, fit.residuals))
    throw std::runtime_error("fit_least_squares: model failed at the optimum");
  ++ctx.evaluations;
  for (double r : fit.residuals) fit.sse += r * r;
  fit.rms = std::sqrt(fit.sse / m);
  fit.jacobian.resize(m, n);
  for (int j = 0; j < n; ++j) {
    // The step spans at least one quantum of a quantised model (sqrt(12) x its
    // resolution), else the differences see a staircase as flat.
    const double quantum = pb.model_resolution.empty() ? 0.0 : std::sqrt(12.0) * pb.model_resolution[j];
    const double h = std::max(fd_relative_step * pb.scale[j], quantum);
    std::vector<double> pp = fit.values, pm = fit.values, rp(m), rm(m);
    pp[j] += h;
    pm[j] -= h;
    if (!pb.residuals(pp, rp) || !pb.residuals(pm, rm))
      throw std::runtime_error("fit_least_squares: model failed next to the optimum");
    ctx.evaluations += 2;
    for (int i = 0; i < m; ++i) fit.jacobian(i, j) = (rp[i] - rm[i]) / (2.0 * h);
  }
  fit.evaluations = ctx.evaluations;
  const double sigma2 = m > n ? fit.sse / (m - n) : 0.0;
  const Eigen::MatrixXd JtJ = fit.jacobian.transpose() * fit.jacobian;
  const Eigen::MatrixXd cov = sigma2 * JtJ.completeOrthogonalDecomposition().pseudoInverse();
  const double t = student_t95(m - n);
  for (int j = 0; j < n; ++j) {
    const double resolution = pb.model_resolution.empty() ? 0.0 : pb.model_resolution[j];
    const double se = std::sqrt(std::max(0.0, cov(j, j)) + resolution * resolution);
    fit.std_error.push_back(se);
    fit.ci_low.push_back(fit.values[j] - t * se);
    fit.ci_high.push_back(fit.values[j] + t * se);
  }
  return fit;
}

namespace {

double interpolate(const std::vector<double>& xs, const std::vector<double>& fs, double x) {
  if (x <= xs.front()) return fs.front();
  if (x >= xs.back()) return fs.back();
  const size_t k = static_cast<size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin());
  const double w = (x - xs[k - 1]) / (xs[k] - xs[k - 1]);
  return (1.0 - w) * fs[k - 1] + w * fs[k];
}

}  // namespace

PullTarget make_pull_target(const PullCurve& data, double travel, double split, double block, double noise) {
  if (!(block > 0)) throw std::invalid_argument("make_pull_target: block width must be > 0");
  PullTarget t;
  std::vector<std::vector<double>> block_x, block_f;
  for (size_t i = 0; i < data.displacement.size(); ++i) {
    const double x = data.displacement[i];
    if (x > travel) continue;
    if (x <= split) {
      t.x.push_back(x);
      t.force.push_back(data.force[i]);
      continue;
    }
    const size_t b = static_cast<size_t>(std::floor((x - split) / block));
    if (b >= block_x.size()) {
      block_x.resize(b + 1);
      block_f.resize(b + 1);
    }
    block_x[b].push_back(x);
    block_f[b].push_back(data.force[i]);
  }
  // Blocks of at least 3 samples (a gap in the data leaves none).
  for (size_t b = 0; b < block_x.size(); ++b) {
    if (block_x[b].size() < 3) continue;
    const double n = static_cast<double>(block_f[b].size());
    double mean = 0, var = 0;
    for (double f : block_f[b]) mean += f / n;
    for (double f : block_f[b]) var += (f - mean) * (f - mean) / (n - 1);
    t.block_x.push_back(block_x[b]);
    t.block_mean.push_back(mean);
    t.block_sd.push_back(std::sqrt(std::max(0.0, var - noise * noise)));
  }
  return t;
}

void append_target_residuals(const std::vector<double>& sim_x, const std::vector<double>& sim_force,
                             const PullTarget& t, std::vector<double>& r) {
  if (sim_x.empty()) throw std::invalid_argument("append_target_residuals: empty simulated curve");
  for (size_t i = 0; i < t.x.size(); ++i) r.push_back(interpolate(sim_x, sim_force, t.x[i]) - t.force[i]);
  for (size_t b = 0; b < t.block_x.size(); ++b) {
    const double n = static_cast<double>(t.block_x[b].size());
    std::vector<double> f;
    for (double x : t.block_x[b]) f.push_back(interpolate(sim_x, sim_force, x));
    double mean = 0, var = 0;
    for (double v : f) mean += v / n;
    for (double v : f) var += (v - mean) * (v - mean) / (n - 1);
    r.push_back(std::sqrt(n) * (mean - t.block_mean[b]));
    r.push_back(std::sqrt(2.0 * n) * (std::sqrt(var) - t.block_sd[b]));
  }
}

}  // namespace morphfem
