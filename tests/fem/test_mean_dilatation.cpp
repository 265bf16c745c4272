// Isochoric/volumetric split of every law, and the mean-dilatation element: its
// gradient and Hessian against finite differences of its energy at random states
// (P2, several laws), its agreement with the displacement element for uniform
// dilatation, and the rejection of P1 meshes.
#include <gtest/gtest.h>

#include <random>

#include "core/errors.h"
#include "fem/kinematics.h"
#include "fem/mean_dilatation.h"
#include "tests/support/finite_differences.h"
#include "tests/support/one_tet.h"

using namespace morphfem;

namespace {

// Laws with a large bulk modulus (kappa / mu ~ 1000, nu ~ 0.4995).
std::shared_ptr<const Material> law(const std::string& name) {
  ParamSet p("test");
  p.set_string("model", name);
  if (name == "neo_hookean") p.set("mu", 1e5);
  if (name == "mooney_rivlin") {
    p.set("c10", 4e4);
    p.set("c01", 1e4);
  }
  if (name == "yeoh") {
    p.set("c1", 2e4);
    p.set("c2", 3e3);
    p.set("c3", 1e2);
  }
  if (name == "ogden") {
    p.set("mu", std::vector<double>{6e4, -2e3});
    p.set("alpha", std::vector<double>{1.8, -2.0});
  }
  p.set("kappa", 1e8);
  return make_material(p);
}

const std::vector<std::string> kLaws{"neo_hookean", "mooney_rivlin", "yeoh", "ogden"};

Mat3 random_F(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> d(-amplitude, amplitude);
  return Mat3::Identity() + Mat3::NullaryExpr([&]() { return d(rng); });
}

}  // namespace

TEST(MaterialSplit, IsochoricPlusVolumetricIsTheWholeLaw) {
  std::mt19937 rng(11);
  for (const auto& name : kLaws) {
    auto m = law(name);
    for (int trial = 0; trial < 3; ++trial) {
      const Mat3 F = random_F(rng, 0.3);
      const double J = F.determinant();
      ASSERT_GT(J, 0.0);
      double W, Wi, U, dU, d2U;
      Mat3 P, Pi;
      Tangent A, Ai, HJ;
      Vec9 gJ;
      m->evaluate(F, W, P, &A);
      m->evaluate_isochoric(F, Wi, Pi, &Ai);
      m->volumetric_energy(J, U, dU, d2U);
      det_derivatives(F, J, gJ, &HJ);
      // W = W_iso + U, P = P_iso + U' dJ/dF, A = A_iso + U'' dJ dJ^T + U' d2J
      EXPECT_NEAR(W, Wi + U, 1e-12 * std::abs(W)) << name;
      EXPECT_LT((flatten(P) - flatten(Pi) - dU * gJ).norm(), 1e-10 * flatten(P).norm()) << name;
      EXPECT_LT((A - Ai - d2U * gJ * gJ.transpose() - dU * HJ).norm(), 1e-10 * A.norm()) << name;
      // W_iso depends on Fbar only: W_iso(s F) = W_iso(F).
      double Ws;
      Mat3 Ps;
      m->evaluate_isochoric(1.3 * F, Ws, Ps, nullptr);
      EXPECT_NEAR(Ws, Wi, 1e-10 * std::abs(Wi) + 1e-9) << name;
    }
  }
}

TEST(MaterialSplit, IsochoricStressAndTangentMatchFiniteDifferences) {
  std::mt19937 rng(5);
  const double eps = 1e-7;
  for (const auto& name : kLaws) {
    auto m = law(name);
    const Mat3 F = random_F(rng, 0.25);
    double W;
    Mat3 P;
    Tangent A;
    m->evaluate_isochoric(F, W, P, &A);
    Vec9 P_fd;
    Tangent A_fd;
    for (int a = 0; a < 9; ++a) {
      Mat3 Fp = F, Fm = F;
      Fp(a / 3, a % 3) += eps;
      Fm(a / 3, a % 3) -= eps;
      double Wp, Wm;
      Mat3 Pp, Pm;
      m->evaluate_isochoric(Fp, Wp, Pp, nullptr);
      m->evaluate_isochoric(Fm, Wm, Pm, nullptr);
      P_fd(a) = (Wp - Wm) / (2 * eps);
      A_fd.col(a) = (flatten(Pp) - flatten(Pm)) / (2 * eps);
    }
    EXPECT_LT((flatten(P) - P_fd).norm(), 1e-6 * flatten(P).norm()) << name;
    EXPECT_LT((A - A_fd).norm(), 1e-6 * A.norm()) << name;
  }
}

