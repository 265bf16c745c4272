// Element kernels: quadrature exactness, shape functions, and the elastic term's
// gradient and Hessian against finite differences of its energy (P1 and P2).
#include <gtest/gtest.h>

#include <random>

#include "fem/elastic.h"
#include "fem/element.h"
#include "fem/loads.h"
#include "fem/material.h"
#include "tests/support/finite_differences.h"
#include "tests/support/one_tet.h"

using namespace morphfem;

namespace {

// Exact integral over the reference tet of x^a y^b z^c: a! b! c! / (a+b+c+3)!
double monomial_integral(int a, int b, int c) {
  auto fact = [](int n) {
    double f = 1;
    for (int i = 2; i <= n; ++i) f *= i;
    return f;
  };
  return fact(a) * fact(b) * fact(c) / fact(a + b + c + 3);
}

}  // namespace

TEST(Quadrature, TetRulesIntegrateMonomialsExactly) {
  for (int degree = 1; degree <= 6; ++degree)
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b)
        for (int c = 0; a + b + c <= degree; ++c) {
          double sum = 0;
          for (const auto& q : tet_quadrature(degree))
            sum += q.weight * std::pow(q.xi[0], a) * std::pow(q.xi[1], b) * std::pow(q.xi[2], c);
          EXPECT_NEAR(sum, monomial_integral(a, b, c), 1e-12)
              << "degree " << degree << " x^" << a << " y^" << b << " z^" << c;
        }
}

TEST(Quadrature, TriangleRulesIntegrateMonomialsExactly) {
  auto fact = [](int n) {
    double f = 1;
    for (int i = 2; i <= n; ++i) f *= i;
    return f;
  };
  for (int degree = 1; degree <= 6; ++degree)
    for (int a = 0; a <= degree; ++a)
      for (int b = 0; a + b <= degree; ++b) {
        double sum = 0;
        for (const auto& q : triangle_quadrature(degree)) sum += q.weight * std::pow(q.xi[0], a) * std::pow(q.xi[1], b);
        EXPECT_NEAR(sum, fact(a) * fact(b) / fact(a + b + 2), 1e-12) << "degree " << degree;
      }
}

TEST(ShapeFunctions, PartitionOfUnityAndNodalInterpolation) {
  for (int order : {1, 2}) {
    const int n = order == 1 ? 4 : 10;
    Eigen::MatrixXd nodes(10, 3);
    nodes << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5, 0, 0, 0.5, 0.5, 0, 0, 0.5, 0, 0, 0, 0.5, 0.5, 0, 0.5, 0, 0.5, 0.5;
    for (int a = 0; a < n; ++a) {
      Eigen::VectorXd N;
      Eigen::MatrixXd dN;
      tet_shape(order, nodes.row(a).transpose(), N, dN);
      for (int b = 0; b < n; ++b) EXPECT_NEAR(N[b], a == b ? 1.0 : 0.0, 1e-14);
      EXPECT_NEAR(dN.colwise().sum().norm(), 0.0, 1e-13);
    }
  }
}

class ElasticFD : public ::testing::TestWithParam<std::tuple<int, std::string>> {};

TEST_P(ElasticFD, GradientAndHessianMatchFiniteDifferences) {
  const int order = std::get<0>(GetParam());
  ParamSet p("test");
  p.set_string("model", std::get<1>(GetParam()));
  if (std::get<1>(GetParam()) == "neo_hookean") p.set("mu", 1e5);
  if (std::get<1>(GetParam()) == "yeoh") {
    p.set("c1", 2e4);
    p.set("c2", 3e3);
    p.set("c3", 1e2);
  }
  p.set("kappa", 2e6);
  std::shared_ptr<const Material> law = make_material(p);
  Mesh mesh = morphfem::testing::one_tet(order, 7);
  Partition part{1, {0}, {0, mesh.n_nodes()}};
  ElasticTerm term(mesh, part, 0, {law}, order == 1 ? 1 : 4);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-1e-3, 1e-3);
  PieceState s;
  s.X = mesh.X;
  s.u = Eigen::MatrixXd::NullaryExpr(mesh.n_nodes(), 3, [&]() { return d(rng); });
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  term.piece(0, s, &g, &H);
  Eigen::VectorXd g_fd;
  Eigen::MatrixXd H_fd;
  morphfem::testing::piece_finite_differences(term, 0, s, 1e-7, g_fd, H_fd);
  EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm());
  EXPECT_LT((H - H_fd).norm(), 1e-6 * H.norm());
  EXPECT_LT((H - H.transpose()).norm(), 1e-10 * H.norm());
}

