// Inertia and damping kernels (no PETSc): element mass matrices (closed form,
// exact integration of polynomials, HRZ lumping), the inertia kernel's and the
// Kelvin-Voigt damping kernel's gradient and Hessian against finite differences,
// and the damping's frame indifference.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fem/damping.h"
#include "fem/inertia.h"

using namespace morphfem;

namespace {

// One tetrahedron of about 1 cm (P2: straight edges, mid-nodes at midpoints, or
// curved ones displaced by up to 3 % of the edge).
Eigen::MatrixXd tet_nodes(int order, bool curved, unsigned seed) {
  const int n = order == 1 ? 4 : 10;
  Eigen::MatrixXd X(n, 3);
  X.row(0) << 0, 0, 0;
  X.row(1) << 1, 0.1, 0;
  X.row(2) << 0.2, 0.9, 0.1;
  X.row(3) << 0.1, 0.2, 1.1;
  if (order == 2) {
    const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> d(-0.03, 0.03);
    for (int e = 0; e < 6; ++e)
      for (int i = 0; i < 3; ++i) X(4 + e, i) = 0.5 * (X(edge[e][0], i) + X(edge[e][1], i)) + (curved ? d(rng) : 0.0);
  }
  return 0.01 * X;
}

Eigen::MatrixXd random_field(int n, double scale, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-scale, scale);
  Eigen::MatrixXd u(n, 3);
  for (int a = 0; a < n; ++a)
    for (int i = 0; i < 3; ++i) u(a, i) = d(rng);
  return u;
}

// Volume of the straight tetrahedron of the first four nodes [m^3].
double tet_volume(const Eigen::MatrixXd& X) {
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) J.col(i) = (X.row(i + 1) - X.row(0)).transpose();
  return J.determinant() / 6.0;
}

// Central finite differences of energy(u) (u: n x 3, dof 3a + i) against the
// analytic gradient and Hessian; relative tolerances.
template <class Energy>
void check_derivatives(const Eigen::MatrixXd& u, double step, Energy&& energy, double tol_g, double tol_H) {
  const int n = static_cast<int>(u.rows());
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  energy(u, &g, &H);
  Eigen::VectorXd g_fd(3 * n);
  Eigen::MatrixXd H_fd(3 * n, 3 * n);
  for (int d = 0; d < 3 * n; ++d) {
    Eigen::MatrixXd up = u, um = u;
    up(d / 3, d % 3) += step;
    um(d / 3, d % 3) -= step;
    Eigen::VectorXd gp, gm;
    g_fd[d] = (energy(up, nullptr, nullptr) - energy(um, nullptr, nullptr)) / (2 * step);
    energy(up, &gp, nullptr);
    energy(um, &gm, nullptr);
    H_fd.col(d) = (gp - gm) / (2 * step);
  }
  EXPECT_LE((g - g_fd).norm(), tol_g * g.norm()) << "gradient\n" << g.transpose() << "\n" << g_fd.transpose();
  EXPECT_LE((H - H_fd).norm(), tol_H * H.norm()) << "Hessian";
  EXPECT_LE((H - H.transpose()).norm(), 1e-12 * H.norm()) << "Hessian not symmetric";
}

}  // namespace

TEST(TimeSchemes, NamesInOneTable) {
  EXPECT_EQ(time_schemes().at("implicit_euler"), TimeScheme::implicit_euler);
  EXPECT_EQ(time_schemes().at("bdf1"), TimeScheme::implicit_euler);
  EXPECT_EQ(time_schemes().at("bdf2"), TimeScheme::bdf2);
  EXPECT_EQ(time_schemes().at("newmark"), TimeScheme::newmark);
}

TEST(MassMatrix, ConsistentP1ClosedForm) {
  const Eigen::MatrixXd X = tet_nodes(1, false, 0);
  const double rho = 1070.0, V = tet_volume(X);
  const Eigen::MatrixXd M = element_mass_matrix(make_mass_table(1), X, rho, false);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) EXPECT_NEAR(M(a, b), rho * V / 20.0 * (a == b ? 2.0 : 1.0), 1e-12 * rho * V);
  const Eigen::MatrixXd lumped = element_mass_matrix(make_mass_table(1), X, rho, true);
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) EXPECT_NEAR(lumped(a, b), a == b ? rho * V / 4.0 : 0.0, 1e-12 * rho * V);
}

// For straight-sided cells the mass matrix integrates products of interpolated
// fields exactly: 1^T M 1 = rho V and x_i^T M x_j = rho int X_i X_j dV (P1: linear
// fields; P2: also quadratic ones, here X_i X_j interpolated through the nodes).
TEST(MassMatrix, ConsistentIntegratesInterpolatedFieldsExactly) {
  for (int order : {1, 2}) {
    const Eigen::MatrixXd X = tet_nodes(order, false, 0);
    const int n = static_cast<int>(X.rows());
    const double rho = 1000.0, V = tet_volume(X);
    const Eigen::MatrixXd M = element_mass_matrix(make_mass_table(order), X, rho, false);
    EXPECT_NEAR(M.sum(), rho * V, 1e-12 * rho * V);
    EXPECT_LE((M - M.transpose()).norm(), 1e-14 * M.norm());
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff(), 0.0);
    // Reference integrals by a degree-6 rule on the affine map.
    const ShapeTable fine = make_tet_table(1, 6);
    const Eigen::MatrixXd X1 = X.topRows(4);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double exact = 0.0, exact4 = 0.0;
        for (size_t q = 0; q < fine.points.size(); ++q) {
          const Eigen::Vector3d x = X1.transpose() * fine.N[q];
          const double dV = fine.points[q].weight * 6.0 * V;
          exact += rho * dV * x[i] * x[j];
          exact4 += rho * dV * x[i] * x[i] * x[j] * x[j];
        }
        const double scale = rho * V * X.squaredNorm() / n;
        EXPECT_NEAR(X.col(i).dot(M * X.col(j)), exact, 1e-12 * scale) << "order " << order;
        if (order == 2) {
          const Eigen::VectorXd fi = X.col(i).cwiseProduct(X.col(i)), fj = X.col(j).cwiseProduct(X.col(j));
          EXPECT_NEAR(fi.dot(M * fj), exact4, 1e-10 * exact4) << "quadratic fields";
        }
      }
  }
}

