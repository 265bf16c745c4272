// Cavity pressure: the face kernel's gradient and Hessian against finite
// differences (P1, P2, every volume-axes mask), and enclosed volumes of closed
// surfaces against exact values.
#include <gtest/gtest.h>

#include <random>

#include "actuation/cavity.h"

using namespace morphfem;

class CavityFD : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(CavityFD, GradientAndHessianMatchFiniteDifferences) {
  const int order = std::get<0>(GetParam());
  const int mask = std::get<1>(GetParam());
  const std::array<bool, 3> axes{bool(mask & 1), bool(mask & 2), bool(mask & 4)};
  ShapeTable table = make_triangle_table(order, 2 * order);
  const int n = order == 1 ? 3 : 6;
  std::mt19937 rng(11 + mask);
  std::uniform_real_distribution<double> d(-0.2, 0.2);
  Eigen::MatrixXd x(n, 3);
  x.row(0) << 1, 0.2, 0.3;
  x.row(1) << 0.1, 1.2, 0.4;
  x.row(2) << 0.3, 0.1, 0.9;
  for (int a = 3; a < n; ++a) x.row(a) = 0.5 * (x.row(a - 3) + x.row((a - 2) % 3));
  for (int a = 0; a < n; ++a)
    for (int i = 0; i < 3; ++i) x(a, i) += 0.1 * d(rng);
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  cavity_face_integral(table, axes, x, &g, &H);
  const double eps = 1e-6;
  for (int j = 0; j < 3 * n; ++j) {
    Eigen::MatrixXd xp = x, xm = x;
    xp(j / 3, j % 3) += eps;
    xm(j / 3, j % 3) -= eps;
    Eigen::VectorXd gp, gm;
    const double fp = cavity_face_integral(table, axes, xp, &gp, nullptr);
    const double fm = cavity_face_integral(table, axes, xm, &gm, nullptr);
    EXPECT_NEAR(g[j], (fp - fm) / (2 * eps), 1e-8 * (1 + g.norm()));
    EXPECT_LT((H.col(j) - (gp - gm) / (2 * eps)).norm(), 1e-7 * (1 + H.norm()));
  }
  EXPECT_LT((H - H.transpose()).norm(), 1e-12 * (1 + H.norm()));
}

INSTANTIATE_TEST_SUITE_P(OrdersAndAxes, CavityFD, ::testing::Combine(::testing::Values(1, 2), ::testing::Range(1, 8)));

