// Self-contact kernel: point-triangle distance against dense sampling, and the
// barrier's gradient and Hessian against finite differences for every closest
// feature (face, edge, vertex); candidate search on a thin plate (P1 and P2).
#include <gtest/gtest.h>

#include <random>

#include "contact/self_contact.h"
#include "mesh/geometry.h"

using namespace morphfem;

namespace {

// Triangle (0,0,0) (1,0,0) (0,1,0) scaled by 1e-2 and a point above the face
// (feature 3), beyond an edge (2) or beyond a vertex (1), at distance ~d.
Eigen::Matrix<double, 4, 3> configuration(int feature, double d, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Matrix<double, 4, 3> x;
  x.row(1) << 0, 0, 0;
  x.row(2) << 1, 0, 0;
  x.row(3) << 0, 1, 0;
  Eigen::RowVector3d foot = feature == 3   ? Eigen::RowVector3d(0.3, 0.3, 0)
                            : feature == 2 ? Eigen::RowVector3d(0.5, 0, 0)
                                           : Eigen::RowVector3d(0, 0, 0);
  Eigen::RowVector3d dir = feature == 3   ? Eigen::RowVector3d(0, 0, 1)
                           : feature == 2 ? Eigen::RowVector3d(0, -0.6, 0.8)
                                          : Eigen::RowVector3d(-0.5, -0.5, 0.7071);
  x *= 1e-2;
  x.row(0) = 1e-2 * foot + d * dir.normalized();
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) x(a, i) += 1e-3 * d * unit(rng);  // small random perturbation
  return x;
}

}  // namespace

TEST(SelfContactKernel, DistanceMatchesDenseSampling) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Matrix<double, 4, 3> x;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) x(a, i) = unit(rng);
    double best = std::numeric_limits<double>::infinity();
    const int n = 300;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const Eigen::RowVector3d y =
            x.row(1) + (double(i) / n) * (x.row(2) - x.row(1)) + (double(j) / n) * (x.row(3) - x.row(1));
        best = std::min(best, (x.row(0) - y).norm());
      }
    const double d = point_triangle_distance(x);
    EXPECT_LE(d, best + 1e-12);
    EXPECT_GT(d, best - 1e-2);
  }
}

TEST(SelfContactKernel, BarrierGradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(4);
  const double dhat = 1e-3, kappa = 1e6, area = 2e-5;
  for (int feature : {3, 2, 1})
    for (double s : {0.05, 0.3, 0.7, 0.95}) {
      const Eigen::Matrix<double, 4, 3> x = configuration(feature, s * dhat, rng);
      Eigen::VectorXd g;
      Eigen::MatrixXd H;
      const double e = point_triangle_barrier(x, area, kappa, dhat, &g, &H);
      ASSERT_TRUE(std::isfinite(e) && e > 0) << feature << " " << s;
      const double h = 1e-6 * s * dhat;
      Eigen::VectorXd g_fd(12);
      Eigen::MatrixXd H_fd(12, 12);
      for (int j = 0; j < 12; ++j) {
        Eigen::Matrix<double, 4, 3> xp = x, xm = x;
        xp(j / 3, j % 3) += h;
        xm(j / 3, j % 3) -= h;
        Eigen::VectorXd gp, gm;
        g_fd[j] = (point_triangle_barrier(xp, area, kappa, dhat, &gp, nullptr) -
                   point_triangle_barrier(xm, area, kappa, dhat, &gm, nullptr)) /
                  (2 * h);
        H_fd.col(j) = (gp - gm) / (2 * h);
      }
      EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm()) << "feature " << feature << " s " << s;
      EXPECT_LT((H - H_fd).norm(), 1e-5 * H.norm()) << "feature " << feature << " s " << s;
      EXPECT_LT((H - H.transpose()).norm(), 1e-10 * H.norm());
      // Translation invariance: the gradient sums to zero over the four nodes.
      EXPECT_LT((g.segment<3>(0) + g.segment<3>(3) + g.segment<3>(6) + g.segment<3>(9)).norm(), 1e-9 * g.norm());
    }
}

TEST(SelfContactTerm, FindsCandidatesAcrossAThinPlateOnP1AndP2) {
  for (int order : {1, 2}) {
    ParamSet p("plate");
    p.set_string("type", "block");
    p.set("lx", 0.04);
    p.set("ly", 0.04);
    p.set("lz", 0.004);
    p.set("mesh_size", 0.02);
    p.set("order", order);
    const Mesh mesh = build_geometry(p);
    Partition part;
    part.cell_part.assign(mesh.n_cells(), 0);
    part.node_begin = {0, mesh.n_nodes()};
    SelfContactSpec spec;
    spec.pairs = {{"zmin", "zmax"}};
    spec.dhat = 1e-3;
    spec.kappa = 1e6;
    spec.inflation = 0.0045;  // reaches across the 4 mm plate
    SelfContactTerm term(mesh, part, 0, spec);
    EXPECT_GT(term.n_pairs(), 0) << order;
    // No pair is in the barrier at the start (4 mm > dhat): energy 0 everywhere.
    for (int k = 0; k < term.n_pieces(); ++k) {
      std::vector<int> nodes;
      term.piece_nodes(k, nodes);
      PieceState s;
      s.X.resize(nodes.size(), 3);
      s.u.setZero(nodes.size(), 3);
      for (size_t a = 0; a < nodes.size(); ++a) s.X.row(a) = mesh.X.row(nodes[a]);
      EXPECT_EQ(term.piece(k, s, nullptr, nullptr), 0.0);
    }
  }
}