// HRZ lumping: positive diagonal summing to rho V, also for P2 whose consistent
// row sums are negative at the vertices (int N_vertex dV = -V/20).
TEST(MassMatrix, HrzLumpingIsPositiveAndConservesMass) {
  for (bool curved : {false, true}) {
    const Eigen::MatrixXd X = tet_nodes(2, curved, 7);
    const double rho = 1000.0;
    const Eigen::MatrixXd M = element_mass_matrix(make_mass_table(2), X, rho, false);
    const Eigen::MatrixXd lumped = element_mass_matrix(make_mass_table(2), X, rho, true);
    EXPECT_NEAR(lumped.sum(), M.sum(), 1e-12 * M.sum());
    EXPECT_LT(M.row(0).sum(), 0.0);
    for (int a = 0; a < 10; ++a) {
      EXPECT_GT(lumped(a, a), 0.0);
      for (int b = 0; b < 10; ++b) {
        if (a != b) {
          EXPECT_EQ(lumped(a, b), 0.0);
        }
      }
    }
  }
}

TEST(InertiaKernel, GradientAndHessianMatchFiniteDifferences) {
  for (int order : {1, 2})
    for (bool lumped : {false, true}) {
      const Eigen::MatrixXd X = tet_nodes(order, true, 3);
      const int n = static_cast<int>(X.rows());
      const Eigen::MatrixXd M = element_mass_matrix(make_mass_table(order), X, 1200.0, lumped);
      const Eigen::MatrixXd pred = random_field(n, 1e-3, 11);
      const double c = 1.0 / (0.25 * 1e-3 * 1e-3);  // Newmark, h = 1 ms [1/s^2]
      check_derivatives(
          random_field(n, 1e-3, 12), 1e-6,
          [&](const Eigen::MatrixXd& u, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
            return inertia_kernel(M, c, u - pred, g, H);
          },
          1e-7, 1e-7);
    }
}

TEST(DampingKernel, GradientAndHessianMatchFiniteDifferences) {
  for (int order : {1, 2}) {
    const Eigen::MatrixXd X = tet_nodes(order, true, 5);
    const int n = static_cast<int>(X.rows());
    const ShapeTable table = make_tet_table(order, order == 1 ? 1 : 2);
    // Large strains (up to ~30 %) at the step start and end.
    const std::vector<Mat3> E_n = green_lagrange_at_points(table, X, random_field(n, 2e-3, 21));
    check_derivatives(
        random_field(n, 2e-3, 22), 1e-7,
        [&](const Eigen::MatrixXd& u, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
          return viscous_damping_kernel(table, X, u, E_n, 300.0, 150.0, 1e-3, g, H);
        },
        1e-6, 1e-6);
  }
}

// A rigid rotation of the step-start configuration dissipates nothing; a small
// uniform shear rate gamma_dot dissipates eta gamma_dot^2 V h (D = W_diss / 2).
TEST(DampingKernel, FrameIndifferentAndKelvinVoigtAtSmallStrain) {
  for (int order : {1, 2}) {
    const Eigen::MatrixXd X = tet_nodes(order, false, 0);
    const int n = static_cast<int>(X.rows());
    const ShapeTable table = make_tet_table(order, order == 1 ? 1 : 2);
    const Eigen::MatrixXd u_n = random_field(n, 1e-3, 31);
    const std::vector<Mat3> E_n = green_lagrange_at_points(table, X, u_n);
    const Mat3 R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::MatrixXd x_rot = (X + u_n) * R.transpose();
    Eigen::VectorXd g;
    const double eta = 300.0, h = 1e-3;
    EXPECT_NEAR(viscous_damping_kernel(table, X, x_rot - X, E_n, eta, 100.0, h, &g, nullptr), 0.0, 1e-18);
    EXPECT_LE(g.norm(), 1e-9);
    // Simple shear u = gamma X_2 e_1 over one step from the reference state.
    const double gamma = 1e-6, V = tet_volume(X);
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, 3);
    u.col(0) = gamma * X.col(1);
    const std::vector<Mat3> E0(table.points.size(), Mat3::Zero());
    const double D = viscous_damping_kernel(table, X, u, E0, eta, 0.0, h, nullptr, nullptr);
    // dev dE = sym shear gamma/2 (+ O(gamma^2)): |dev dE|^2 = gamma^2 / 2; D = eta/h gamma^2/2 V
    EXPECT_NEAR(D, eta / h * 0.5 * gamma * gamma * V, 1e-5 * D);
  }
}