INSTANTIATE_TEST_SUITE_P(Laws, ElasticFD,
                         ::testing::Combine(::testing::Values(1, 2), ::testing::Values("neo_hookean", "yeoh")));

TEST(ElasticTerm, InvertedElementHasInfiniteEnergy) {
  ParamSet p("test");
  p.set_string("model", "neo_hookean");
  p.set("mu", 1e5);
  p.set("kappa", 1e6);
  Mesh mesh = morphfem::testing::one_tet(1, 1);
  Partition part{1, {0}, {0, 4}};
  ElasticTerm term(mesh, part, 0, {make_material(p)});
  PieceState s{mesh.X, Eigen::MatrixXd::Zero(4, 3)};
  EXPECT_EQ(term.piece(0, s, nullptr, nullptr), 0.0);
  s.u.row(3) = -2.0 * mesh.X.row(3);  // push the apex through the base
  EXPECT_TRUE(std::isinf(term.piece(0, s, nullptr, nullptr)));
}

TEST(BodyForce, GravityWorkEqualsWeightTimesCentroidDrop) {
  for (int order : {1, 2}) {
    Mesh mesh = morphfem::testing::one_tet(order, 2);
    Partition part{1, {0}, {0, mesh.n_nodes()}};
    const Eigen::Vector3d b(0, 0, -1000 * 9.81);
    BodyForceTerm term(
        mesh, part, 0, {0}, [b](const Eigen::Vector3d&, double) { return b; }, 2);
    // Uniform translation d: E = -b.d V
    PieceState s{mesh.X, Eigen::MatrixXd::Zero(mesh.n_nodes(), 3)};
    s.u.col(2).setConstant(-0.01);
    double V = 0;
    for (const auto& q : tet_quadrature(2)) {
      Eigen::VectorXd N;
      Eigen::MatrixXd dN;
      tet_shape(order, q.xi, N, dN);
      V += q.weight * (mesh.X.transpose() * dN).determinant();
    }
    EXPECT_NEAR(term.piece(0, s, nullptr, nullptr), -b.z() * (-0.01) * V, 1e-12);  // E = -b.u V
  }
}

namespace {

std::shared_ptr<const Material> yeoh_for_growth() {
  ParamSet p("test");
  p.set_string("model", "yeoh");
  p.set("c1", 2e4);
  p.set("c2", 3e3);
  p.set("c3", 1e2);
  p.set("kappa", 2e6);
  return make_material(p);
}

}  // namespace

TEST(Growth, GradientAndHessianMatchFiniteDifferences) {
  for (int order : {1, 2}) {
    Mesh mesh = morphfem::testing::one_tet(order, 5);
    Partition part{1, {0}, {0, mesh.n_nodes()}};
    ElasticTerm term(mesh, part, 0, {yeoh_for_growth()}, order == 1 ? 1 : 4);
    term.set_growth(0, [](double t) { return Eigen::Vector3d(1.0 + 0.1 * t, 1.0 + 0.6 * t, 1.0 + 4.0 * t); });
    term.set_time(0.7);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> d(-1e-3, 1e-3);
    PieceState s{mesh.X, Eigen::MatrixXd::NullaryExpr(mesh.n_nodes(), 3, [&]() { return d(rng); })};
    Eigen::VectorXd g, g_fd;
    Eigen::MatrixXd H, H_fd;
    term.piece(0, s, &g, &H);
    morphfem::testing::piece_finite_differences(term, 0, s, 1e-7, g_fd, H_fd);
    EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm()) << "P" << order;
    EXPECT_LT((H - H_fd).norm(), 1e-6 * H.norm()) << "P" << order;
  }
}

TEST(Growth, GrownShapeIsStressFreeAndOthersAreNot) {
  // u = (G - I) X makes F = G: zero energy and zero force; the undeformed state
  // then carries the growth's strain energy.
  Mesh mesh = morphfem::testing::one_tet(2, 3);
  Partition part{1, {0}, {0, mesh.n_nodes()}};
  ElasticTerm term(mesh, part, 0, {yeoh_for_growth()}, 4);
  const Eigen::Vector3d stretch(1.115, 2.35, 12.5);  // the voxel study's inflated bladder at p = 0
  term.set_growth(0, [&](double) { return stretch; });
  PieceState s{mesh.X, mesh.X * (stretch - Eigen::Vector3d::Ones()).asDiagonal()};
  Eigen::VectorXd g;
  const double e = term.piece(0, s, &g, nullptr);
  EXPECT_NEAR(e, 0.0, 1e-12);
  EXPECT_LT(g.norm(), 1e-9);
  s.u.setZero();
  EXPECT_GT(term.piece(0, s, nullptr, nullptr), 1e-3);
}
