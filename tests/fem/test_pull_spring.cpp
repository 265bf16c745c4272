// The test-machine pull spring: energy, load-cell force and crosshead motion, and
// gradient / Hessian against finite differences at random states.
#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "core/params.h"
#include "fem/pull_spring.h"
#include "mesh/geometry.h"
#include "tests/support/block_mesh.h"
#include "tests/support/finite_differences.h"
#include "tests/support/piece_state.h"

namespace morphfem {
namespace {

Mesh block_mesh(int order) { return testing::block_mesh({0.02, 0.01, 0.005}, 0.005, order); }

TEST(PullSpring, ForceIsStiffnessTimesSpringStretch) {
  const Mesh mesh = block_mesh(1);
  PullSpringTerm term(mesh, 0, {"xmax", 200.0, Eigen::Vector3d(0.002, 0, 0), 1.0, ""});
  RowMatrixXd u = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  EXPECT_NEAR(term.force(u, 0.5), 0.0, 1e-12);  // before the start: unstretched
  EXPECT_NEAR(term.crosshead(3.0) - term.crosshead(1.0), 0.004, 1e-15);
  // Rigid translation of the whole body by 1 mm along x, crosshead 4 mm on: 3 mm stretch.
  u.col(0).setConstant(0.001);
  u.col(1).setConstant(0.05);  // lateral motion is not pulled
  EXPECT_NEAR(term.force(u, 3.0), 200.0 * 0.003, 1e-10);
  std::vector<int> nodes;
  term.piece_nodes(0, nodes);
  term.set_time(3.0);
  const PieceState s = testing::piece_state(mesh, nodes, u);
  Eigen::VectorXd g;
  const double E = term.piece(0, s, &g, nullptr);
  EXPECT_NEAR(E, 0.5 * 200.0 * 0.003 * 0.003, 1e-14);
  // The nodal forces -g sum to the spring force along the pull direction.
  double fx = 0, fy = 0;
  for (int a = 0; a < static_cast<int>(nodes.size()); ++a) {
    fx -= g(3 * a);
    fy -= g(3 * a + 1);
  }
  EXPECT_NEAR(fx, 0.6, 1e-10);
  EXPECT_NEAR(fy, 0.0, 1e-14);
}

TEST(PullSpring, GradientAndHessianMatchFiniteDifferences) {
  for (int order : {1, 2}) {
    SCOPED_TRACE(order);
    const Mesh mesh = block_mesh(order);
    PullSpringTerm term(mesh, 0, {"xmax", 350.0, Eigen::Vector3d(0.001, -0.0005, 0.0002), 0.2, ""});
    term.set_time(1.7);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> r(-1e-3, 1e-3);
    RowMatrixXd u(mesh.n_nodes(), 3);
    for (int i = 0; i < u.size(); ++i) u.data()[i] = r(rng);
    std::vector<int> nodes;
    term.piece_nodes(0, nodes);
    const PieceState s = testing::piece_state(mesh, nodes, u);
    Eigen::VectorXd g, g_fd;
    Eigen::MatrixXd H, H_fd;
    const double E = term.piece(0, s, &g, &H);
    testing::piece_finite_differences(term, 0, s, 1e-7, g_fd, H_fd);
    EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm()) << E;
    EXPECT_LT((H - H_fd).norm(), 1e-6 * H.norm());
    EXPECT_NEAR(E, 0.5 * 350.0 * std::pow(term.force(u, 1.7) / 350.0, 2), 1e-12 * E);
  }
}

TEST(PullSpring, RejectsBadSpecs) {
  const Mesh mesh = block_mesh(1);
  EXPECT_THROW(PullSpringTerm(mesh, 0, {"nowhere", 1.0, Eigen::Vector3d(1, 0, 0), 0, ""}), InputError);
  EXPECT_THROW(PullSpringTerm(mesh, 0, {"xmax", 0.0, Eigen::Vector3d(1, 0, 0), 0, ""}), InputError);
  EXPECT_THROW(PullSpringTerm(mesh, 0, {"xmax", 1.0, Eigen::Vector3d(0, 0, 0), 0, ""}), InputError);
  PullSpringTerm other_rank(mesh, 1, {"xmax", 1.0, Eigen::Vector3d(1, 0, 0), 0, ""});
  EXPECT_EQ(other_rank.n_pieces(), 0);
}

}  // namespace
}  // namespace morphfem
