// Contact kernels: the log barrier, nodal area weights, the ground-contact and
// friction pieces' gradients and Hessians against finite differences at random
// states (P1 and P2 surfaces, flat and inclined planes), the friction law's
// continuity and limits, and coefficients per region over time.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "contact/barrier.h"
#include "contact/friction.h"
#include "contact/ground.h"
#include "core/errors.h"
#include "tests/support/block_mesh.h"

using namespace morphfem;

namespace {

Mesh block(int order, double mesh_size = 0.05) {
  return morphfem::testing::block_mesh({0.1, 0.08, 0.06}, mesh_size, order);
}
using morphfem::testing::one_rank;

// Central-difference check of a one-node piece's gradient and Hessian at s.
void check_piece_fd(const EnergyTerm& term, int k, const PieceState& s, double h, const std::string& what) {
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  const double e = term.piece(k, s, &g, &H);
  ASSERT_TRUE(std::isfinite(e)) << what;
  const int n = static_cast<int>(g.size());
  Eigen::VectorXd g_fd(n);
  Eigen::MatrixXd H_fd(n, n);
  for (int j = 0; j < n; ++j) {
    PieceState sp = s, sm = s;
    sp.u(j / 3, j % 3) += h;
    sm.u(j / 3, j % 3) -= h;
    Eigen::VectorXd gp, gm;
    const double ep = term.piece(k, sp, &gp, nullptr), em = term.piece(k, sm, &gm, nullptr);
    g_fd[j] = (ep - em) / (2 * h);
    H_fd.col(j) = (gp - gm) / (2 * h);
  }
  EXPECT_LT((g - g_fd).norm(), 1e-6 * (g.norm() + 1e-12))
      << what << "\n g " << g.transpose() << "\n fd " << g_fd.transpose();
  EXPECT_LT((H - H_fd).norm(), 1e-6 * (H.norm() + 1e-12)) << what << "\n H\n" << H << "\n fd\n" << H_fd;
  EXPECT_LT((H - H.transpose()).norm(), 1e-12 * (H.norm() + 1e-30)) << what;
}

}  // namespace

TEST(Barrier, DerivativesMatchFiniteDifferencesAndVanishAtOne) {
  for (double s : {1e-3, 0.01, 0.1, 0.3, 0.5, 0.8, 0.99}) {
    const double h = 1e-6 * s;
    EXPECT_NEAR(barrier_dphi(s), (barrier_phi(s + h) - barrier_phi(s - h)) / (2 * h), 1e-6 * std::abs(barrier_dphi(s)));
    EXPECT_NEAR(barrier_d2phi(s), (barrier_dphi(s + h) - barrier_dphi(s - h)) / (2 * h),
                1e-6 * std::abs(barrier_d2phi(s)));
    EXPECT_GT(barrier_phi(s), 0);
    EXPECT_LT(barrier_dphi(s), 0);
    EXPECT_GT(barrier_d2phi(s), 0);
  }
  EXPECT_NEAR(barrier_phi(1 - 1e-8), 0, 1e-20);
  EXPECT_NEAR(barrier_dphi(1 - 1e-8), 0, 1e-12);
  EXPECT_NEAR(barrier_d2phi(1 - 1e-8), 0, 1e-7);
  EXPECT_EQ(barrier_phi(1.5), 0);
}

TEST(NodalAreaWeights, SumToTheSurfaceAreaAndArePositiveOnP1AndP2) {
  for (int order : {1, 2}) {
    const Mesh mesh = block(order);
    const auto w = nodal_area_weights(mesh, mesh.faces_of("zmin"));
    double total = 0;
    for (int a : mesh.nodes_of_surface("zmin")) {
      EXPECT_GT(w[a], 0) << "order " << order << " node " << a;
      total += w[a];
    }
    EXPECT_NEAR(total, 0.1 * 0.08, 1e-14) << "order " << order;
  }
}

TEST(GroundContact, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int order : {1, 2})
    for (int inclined : {0, 1}) {
      const Mesh mesh = block(order);
      const Partition part = one_rank(mesh);
      GroundContactSpec spec;
      spec.surfaces = {"zmin", "xmin"};
      spec.normal = inclined ? Eigen::Vector3d(-0.3, 0.2, 1.0) : Eigen::Vector3d(0, 0, 1);
      spec.point = Eigen::Vector3d(0.05, 0.04, -0.05);
      spec.dhat = 1e-3;
      spec.kappa = 1e6;
      GroundContactTerm term(mesh, part, 0, spec);
      ASSERT_GT(term.n_pieces(), 0);
      const Eigen::Vector3d n = term.normal();
      int checked = 0;
      for (int k = 0; k < term.n_pieces(); k += 3) {
        PieceState s;
        std::vector<int> nodes;
        term.piece_nodes(k, nodes);
        s.X = mesh.X.row(nodes[0]);
        // Random position with gap in (0.02, 0.98) dhat plus a random tangential part.
        const double target = (0.02 + 0.96 * unit(rng)) * spec.dhat;
        const double gap0 = term.gap(s.X.row(0).transpose());
        Eigen::Vector3d u = (target - gap0) * n + 0.01 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).cross(n);
        s.u = u.transpose();
        check_piece_fd(term, k, s, 1e-5 * target, "order " + std::to_string(order) + " k " + std::to_string(k));
        ++checked;
      }
      EXPECT_GT(checked, 3);
    }
}

