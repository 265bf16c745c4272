// The end-moment term: rotation angle of rigidly rotated sections (through and
// past +-pi, following the branch), work conjugacy (dE = -M dtheta), and its
// gradient and Hessian against finite differences at random large-rotation states.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fem/end_moment.h"
#include "tests/support/finite_differences.h"

using namespace morphfem;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The nodes of an end section x = L, 0 <= y <= b, 0 <= z <= h (5 x 3 grid), and a
// few other nodes that are not part of it. Lengths in metres.
struct Section {
  Mesh mesh;
  std::vector<int> nodes;
  Partition partition;
};

Section make_section() {
  const double L = 0.1, b = 0.004, h = 0.002;
  Section s;
  s.mesh.order = 2;
  std::vector<Eigen::Vector3d> X{{0, 0, 0}, {0.05, 0.001, 0.001}};
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 5; ++k) {
      s.nodes.push_back(static_cast<int>(X.size()));
      X.emplace_back(L, b * j / 2.0, h * k / 4.0);
    }
  s.mesh.X.resize(X.size(), 3);
  for (size_t a = 0; a < X.size(); ++a) s.mesh.X.row(a) = X[a].transpose();
  s.partition = Partition{1, {}, {0, s.mesh.n_nodes()}};
  return s;
}

// Displacement of a rigid rotation by phi about the y axis through c, bending
// x towards z (the tip section's director turns from +z towards -x).
RowMatrixXd rotation_field(const Mesh& mesh, double phi, const Eigen::Vector3d& c) {
  Eigen::Matrix3d R;
  R << std::cos(phi), 0, -std::sin(phi), 0, 1, 0, std::sin(phi), 0, std::cos(phi);
  RowMatrixXd u(mesh.n_nodes(), 3);
  for (int a = 0; a < mesh.n_nodes(); ++a) {
    const Eigen::Vector3d X = mesh.X.row(a).transpose();
    u.row(a) = (c + R * (X - c) - X).transpose();
  }
  return u;
}

PieceState piece_state(const Section& s, const RowMatrixXd& u) {
  PieceState p;
  p.X.resize(s.nodes.size(), 3);
  p.u.resize(s.nodes.size(), 3);
  for (size_t a = 0; a < s.nodes.size(); ++a) {
    p.X.row(a) = s.mesh.X.row(s.nodes[a]);
    p.u.row(a) = u.row(s.nodes[a]);
  }
  return p;
}

}  // namespace

TEST(EndMoment, RigidRotationAngleFollowsTheBranchThroughAFullTurn) {
  Section s = make_section();
  EndMomentTerm term(s.mesh, s.partition, 0, s.nodes, 0, 2, [](double t) { return 3.0 * t; });
  ASSERT_EQ(term.n_pieces(), 1);
  const Eigen::Vector3d centre(0.02, 0.0, 0.015);  // rotation about an arbitrary point
  for (int step = 0; step <= 40; ++step) {
    const double phi = 2.0 * kPi * step / 40.0 * 1.1;  // up to 2.2 pi
    const RowMatrixXd u = rotation_field(s.mesh, phi, centre);
    EXPECT_NEAR(term.angle(u), phi, 1e-12) << "step " << step;
    term.follow(u);
  }
  EXPECT_NEAR(term.converged_angle(), 2.2 * kPi, 1e-12);
}

TEST(EndMoment, EnergyIsMinusMomentTimesAngleAndWorkConjugate) {
  Section s = make_section();
  EndMomentTerm term(s.mesh, s.partition, 0, s.nodes, 0, 2, [](double t) { return 3.0 * t; });
  term.set_time(0.5);  // M = 1.5 N m
  const double phi = 2.0;
  const Eigen::Vector3d centre(0.1, 0.001, 0.0);
  PieceState p = piece_state(s, rotation_field(s.mesh, phi, centre));
  Eigen::VectorXd g;
  EXPECT_NEAR(term.piece(0, p, &g, nullptr), -1.5 * phi, 1e-12);
  // A small rigid rotation increment dphi about the same centre: dE = -M dphi.
  const double dphi = 1e-6;
  PieceState q = piece_state(s, rotation_field(s.mesh, phi + dphi, centre));
  const Eigen::MatrixXd du = q.u - p.u;
  double dE = 0;
  for (int a = 0; a < du.rows(); ++a) dE += g.segment<3>(3 * a).dot(du.row(a).transpose());
  EXPECT_NEAR(dE / dphi, -1.5, 1e-5);
  // A translation does no work.
  double dT = 0;
  for (int a = 0; a < du.rows(); ++a) dT += g.segment<3>(3 * a).dot(Eigen::Vector3d(0.3, -0.2, 0.7));
  EXPECT_NEAR(dT, 0.0, 1e-10);
}

TEST(EndMoment, GradientAndHessianMatchFiniteDifferences) {
  Section s = make_section();
  EndMomentTerm term(s.mesh, s.partition, 0, s.nodes, 0, 2, [](double t) { return 2.0 * t; });
  term.set_time(1.0);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> d(-2e-4, 2e-4);  // 10 % of the section height
  for (double phi : {0.3, 2.9, 4.0, 6.0}) {
    RowMatrixXd u = rotation_field(s.mesh, phi, Eigen::Vector3d(0.05, 0, 0));
    term.follow(u);
    for (int a = 0; a < u.rows(); ++a)
      for (int i = 0; i < 3; ++i) u(a, i) += d(rng);
    PieceState p = piece_state(s, u);
    Eigen::VectorXd g;
    Eigen::MatrixXd H;
    term.piece(0, p, &g, &H);
    Eigen::VectorXd g_fd;
    Eigen::MatrixXd H_fd;
    morphfem::testing::piece_finite_differences(term, 0, p, 1e-8, g_fd, H_fd);
    EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm()) << "phi " << phi;
    EXPECT_LT((H - H_fd).norm(), 1e-6 * H.norm()) << "phi " << phi;
    EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
  }
}