class MeanDilatationFD : public ::testing::TestWithParam<std::string> {};

TEST_P(MeanDilatationFD, GradientAndHessianMatchFiniteDifferences) {
  Mesh mesh = morphfem::testing::one_tet(2, 7);
  Partition part{1, {0}, {0, mesh.n_nodes()}};
  MeanDilatationTerm term(mesh, part, 0, {law(GetParam())});
  for (unsigned seed : {3u, 4u}) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> d(-1e-3, 1e-3);  // ~10 % strain on a 1 cm cell
    PieceState s;
    s.X = mesh.X;
    s.u = Eigen::MatrixXd::NullaryExpr(mesh.n_nodes(), 3, [&]() { return d(rng); });
    Eigen::VectorXd g;
    Eigen::MatrixXd H;
    const double e = term.piece(0, s, &g, &H);
    EXPECT_EQ(e, term.piece(0, s, nullptr, nullptr));
    Eigen::VectorXd g_fd;
    Eigen::MatrixXd H_fd;
    morphfem::testing::piece_finite_differences(term, 0, s, 1e-8, g_fd, H_fd);
    EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm());
    EXPECT_LT((H - H_fd).norm(), 1e-6 * H.norm());
    EXPECT_LT((H - H.transpose()).norm(), 1e-10 * H.norm());
  }
}

INSTANTIATE_TEST_SUITE_P(Laws, MeanDilatationFD, ::testing::ValuesIn(kLaws));

TEST(MeanDilatation, EqualsTheDisplacementElementForAffineMotion) {
  // Uniform F: Theta = J, so V U(Theta) = int U(J) dV and both elements agree.
  Mesh mesh = morphfem::testing::one_tet(2, 9);
  for (int a = 4; a < 10; ++a) {  // straight edges: an affine field is exactly representable
    const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
    mesh.X.row(a) = 0.5 * (mesh.X.row(edge[a - 4][0]) + mesh.X.row(edge[a - 4][1]));
  }
  Partition part{1, {0}, {0, mesh.n_nodes()}};
  auto m = law("yeoh");
  MeanDilatationTerm md(mesh, part, 0, {m});
  ElasticTerm disp(mesh, part, 0, {m});
  Mat3 F;
  F << 1.05, 0.1, 0.0, -0.02, 0.97, 0.03, 0.01, 0.0, 1.02;
  PieceState s{mesh.X, mesh.X * (F - Mat3::Identity()).transpose()};
  Eigen::VectorXd g_md, g_disp;
  const double e_md = md.piece(0, s, &g_md, nullptr), e_disp = disp.piece(0, s, &g_disp, nullptr);
  EXPECT_NEAR(e_md, e_disp, 1e-10 * e_disp);
  EXPECT_LT((g_md - g_disp).norm(), 1e-8 * g_disp.norm());
  double V, theta;
  md.dilatation(s, V, theta);
  EXPECT_NEAR(theta, F.determinant(), 1e-12);
}

TEST(MeanDilatation, RigidRotationHasZeroEnergyAndInversionIsInfinite) {
  Mesh mesh = morphfem::testing::one_tet(2, 3);
  Partition part{1, {0}, {0, mesh.n_nodes()}};
  MeanDilatationTerm term(mesh, part, 0, {law("neo_hookean")});
  const Mat3 R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  PieceState s{mesh.X, mesh.X * (R - Mat3::Identity()).transpose()};
  EXPECT_NEAR(term.piece(0, s, nullptr, nullptr), 0.0, 1e-12);
  s.u.setZero();
  s.u.row(3) = -2.0 * mesh.X.row(3);
  EXPECT_TRUE(std::isinf(term.piece(0, s, nullptr, nullptr)));
}

TEST(MeanDilatation, RejectsLinearTetrahedra) {
  Mesh mesh = morphfem::testing::one_tet(1, 1);
  Partition part{1, {0}, {0, 4}};
  EXPECT_THROW(MeanDilatationTerm(mesh, part, 0, {law("neo_hookean")}), InputError);
  ASSERT_TRUE(elastic_formulations().count("mean_dilatation"));
  Mesh p2 = morphfem::testing::one_tet(2, 1);
  Partition part2{1, {0}, {0, 10}};
  auto term = elastic_formulations().at("mean_dilatation")(p2, part2, 0, {law("neo_hookean")}, 0);
  EXPECT_NE(dynamic_cast<MeanDilatationTerm*>(term.get()), nullptr);
}