TEST(GroundContact, EnergyIsInfiniteAtOrBelowThePlaneAndZeroBeyondDhat) {
  const Mesh mesh = block(1);
  const Partition part = one_rank(mesh);
  GroundContactSpec spec;
  spec.surfaces = {"zmin"};
  spec.point = Eigen::Vector3d(0, 0, -1e-4);
  spec.dhat = 1e-3;
  spec.kappa = 1e6;
  GroundContactTerm term(mesh, part, 0, spec);
  std::vector<int> nodes;
  term.piece_nodes(0, nodes);
  PieceState s;
  s.X = mesh.X.row(nodes[0]);
  s.u = Eigen::RowVector3d(0, 0, -1e-4);
  EXPECT_TRUE(std::isinf(term.piece(0, s, nullptr, nullptr)));
  s.u = Eigen::RowVector3d(0, 0, -2e-4);
  EXPECT_TRUE(std::isinf(term.piece(0, s, nullptr, nullptr)));
  s.u = Eigen::RowVector3d(0, 0, 0.95e-3);
  EXPECT_EQ(term.piece(0, s, nullptr, nullptr), 0.0);
  // Normal force A kappa (-phi'(s)) in N.
  const double w = term.area_weight(nodes[0]);
  EXPECT_GT(w, 0);
  EXPECT_NEAR(term.normal_force(w, 0.5e-3), w * 1e6 * -barrier_dphi(0.5), 1e-12);
}

TEST(GroundContact, RejectsNodesStartingBelowThePlaneAndUnknownSurfaces) {
  const Mesh mesh = block(1);
  const Partition part = one_rank(mesh);
  GroundContactSpec spec;
  spec.surfaces = {"zmin"};
  spec.kappa = 1e6;
  EXPECT_THROW(GroundContactTerm(mesh, part, 0, spec), InputError);  // plane through the face
  spec.point = Eigen::Vector3d(0, 0, -1e-4);
  spec.surfaces = {"no_such_surface"};
  EXPECT_THROW(GroundContactTerm(mesh, part, 0, spec), InputError);
  spec.surfaces = {"zmin"};
  spec.kappa = 0;
  EXPECT_THROW(GroundContactTerm(mesh, part, 0, spec), InputError);  // no kappa, no modulus
  spec.young_modulus = 2e5;
  EXPECT_NO_THROW(GroundContactTerm(mesh, part, 0, spec));
}

TEST(FrictionLaw, IsContinuousWithTheStatedLimitsAndDerivatives) {
  for (double mu_k : {0.3, 0.5, 0.7}) {
    FrictionLaw f{0.5, mu_k, 2e-4};
    const double eps = f.eps;
    EXPECT_EQ(f.force(0), 0);
    EXPECT_NEAR(f.force(eps), 0.5, 1e-15);       // static limit reached at slip eps
    EXPECT_NEAR(f.force(2 * eps), mu_k, 1e-15);  // kinetic value from 2 eps on
    EXPECT_NEAR(f.force(10 * eps), mu_k, 1e-15);
    EXPECT_NEAR(f.force_over_y(0), 2 * 0.5 / eps, 1e-9);
    for (double y :
         {0.1 * eps, 0.5 * eps, 0.999 * eps, 1.001 * eps, 1.3 * eps, 1.7 * eps, 1.999 * eps, 2.001 * eps, 3 * eps}) {
      const double h = 1e-6 * eps;
      EXPECT_NEAR(f.force(y), (f.potential(y + h) - f.potential(y - h)) / (2 * h), 1e-7) << y / eps;
      EXPECT_NEAR(f.dforce(y), (f.force(y + h) - f.force(y - h)) / (2 * h), 1e-6 / eps) << y / eps;
      EXPECT_NEAR(f.force_over_y(y), f.force(y) / y, 1e-9 / eps);
    }
    // Potential and force continuous at eps and 2 eps.
    for (double y : {eps, 2 * eps}) {
      EXPECT_NEAR(f.potential(y * (1 - 1e-12)), f.potential(y * (1 + 1e-12)), 1e-15);
      EXPECT_NEAR(f.force(y * (1 - 1e-12)), f.force(y * (1 + 1e-12)), 1e-9);
    }
  }
}

