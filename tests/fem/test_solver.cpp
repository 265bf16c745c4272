// QuasiStaticSolver's adaptive Hessian projection (SolverOptions::hessian_projection)
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
  QuasiStaticSolver solver(assembler, {}, opt);
  Outcome r;
  r.stats = solver.run();
  r.error = (assembler.gather_all(solver.solution()) - term->target()).cwiseAbs().maxCoeff();
  return r;
}

}  // namespace

TEST(QuasiStaticSolver, AdaptiveProjectionFallsBackWhereTheExactHessianFails) {
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