// Unit cube boundary as 12 outward triangles of the solid around a cavity means the
// normals point INTO the cube; volume = -(1/|S|) sum f.
TEST(CavityVolume, CubeWithEveryAxisMaskIsExact) {
  const double c[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  // Faces oriented with normals pointing into the cube (out of the surrounding solid).
  const int tri[12][3] = {{0, 1, 2}, {0, 2, 3}, {4, 6, 5}, {4, 7, 6}, {0, 4, 5}, {0, 5, 1},
                          {1, 5, 6}, {1, 6, 2}, {2, 6, 7}, {2, 7, 3}, {3, 7, 4}, {3, 4, 0}};
  ShapeTable table = make_triangle_table(1, 2);
  for (int mask = 1; mask < 8; ++mask) {
    const std::array<bool, 3> axes{bool(mask & 1), bool(mask & 2), bool(mask & 4)};
    double sum = 0;
    for (const auto& t : tri) {
      Eigen::MatrixXd x(3, 3);
      for (int a = 0; a < 3; ++a)
        for (int i = 0; i < 3; ++i) x(a, i) = 2.0 * c[t[a]][i] + 0.5;  // side 2, shifted
      sum += cavity_face_integral(table, axes, x, nullptr, nullptr);
    }
    EXPECT_NEAR(-sum / (axes[0] + axes[1] + axes[2]), 8.0, 1e-12) << "mask " << mask;
  }
}

// Open sleeve: the kernel with the open axis frozen at the reference coordinates has
// zero derivatives along that axis and matches finite differences in the others.
TEST(CavityOpenSleeve, WallIntegralMatchesFiniteDifferences) {
  for (int order : {1, 2}) {
    const std::array<bool, 3> axes{true, false, true};
    ShapeTable table = make_triangle_table(order, 2 * order);
    const int n = order == 1 ? 3 : 6;
    Eigen::MatrixXd X(n, 3);
    X.row(0) << 1, 0.2, 0.3;
    X.row(1) << 0.1, 1.2, 0.4;
    X.row(2) << 0.3, 0.1, 0.9;
    for (int a = 3; a < n; ++a) X.row(a) = 0.5 * (X.row(a - 3) + X.row((a - 2) % 3));
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> d(-0.1, 0.1);
    Eigen::MatrixXd x = X;
    for (int a = 0; a < n; ++a)
      for (int i = 0; i < 3; ++i) x(a, i) += d(rng);
    Eigen::VectorXd g;
    Eigen::MatrixXd H;
    cavity_wall_integral(table, axes, 1, X, x, &g, &H);
    const double eps = 1e-6;
    for (int j = 0; j < 3 * n; ++j) {
      Eigen::MatrixXd xp = x, xm = x;
      xp(j / 3, j % 3) += eps;
      xm(j / 3, j % 3) -= eps;
      Eigen::VectorXd gp, gm;
      const double fp = cavity_wall_integral(table, axes, 1, X, xp, &gp, nullptr);
      const double fm = cavity_wall_integral(table, axes, 1, X, xm, &gm, nullptr);
      EXPECT_NEAR(g[j], (fp - fm) / (2 * eps), 1e-8 * (1 + g.norm())) << "order " << order << " dof " << j;
      EXPECT_LT((H.col(j) - (gp - gm) / (2 * eps)).norm(), 1e-7 * (1 + H.norm()));
      if (j % 3 == 1) {
        EXPECT_EQ(g[j], 0.0);
        EXPECT_EQ(H.col(j).norm(), 0.0);
      }
    }
  }
}

// An open polygonal tube along y (N sides, radius R, length L, no caps): the sleeve
// volume is the polygon's area times L exactly, does not change when the tube is
// stretched along its axis, and the pressure forces on its wall sum to zero (no
// end-cap force). The plain [x, z] mask instead puts the caps' p A on the rims.
TEST(CavityOpenSleeve, OpenTubeHasExactVolumeAndNoCapForce) {
  const int N = 12, M = 4;
  const double R = 0.03, L = 0.15;
  const std::array<bool, 3> axes{true, false, true};
  ShapeTable table = make_triangle_table(1, 2);
  auto node = [&](int i, int j, double stretch) {
    const double th = 2 * M_PI * (i % N) / N;
    return Eigen::Vector3d(R * std::cos(th), stretch * L * j / M, R * std::sin(th));
  };
  auto sleeve = [&](double stretch, int open_axis, Eigen::Vector3d* force) {
    double sum = 0;
    force->setZero();
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < M; ++j) {
        const int quad[2][3][2] = {{{i, j}, {i + 1, j}, {i + 1, j + 1}}, {{i, j}, {i + 1, j + 1}, {i, j + 1}}};
        for (const auto& tri : quad) {
          Eigen::MatrixXd X(3, 3), x(3, 3);
          for (int a = 0; a < 3; ++a) {
            X.row(a) = node(tri[a][0], tri[a][1], 1.0).transpose();
            x.row(a) = node(tri[a][0], tri[a][1], stretch).transpose();
          }
          Eigen::VectorXd g;
          sum += cavity_wall_integral(table, axes, open_axis, X, x, &g, nullptr);
          for (int a = 0; a < 3; ++a) *force += g.segment<3>(3 * a) / 2.0;  // dE/dx per unit pressure
        }
      }
    return -sum / 2.0;
  };
  const double exact = 0.5 * N * R * R * std::sin(2 * M_PI / N) * L;
  Eigen::Vector3d f;
  EXPECT_NEAR(sleeve(1.0, 1, &f), exact, 1e-15);
  EXPECT_LT(f.norm(), 1e-15);
  EXPECT_NEAR(sleeve(1.3, 1, &f), exact, 1e-15);  // axial stretch: same cross-sections
  EXPECT_LT(f.norm(), 1e-15);
  // The plain mask: the stretched tube's volume grows with its length.
  EXPECT_NEAR(sleeve(1.3, -1, &f), 1.3 * exact, 1e-15);
}

TEST(CavityOpenSleeve, AxesMustBeTheOtherTwo) {
  EXPECT_NO_THROW(check_cavity_axes("core", {true, false, true}, 1));
  EXPECT_THROW(check_cavity_axes("core", {true, true, true}, 1), std::invalid_argument);
  EXPECT_THROW(check_cavity_axes("core", {true, false, false}, 1), std::invalid_argument);
  EXPECT_THROW(check_cavity_axes("core", {false, false, false}, -1), std::invalid_argument);
}