class FrictionFD : public ::testing::TestWithParam<std::tuple<int, double>> {};

// Exact (unprojected) Hessian against finite differences; slips in the stick
// range, the static->kinetic drop and the kinetic range; flat and inclined planes.
TEST_P(FrictionFD, GradientAndHessianMatchFiniteDifferences) {
  const int order = std::get<0>(GetParam());
  const double mu_k = std::get<1>(GetParam());
  const Mesh mesh = block(order);
  const Partition part = one_rank(mesh);
  std::mt19937 rng(7 + order);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int inclined : {0, 1}) {
    GroundContactSpec gs;
    gs.surfaces = {"zmin"};
    gs.normal = inclined ? Eigen::Vector3d(0.4, -0.1, 1.0) : Eigen::Vector3d(0, 0, 1);
    gs.point = Eigen::Vector3d(0.05, 0.04, -0.05);
    gs.dhat = 1e-3;
    gs.kappa = 1e6;
    auto ground = std::make_shared<GroundContactTerm>(mesh, part, 0, gs);
    FrictionSpec fs;
    fs.regions = {{"zmin", TimeFunction::constant(0.6), TimeFunction::constant(mu_k)}};
    fs.eps_v = 1e-3;
    // The exact Hessian two ways: no projection at all (level ground), or a projecting
    // term asked for the exact one by the solver's adaptive projection (inclined).
    fs.project_hessian = inclined == 1;
    FrictionTerm term(mesh, part, 0, ground, fs);
    if (inclined) term.set_exact_hessian(true);
    const double h_step = 0.1;
    term.set_step_length(h_step);
    const double eps = fs.eps_v * h_step;
    ASSERT_EQ(term.n_pieces(), ground->n_pieces());
    int k = 0;
    for (double y_over_eps : {0.0, 0.05, 0.4, 0.9, 1.2, 1.5, 1.9, 2.5, 10.0}) {
      k = (k + 5) % term.n_pieces();
      std::vector<int> nodes;
      term.piece_nodes(k, nodes);
      const Eigen::Vector3d u0(unit(rng) * 1e-3, unit(rng) * 1e-3, unit(rng) * 1e-3);
      term.set_lagged(k, 2.5, u0);
      // Displacement: u0 + a tangential slip of length y + a normal part (ignored by D).
      const Eigen::Vector3d n = ground->normal();
      Eigen::Vector3d t = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).cross(n).normalized();
      PieceState s;
      s.X = mesh.X.row(nodes[0]);
      s.u = (u0 + y_over_eps * eps * t + 3e-4 * unit(rng) * n).transpose();
      const double fd_h = y_over_eps == 0.0 ? 1e-4 * eps : 1e-4 * eps * std::min(1.0, y_over_eps);
      if (y_over_eps == 0.0) {
        // At zero slip the energy is C2 and the Hessian is lambda 2 mu_s/eps P.
        Eigen::MatrixXd H;
        Eigen::VectorXd g;
        term.piece(k, s, &g, &H);
        const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - n * n.transpose();
        EXPECT_LT((H - 2.5 * 2 * 0.6 / eps * P).norm(), 1e-9 * H.norm());
        EXPECT_LT(g.norm(), 1e-12);
        continue;
      }
      check_piece_fd(
          term, k, s, fd_h,
          "order " + std::to_string(order) + " y/eps " + std::to_string(y_over_eps) + " mu_k " + std::to_string(mu_k));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(OrdersAndKinetic, FrictionFD,
                         ::testing::Combine(::testing::Values(1, 2), ::testing::Values(0.6, 0.4)));

TEST(Friction, ProjectedHessianIsPositiveSemidefinite) {
  const Mesh mesh = block(1);
  const Partition part = one_rank(mesh);
  GroundContactSpec gs;
  gs.surfaces = {"zmin"};
  gs.point = Eigen::Vector3d(0, 0, -1e-4);
  gs.dhat = 1e-3;
  gs.kappa = 1e6;
  auto ground = std::make_shared<GroundContactTerm>(mesh, part, 0, gs);
  FrictionSpec fs;
  fs.regions = {{"zmin", TimeFunction::constant(0.8), TimeFunction::constant(0.3)}};
  FrictionTerm term(mesh, part, 0, ground, fs);
  term.set_step_length(1.0);
  const double eps = fs.eps_v;
  std::vector<int> nodes;
  term.piece_nodes(0, nodes);
  term.set_lagged(0, 1.0, Eigen::Vector3d::Zero());
  for (double y : {0.3, 1.0, 1.25, 1.5, 1.75, 2.0, 4.0}) {
    PieceState s;
    s.X = mesh.X.row(nodes[0]);
    s.u = Eigen::RowVector3d(y * eps * 0.6, y * eps * 0.8, 0);
    Eigen::MatrixXd H;
    term.piece(0, s, nullptr, &H);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(H);
    EXPECT_GE(es.eigenvalues().minCoeff(), -1e-12 * H.norm()) << "y/eps " << y;
    // The exact Hessian (adaptive projection) has the drop's negative curvature, and
    // only inside the drop (eps, 2 eps); the term projects again once released.
    term.set_exact_hessian(true);
    term.piece(0, s, nullptr, &H);
    term.set_exact_hessian(false);
    const double min_exact = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff();
    if (y > 1.0 && y < 2.0)
      EXPECT_LT(min_exact, -1e-6 * H.norm()) << "y/eps " << y;
    else
      EXPECT_GE(min_exact, -1e-12 * H.norm()) << "y/eps " << y;
  }
  PieceState s;
  s.X = mesh.X.row(nodes[0]);
  s.u = Eigen::RowVector3d(1.5 * eps * 0.6, 1.5 * eps * 0.8, 0);
  Eigen::MatrixXd H;
  term.piece(0, s, nullptr, &H);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(H).eigenvalues().minCoeff(), -1e-12 * H.norm());
}

