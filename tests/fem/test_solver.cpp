// IncrementalSolver's adaptive Hessian projection (SolverOptions::hessian_projection)
// on a term whose exact Hessian is wrong on purpose, so that each of the two
// fallbacks must carry the solve: a direction that does not descend (the exact
// Hessian negative definite), and a descent direction along which the line search
// finds no decrease (the exact Hessian nearly singular: a step 1e14 times too long).
// (The fallbacks on real terms: the tube-vacuum test in tests/verify.)
#include <gtest/gtest.h>
#include <petscvec.h>

#include <memory>

#include "fem/assembly.h"
#include "fem/solver.h"
#include "tests/support/block_mesh.h"

using namespace morphfem;

namespace {

// Each node pulled to t d_a: E = k/2 |w|^2 + c/4 |w|^4, w = u_a - t d_a [m], k [N/m],
// c [N/m^3]; g = (k + c|w|^2) w, H = (k + c|w|^2) I + 2c w w^T (positive definite).
// With set_exact_hessian(true) the term hands out `exact_scale` H instead.
class QuarticPull : public EnergyTerm {
 public:
  QuarticPull(const Mesh& mesh, double exact_scale) : exact_scale_(exact_scale) {
    target_.resize(mesh.n_nodes(), 3);
    for (int a = 0; a < mesh.n_nodes(); ++a)  // a field that differs between nodes
      target_.row(a) << mesh.X(a, 0) + 0.2, -mesh.X(a, 2), 0.5 * mesh.X(a, 1) * mesh.X(a, 0);
  }
  std::string name() const override { return "quartic_pull"; }
  int n_pieces() const override { return static_cast<int>(target_.rows()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override { nodes.assign(1, k); }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override {
    const Eigen::Vector3d w = s.u.row(0).transpose() - t_ * target_.row(k).transpose();
    const double s2 = w.squaredNorm();
    if (g) *g = (kK + kC * s2) * w;
    if (H) {
      *H = (kK + kC * s2) * Eigen::Matrix3d::Identity() + 2 * kC * w * w.transpose();
      if (exact_) *H *= exact_scale_;
    }
    return 0.5 * kK * s2 + 0.25 * kC * s2 * s2;
  }
  void set_exact_hessian(bool exact) override { exact_ = exact; }
  void set_time(double t) override { t_ = t; }
  const RowMatrixXd& target() const { return target_; }

 private:
  static constexpr double kK = 1.0, kC = 100.0;
  RowMatrixXd target_;
  double exact_scale_, t_ = 0.0;
  bool exact_ = false;
};

struct Outcome {
  RunStats stats;
  double error = 0;  // max |u_a - d_a| at t = 1 [m]
};

Outcome solve(HessianProjection projection, double exact_scale) {
  const Mesh mesh = morphfem::testing::block_mesh({1, 1, 1}, 0.5, 1);
  const Partition part = morphfem::testing::one_rank(mesh);
  Assembler assembler(mesh, part, PETSC_COMM_SELF);
  auto term = std::make_shared<QuarticPull>(mesh, exact_scale);
  assembler.add_term(term);
  SolverOptions opt;
  opt.t_end = opt.dt_initial = opt.dt_max = 1.0;  // one step, the quartic regime (|w| ~ 1)
  opt.max_newton_its = 50;
  opt.hessian_projection = projection;
  IncrementalSolver solver(assembler, {}, opt);
  Outcome r;
  r.stats = solver.run();
  r.error = (assembler.gather_all(solver.solution()) - term->target()).cwiseAbs().maxCoeff();
  return r;
}

}  // namespace

TEST(IncrementalSolver, AdaptiveProjectionFallsBackWhereTheExactHessianFails) {
  const Outcome always = solve(HessianProjection::always, -1.0);  // "always" never asks for the exact Hessian
  ASSERT_TRUE(always.stats.completed) << always.stats.failure;
  EXPECT_EQ(always.stats.steps, 1);
  EXPECT_GT(always.stats.newton_its, 3);  // several iterations: the exact switch gets its chance
  EXPECT_EQ(always.stats.exact_hessian_its, 0);
  EXPECT_EQ(always.stats.projection_fallbacks, 0);
  EXPECT_LT(always.error, 1e-8);
  for (double scale : {-1.0, 1e-14}) {
    SCOPED_TRACE(scale);
    const Outcome adaptive = solve(HessianProjection::adaptive, scale);
    ASSERT_TRUE(adaptive.stats.completed) << adaptive.stats.failure;
    EXPECT_EQ(adaptive.stats.step_cuts, 0);
    EXPECT_LT(adaptive.error, 1e-8);
    // Every exact iteration failed and was re-solved projected: the same iterations.
    EXPECT_GT(adaptive.stats.exact_hessian_its, 0);
    EXPECT_EQ(adaptive.stats.projection_fallbacks, adaptive.stats.exact_hessian_its);
    EXPECT_EQ(adaptive.stats.newton_its, always.stats.newton_its);
  }
  // The exact Hessian right (scale 1): exact iterations, no fallback, no more iterations.
  const Outcome exact = solve(HessianProjection::adaptive, 1.0);
  ASSERT_TRUE(exact.stats.completed) << exact.stats.failure;
  EXPECT_GT(exact.stats.exact_hessian_its, 0);
  EXPECT_EQ(exact.stats.projection_fallbacks, 0);
  EXPECT_LE(exact.stats.newton_its, always.stats.newton_its);
  EXPECT_LT(exact.error, 1e-8);
}

namespace {

// Four steps of the quartic pull to t = 1 (the minimiser u_a = t d_a moves
// linearly in time); `error` = max |u_a - d_a| at t = 1 [m].
RunStats pull_in_steps(double newton_velocity_tol, bool extrapolate, double& error) {
  const Mesh mesh = morphfem::testing::block_mesh({1, 1, 1}, 0.5, 1);
  const Partition part = morphfem::testing::one_rank(mesh);
  Assembler assembler(mesh, part, PETSC_COMM_SELF);
  auto term = std::make_shared<QuarticPull>(mesh, 1.0);
  assembler.add_term(term);
  SolverOptions opt;
  opt.t_end = 1.0;
  opt.dt_initial = opt.dt_max = 0.25;
  opt.max_newton_its = 50;
  opt.newton_velocity_tol = newton_velocity_tol;
  opt.extrapolate = extrapolate;
  IncrementalSolver solver(assembler, {}, opt);
  const RunStats stats = solver.run();
  error = (assembler.gather_all(solver.solution()) - term->target()).cwiseAbs().maxCoeff();
  return stats;
}

}  // namespace

// SolverOptions::newton_velocity_tol: Newton stops once its last direction moves no
// node faster than tol [m/s] over the step: a huge tolerance stops every solve after
// one iteration, a tiny one changes nothing, a moderate one stops early with the
// state within about tol * dt of the solution.
TEST(IncrementalSolver, VelocityToleranceStopsNewtonOnTheDirection) {
  double error_default = 0, error_huge = 0, error_tiny = 0, error_moderate = 0;
  const RunStats base = pull_in_steps(0.0, false, error_default);
  ASSERT_TRUE(base.completed) << base.failure;
  ASSERT_EQ(base.steps, 4);
  ASSERT_GT(base.newton_its, 2 * base.steps);
  EXPECT_LT(error_default, 1e-10);
  const RunStats huge = pull_in_steps(1e6, false, error_huge);
  ASSERT_TRUE(huge.completed) << huge.failure;
  EXPECT_EQ(huge.newton_its, huge.steps);
  const RunStats tiny = pull_in_steps(1e-30, false, error_tiny);
  EXPECT_EQ(tiny.newton_its, base.newton_its);
  EXPECT_EQ(error_tiny, error_default);
  const double tol = 1e-2;  // [m/s]; dt = 0.25 s
  const RunStats moderate = pull_in_steps(tol, false, error_moderate);
  ASSERT_TRUE(moderate.completed) << moderate.failure;
  EXPECT_LT(moderate.newton_its, base.newton_its) << error_moderate;
  EXPECT_LT(error_moderate, tol * 0.25);
}

// SolverOptions::extrapolate: the solution moves linearly in time, so from the second
// step on the extrapolated start (u_n + dt (u_n - u_{n-1}) / dt_{n-1}) is the
// solution and Newton has nothing left to do; starting from u_n it has.
TEST(IncrementalSolver, ExtrapolatedStartSavesIterationsOnALinearMotion) {
  double error_extrapolated = 0, error_from_last = 0;
  const RunStats extrapolated = pull_in_steps(0.0, true, error_extrapolated);
  const RunStats from_last = pull_in_steps(0.0, false, error_from_last);
  ASSERT_TRUE(extrapolated.completed && from_last.completed);
  EXPECT_LT(extrapolated.newton_its + 2 * (extrapolated.steps - 1), from_last.newton_its);
  EXPECT_LT(error_extrapolated, 1e-10);
  EXPECT_LT(error_from_last, 1e-10);
}