// Two regions meeting at an edge; coefficients switch over time. A node inside a
// region follows that region's schedule; a node on the shared edge gets the
// area-weighted mean.
TEST(Friction, CoefficientsPerRegionFollowTheirScheduleOverTime) {
  const Mesh mesh = block(1);
  const Partition part = one_rank(mesh);
  GroundContactSpec gs;
  gs.surfaces = {"zmin", "xmin"};
  gs.normal = Eigen::Vector3d(1, 0, 1);
  gs.point = Eigen::Vector3d(-0.01, 0, -0.01);
  gs.dhat = 1e-3;
  gs.kappa = 1e6;
  auto ground = std::make_shared<GroundContactTerm>(mesh, part, 0, gs);
  FrictionSpec fs;
  const TimeFunction foot({{0.0, 2.0}, {1.0, 2.0}, {1.001, 1e-4}, {2.0, 1e-4}});
  fs.regions = {{"zmin", foot, foot}, {"xmin", TimeFunction::constant(0.5), TimeFunction::constant(0.5)}};
  fs.eps_v = 1e-3;
  FrictionTerm term(mesh, part, 0, ground, fs);
  const auto w_z = nodal_area_weights(mesh, mesh.faces_of("zmin"));
  const auto w_x = nodal_area_weights(mesh, mesh.faces_of("xmin"));
  term.set_step_length(1.0);
  const double y = 5 * fs.eps_v;  // kinetic range: force = mu_k lambda
  int interior = 0, shared = 0;
  for (double t : {0.5, 1.5}) {
    term.set_time(t);
    for (int k = 0; k < term.n_pieces(); ++k) {
      std::vector<int> nodes;
      term.piece_nodes(k, nodes);
      const int a = nodes[0];
      term.set_lagged(k, 1.0, Eigen::Vector3d::Zero());
      PieceState s;
      s.X = mesh.X.row(a);
      s.u = Eigen::RowVector3d(0, y, 0);  // tangential to the plane
      Eigen::VectorXd g;
      term.piece(k, s, &g, nullptr);
      const double mu_expected = (w_z[a] * foot(t) + w_x[a] * 0.5) / (w_z[a] + w_x[a]);
      EXPECT_NEAR(g.norm(), mu_expected, 1e-12) << "t " << t << " node " << a;
      if (w_z[a] > 0 && w_x[a] > 0) ++shared;
      if (w_z[a] > 0 && w_x[a] == 0) ++interior;
    }
  }
  EXPECT_GT(shared, 0);
  EXPECT_GT(interior, 0);
}

TEST(Friction, RejectsFrictionSurfacesThatAreNotContactSurfaces) {
  const Mesh mesh = block(1);
  const Partition part = one_rank(mesh);
  GroundContactSpec gs;
  gs.surfaces = {"zmin"};
  gs.point = Eigen::Vector3d(0, 0, -1e-4);
  gs.kappa = 1e6;
  auto ground = std::make_shared<GroundContactTerm>(mesh, part, 0, gs);
  FrictionSpec fs;
  fs.regions = {{"zmax", TimeFunction::constant(0.5), TimeFunction::constant(0.5)}};
  EXPECT_THROW(FrictionTerm(mesh, part, 0, ground, fs), InputError);
}
