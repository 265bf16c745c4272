// Self-contact kernels: point-triangle and edge-edge distances against dense
// sampling, and the barriers' gradients and Hessians against finite differences
// for every closest feature (face, edge, vertex; line-line, point-line,
// point-point) including near-parallel edges (mollifier active); candidate search
// on a thin plate (P1 and P2); two wedges whose edges cross with no vertex near a
// face (only the edge-edge pairs see it).
#include <gtest/gtest.h>

#include <random>

#include "contact/barrier.h"
#include "contact/self_contact.h"
#include "mesh/geometry.h"
#include "tests/support/block_mesh.h"
#include "tests/support/piece_state.h"

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

namespace {

// A 40 x 40 x 4 mm plate (mesh_size 20 mm) on one rank, and a spec whose barrier
// (dhat 1 mm) is off across the plate but whose candidates (20 dhat + r) reach it.
Mesh thin_plate(int order) { return morphfem::testing::block_mesh({0.04, 0.04, 0.004}, 0.02, order); }
using morphfem::testing::one_rank;
SelfContactSpec across_the_plate() {
  SelfContactSpec spec;
  spec.pairs = {{"zmin", "zmax"}};
  spec.dhat = 1e-3;
  spec.kappa = 1e6;
  spec.inflation = 0.0045;  // reaches across the 4 mm plate
  return spec;
}

}  // namespace

TEST(SelfContactTerm, FindsCandidatesAcrossAThinPlateOnP1AndP2) {
  for (int order : {1, 2}) {
    const Mesh mesh = thin_plate(order);
    const Partition part = one_rank(mesh);
    const SelfContactSpec spec = across_the_plate();
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

namespace {

// Central finite differences of a 4 x 3 kernel's energy and gradient against its
// analytic gradient and Hessian, at step h [m].
template <class Kernel>
void expect_derivatives_match(const Eigen::Matrix<double, 4, 3>& x, double h, Kernel&& kernel,
                              const std::string& what) {
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  const double e = kernel(x, &g, &H);
  ASSERT_TRUE(std::isfinite(e) && e > 0) << what;
  Eigen::VectorXd g_fd(12);
  Eigen::MatrixXd H_fd(12, 12);
  for (int j = 0; j < 12; ++j) {
    Eigen::Matrix<double, 4, 3> xp = x, xm = x;
    xp(j / 3, j % 3) += h;
    xm(j / 3, j % 3) -= h;
    Eigen::VectorXd gp, gm;
    g_fd[j] = (kernel(xp, &gp, nullptr) - kernel(xm, &gm, nullptr)) / (2 * h);
    H_fd.col(j) = (gp - gm) / (2 * h);
  }
  EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm()) << what;
  EXPECT_LT((H - H_fd).norm(), 1e-5 * H.norm()) << what;
  EXPECT_LT((H - H.transpose()).norm(), 1e-10 * H.norm()) << what;
  // Translation invariance: the gradient sums to zero over the four nodes.
  EXPECT_LT((g.segment<3>(0) + g.segment<3>(3) + g.segment<3>(6) + g.segment<3>(9)).norm(), 1e-9 * g.norm()) << what;
}

// Edge a along x (length 1e-2) and edge b at distance ~d: crossing skew edges
// (closest points interior: line-line), b's end near a's interior (point-line),
// end near end (point-point), or b at angle `angle` [rad] to a (near-parallel).
Eigen::Matrix<double, 4, 3> edge_configuration(const std::string& kind, double d, double angle, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Matrix<double, 4, 3> x;
  x.row(0) << 0, 0, 0;
  x.row(1) << 1, 0, 0;
  if (kind == "line-line") {
    x.row(2) << 0.4, -0.5, d / 1e-2;
    x.row(3) << 0.6, 0.5, d / 1e-2;
  } else if (kind == "point-line") {
    x.row(2) << 0.5, 0.0, d / 1e-2;
    x.row(3) << 0.5, 0.6, 0.8 + d / 1e-2;
  } else if (kind == "point-point") {
    x.row(2) << 1.0 + 0.6 * d / 1e-2, 0.0, 0.8 * d / 1e-2;
    x.row(3) << 1.8, 0.4, 0.9;
  } else {  // near-parallel: b over the middle of a, turned by `angle` about z
    x.row(2) << 0.5 - 0.4 * std::cos(angle), -0.4 * std::sin(angle), d / 1e-2;
    x.row(3) << 0.5 + 0.4 * std::cos(angle), 0.4 * std::sin(angle), d / 1e-2;
  }
  x *= 1e-2;
  // Small random perturbation. Near-parallel lines: a tilt tau moves their closest
  // points by ~ tau d / angle^2 along them, so it shrinks with angle^2 to keep the
  // closest points interior (away from the C1-only switch to point-line).
  const double size = kind == "parallel" ? 1e-3 * d * std::pow(angle / 0.1, 2) : 1e-3 * d;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) x(a, i) += size * unit(rng);
  return x;
}

}  // namespace

TEST(SelfContactKernel, EdgeEdgeDistanceMatchesDenseSampling) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 60; ++trial) {
    Eigen::Matrix<double, 4, 3> x;
    for (int a = 0; a < 4; ++a)
      for (int i = 0; i < 3; ++i) x(a, i) = unit(rng);
    if (trial % 3 == 0) x.row(3) = x.row(2) + (x.row(1) - x.row(0)) * (0.5 + 0.5 * unit(rng));  // parallel
    double best = std::numeric_limits<double>::infinity();
    const int n = 400;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        const Eigen::RowVector3d pa = x.row(0) + (double(i) / n) * (x.row(1) - x.row(0));
        const Eigen::RowVector3d pb = x.row(2) + (double(j) / n) * (x.row(3) - x.row(2));
        best = std::min(best, (pa - pb).norm());
      }
    const double d = edge_edge_distance(x);
    EXPECT_LE(d, best + 1e-12) << trial;
    EXPECT_GT(d, best - 1e-2) << trial;
  }
}

TEST(SelfContactKernel, EdgeEdgeBarrierGradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(6);
  const double dhat = 1e-3, kappa = 1e6, area = 2e-5;
  for (const std::string kind : {"line-line", "point-line", "point-point", "parallel"})
    for (double s : {0.05, 0.3, 0.7, 0.95}) {
      // Near-parallel: angles where c = |e_a x e_b|^2 lies below eps (mollified)
      // and above it; eps = 1e-3 |E_a|^2 |E_b|^2 <=> sin(angle) ~ 0.032.
      for (double angle : kind == "parallel" ? std::vector<double>{0.002, 0.01, 0.025, 0.1} : std::vector<double>{0}) {
        const Eigen::Matrix<double, 4, 3> x = edge_configuration(kind, s * dhat, angle, rng);
        const double eps = edge_edge_mollifier_threshold(x);
        const std::string what = kind + " s=" + std::to_string(s) + " angle=" + std::to_string(angle);
        EXPECT_NEAR(edge_edge_distance(x), s * dhat, 0.02 * s * dhat) << what;
        expect_derivatives_match(
            x, 1e-6 * s * dhat,
            [&](const Eigen::Matrix<double, 4, 3>& y, Eigen::VectorXd* g, Eigen::MatrixXd* H) {
              return edge_edge_barrier(y, area, kappa, dhat, eps, g, H);
            },
            what);
      }
    }
}

TEST(SelfContactKernel, EdgeEdgeMollifierVanishesForParallelEdgesAndIsOneBeyondThreshold) {
  std::mt19937 rng(7);
  const double dhat = 1e-3, kappa = 1e6, area = 2e-5;
  // Exactly parallel (no perturbation): m(0) = 0, so no energy (the point-triangle
  // pairs carry parallel contact); well beyond eps the full barrier.
  Eigen::Matrix<double, 4, 3> x;
  x << 0, 0, 0, 1e-2, 0, 0, 2e-3, 0, 0.5 * dhat, 8e-3, 0, 0.5 * dhat;
  EXPECT_EQ(edge_edge_barrier(x, area, kappa, dhat, edge_edge_mollifier_threshold(x), nullptr, nullptr), 0.0);
  const Eigen::Matrix<double, 4, 3> y = edge_configuration("line-line", 0.5 * dhat, 0, rng);
  const double d = edge_edge_distance(y);
  double phi, dphi, d2phi;
  log_barrier(d / dhat, phi, &dphi, &d2phi);
  EXPECT_NEAR(edge_edge_barrier(y, area, kappa, dhat, edge_edge_mollifier_threshold(y), nullptr, nullptr),
              area * kappa * dhat * phi, 1e-12 * area * kappa * dhat * phi);
  // Intersecting edges (exact binary coordinates, d = 0 exactly): outside the domain.
  const double q = 1.0 / 128;
  Eigen::Matrix<double, 4, 3> z;
  z << 0, 0, 0, 2 * q, 0, 0, q, -q, -q, q, q, q;
  EXPECT_TRUE(std::isinf(edge_edge_barrier(z, area, kappa, dhat, edge_edge_mollifier_threshold(z), nullptr, nullptr)));
}

namespace {

// Two P1 tetrahedra: wedge "a" with its top edge on the x axis (z = 0), wedge "b"
// with its bottom edge along y at height `gap` above it; their surfaces are the
// regions "a" and "b". Moving b down by 2 gap makes the two edges cross while
// b's vertices stay far from a's faces.
Mesh crossing_wedges(double gap) {
  Mesh mesh;
  mesh.order = 1;
  mesh.X.resize(8, 3);
  mesh.X << -1, 0, 0, 1, 0, 0, 0, -0.5, -1, 0, 0.5, -1,  //
      0, -1, gap, 0, 1, gap, -0.5, 0, gap + 1, 0.5, 0, gap + 1;
  mesh.X *= 1e-2;
  mesh.cells.resize(2, 4);
  mesh.cells << 0, 1, 2, 3, 4, 5, 6, 7;
  // Orient each cell positively and each face outward.
  for (int c = 0; c < 2; ++c) {
    const Eigen::Vector3d x0 = mesh.X.row(mesh.cells(c, 0)), x1 = mesh.X.row(mesh.cells(c, 1)),
                          x2 = mesh.X.row(mesh.cells(c, 2)), x3 = mesh.X.row(mesh.cells(c, 3));
    if ((x1 - x0).cross(x2 - x0).dot(x3 - x0) < 0) std::swap(mesh.cells(c, 2), mesh.cells(c, 3));
  }
  mesh.cell_region = {0, 0};
  mesh.faces.resize(8, 3);
  mesh.face_region.clear();
  const int local[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};  // outward for a positive tet
  for (int c = 0; c < 2; ++c)
    for (int f = 0; f < 4; ++f) {
      for (int a = 0; a < 3; ++a) mesh.faces(4 * c + f, a) = mesh.cells(c, local[f][a]);
      mesh.face_region.push_back(1 + c);
    }
  mesh.regions = {{"body", 3, 0}, {"a", 2, 1}, {"b", 2, 2}};
  return mesh;
}

// Contact between the two wedges' surfaces: dhat 0.1 mm, r = 1 mm.
SelfContactSpec between_the_wedges() {
  SelfContactSpec spec;
  spec.pairs = {{"a", "b"}};
  spec.dhat = 1e-4;
  spec.kappa = 1e6;
  spec.inflation = 1e-3;
  return spec;
}

// Total energy of a term's pieces at displacement u (n_nodes x 3).
double term_energy(const EnergyTerm& term, const Mesh& mesh, const RowMatrixXd& u) {
  double total = 0;
  std::vector<int> nodes;
  for (int k = 0; k < term.n_pieces(); ++k) {
    term.piece_nodes(k, nodes);
    total += term.piece(k, morphfem::testing::piece_state(mesh, nodes, u), nullptr, nullptr);
  }
  return total;
}

}  // namespace

TEST(SelfContactTerm, StartsAtItsStartTime) {
  const Mesh mesh = thin_plate(1);
  const Partition part = one_rank(mesh);
  SelfContactSpec spec = across_the_plate();
  const int always = SelfContactTerm(mesh, part, 0, spec).n_pieces();
  ASSERT_GT(always, 0);
  spec.start = 1.0;
  SelfContactTerm term(mesh, part, 0, spec);
  const RowMatrixXd zero = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  EXPECT_FALSE(term.active());
  EXPECT_EQ(term.n_pieces(), 0);  // no candidates, no trust region before the start
  term.set_time(0.999);
  EXPECT_FALSE(term.refresh_pieces(zero));
  EXPECT_EQ(term.n_pieces(), 0);
  term.set_time(1.0);
  EXPECT_TRUE(term.refresh_pieces(zero));  // on: the pattern must be rebuilt
  EXPECT_TRUE(term.active());
  EXPECT_EQ(term.n_pieces(), always);
  EXPECT_FALSE(term.refresh_pieces(zero));  // nothing moved since
}

// A body that turns and moves without deforming keeps its candidates (no new
// assembly pattern) and its trust region moves with it: a rolling robot would
// otherwise rebuild every step and hit the trust region whenever a step moves it by
// more than r/2. Deforming by more than r/4 still rebuilds.
TEST(SelfContactTerm, RigidMotionMovesTheTrustRegionInsteadOfRebuilding) {
  const Mesh mesh = thin_plate(1);
  const Partition part = one_rank(mesh);
  SelfContactSpec spec = across_the_plate();
  spec.dhat = 3.5e-3;  // the 4 mm plate squeezed by 0.85 mm (< r/4) is inside the barrier
  SelfContactTerm term(mesh, part, 0, spec);
  const int pairs = term.n_pairs(), edge_pairs = term.n_edge_pairs();
  RowMatrixXd squeeze = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  for (int a = 0; a < mesh.n_nodes(); ++a) squeeze(a, 2) = -0.85e-3 * mesh.X(a, 2) / 0.004;
  const double e_squeezed = term_energy(term, mesh, squeeze);
  ASSERT_GT(e_squeezed, 0.0);
  ASSERT_TRUE(std::isfinite(e_squeezed));
  // The same shape turned 50 deg about a tilted axis and moved 7 cm: 3-7 cm per node,
  // far beyond r/2 = 2.25 mm.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(50.0 * M_PI / 180.0, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  const Eigen::RowVector3d t(0.05, -0.02, 0.045);
  const auto moved = [&](const RowMatrixXd& u) {
    RowMatrixXd out(mesh.n_nodes(), 3);
    for (int a = 0; a < mesh.n_nodes(); ++a)
      out.row(a) = (mesh.X.row(a) + u.row(a)) * R.transpose() + t - mesh.X.row(a);
    return out;
  };
  const RowMatrixXd turned = moved(RowMatrixXd::Zero(mesh.n_nodes(), 3));
  EXPECT_EQ(term_energy(term, mesh, turned),
            std::numeric_limits<double>::infinity());  // outside the trust region before re-anchoring
  EXPECT_FALSE(term.refresh_pieces(turned));
  EXPECT_EQ(term.n_reanchors(), 1);
  EXPECT_EQ(term.n_refreshes(), 0);
  EXPECT_EQ(term.n_pairs(), pairs);
  EXPECT_EQ(term.n_edge_pairs(), edge_pairs);
  EXPECT_EQ(term_energy(term, mesh, turned), 0.0);
  EXPECT_NEAR(term_energy(term, mesh, moved(squeeze)), e_squeezed, 1e-9 * e_squeezed);
  // Deforming by more than r/4 = 1.125 mm from the (moved) anchor rebuilds: squeezed
  // by 3 mm, the faces are 1.5 mm from the best-fit rigid position (a translation).
  RowMatrixXd crushed = squeeze;
  for (int a = 0; a < mesh.n_nodes(); ++a) crushed(a, 2) = -3.0e-3 * mesh.X(a, 2) / 0.004;
  EXPECT_TRUE(term.refresh_pieces(moved(crushed)));
  EXPECT_EQ(term.n_refreshes(), 1);
}

// Surface pairs that share no node (two chambers) are fitted separately: each may
// turn its own way (a curling laminate turns its chambers by different angles). One
// fit over both would leave centimetres of misfit and rebuild.
TEST(SelfContactTerm, PairsWithoutCommonNodesMoveTheirTrustRegionsSeparately) {
  const Mesh mesh = thin_plate(1);
  const Partition part = one_rank(mesh);
  SelfContactSpec spec = across_the_plate();
  spec.pairs = {{"xmin", "xmin"}, {"xmax", "xmax"}};  // the two end faces: no common node
  SelfContactTerm term(mesh, part, 0, spec);
  const std::vector<int> xmin = mesh.nodes_of_surface("xmin"), xmax = mesh.nodes_of_surface("xmax");
  const Eigen::Matrix3d Ra = Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ()).matrix();
  const Eigen::Matrix3d Rb = Eigen::AngleAxisd(-0.9, Eigen::Vector3d(1, 1, 0).normalized()).matrix();
  RowMatrixXd u = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  for (int a : xmin) u.row(a) = mesh.X.row(a) * Ra.transpose() + Eigen::RowVector3d(0.01, 0, 0) - mesh.X.row(a);
  for (int a : xmax) u.row(a) = mesh.X.row(a) * Rb.transpose() + Eigen::RowVector3d(0, 0.03, 0) - mesh.X.row(a);
  EXPECT_FALSE(term.refresh_pieces(u));
  EXPECT_EQ(term.n_reanchors(), 1);
  EXPECT_EQ(term_energy(term, mesh, u), 0.0);  // both trust regions moved with their faces
  // One face bent by 2 mm > r/4 at one node: rebuild.
  u(xmax.front(), 2) += 2e-3;
  EXPECT_TRUE(term.refresh_pieces(u));
}

TEST(SelfContactTerm, EdgePairsStopCrossingEdgesThatNoVertexSees) {
  const double gap = 2e-4;
  const Mesh mesh = crossing_wedges(gap / 1e-2);
  const Partition part = one_rank(mesh);
  for (bool edges : {false, true}) {
    SelfContactSpec spec = between_the_wedges();
    spec.edge_edge = edges;
    SelfContactTerm term(mesh, part, 0, spec);
    EXPECT_EQ(term.n_edge_pairs() > 0, edges);
    // b moves down through a by 2 gap (inside the trust radius r/2 = 5e-4 m).
    RowMatrixXd u = RowMatrixXd::Zero(mesh.n_nodes(), 3);
    u.block(4, 2, 4, 1).setConstant(-2 * gap);
    // The end state has every vertex far from the other wedge's faces ...
    double min_pt = std::numeric_limits<double>::infinity();
    for (int k = 0; k < term.n_pairs(); ++k) {
      std::vector<int> nodes;
      term.piece_nodes(k, nodes);
      Eigen::Matrix<double, 4, 3> x;
      for (int a = 0; a < 4; ++a) x.row(a) = mesh.X.row(nodes[a]) + u.row(nodes[a]);
      min_pt = std::min(min_pt, point_triangle_distance(x));
    }
    EXPECT_GT(min_pt, spec.dhat);
    EXPECT_EQ(term_energy(term, mesh, u), 0.0);  // (a check of end states alone misses the crossing)
    // ... but on the way the edges meet at half the motion: only edge pairs see it.
    const double e_half = term_energy(term, mesh, 0.5 * u);
    EXPECT_EQ(std::isinf(e_half), edges) << "edge_edge " << edges;
    EXPECT_EQ(term_energy(term, mesh, 0.45 * u) > 0, edges) << "edge_edge " << edges;
  }
}

namespace {

// Every point-triangle and edge-edge distance between surfaces "a" and "b" of the
// crossing wedges at displacement u, candidates or not [m] (brute force).
double smallest_distance_between_wedges(const Mesh& mesh, const RowMatrixXd& u) {
  std::vector<std::array<int, 3>> tri[2];
  for (int f = 0; f < mesh.faces.rows(); ++f)
    tri[mesh.face_region[f] - 1].push_back({mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)});
  const auto at = [&](int n) { return Eigen::RowVector3d(mesh.X.row(n) + u.row(n)); };
  double d = std::numeric_limits<double>::infinity();
  for (int s = 0; s < 2; ++s)
    for (const auto& p : tri[s])
      for (const auto& t : tri[1 - s])
        for (int i = 0; i < 3; ++i) {
          Eigen::Matrix<double, 4, 3> x;
          x << at(p[i]), at(t[0]), at(t[1]), at(t[2]);
          d = std::min(d, point_triangle_distance(x));
          for (int j = 0; j < 3; ++j) {
            x << at(p[i]), at(p[(i + 1) % 3]), at(t[j]), at(t[(j + 1) % 3]);
            d = std::min(d, edge_edge_distance(x));
          }
        }
  return d;
}

}  // namespace

// A node whose nearest feature outside the candidates is d away gets the trust
// radius min((d - dhat)/2, R), never less than r/2: across the 4 mm plate (no
// candidates at r = 1 mm) every node may move 1.5 mm, or R if smaller.
TEST(SelfContactTerm, FarNodesGetTrustRadiiFromTheirNearestFeature) {
  for (int order : {1, 2}) {
    const Mesh mesh = thin_plate(order);
    const Partition part = one_rank(mesh);
    SelfContactSpec spec = across_the_plate();
    spec.inflation = 1e-3;
    const std::vector<int> surface = mesh.nodes_of_surface("zmin");
    for (auto [R, expected] : {std::pair{0.0, 0.5e-3}, std::pair{1e-3, 1e-3}, std::pair{5e-3, 1.5e-3}}) {
      spec.max_trust_radius = R;
      const SelfContactTerm term(mesh, part, 0, spec);
      EXPECT_EQ(term.n_pairs(), 0);
      for (int a : surface) EXPECT_NEAR(term.trust_radius(a), expected, 1e-12) << "order " << order << " R " << R;
    }
  }
}

// The far radii keep their promise: moving every node anywhere within its own
// radius leaves every pair, candidate or not, at least dhat apart, and the bound is
// tight (the two wedge edges moved towards each other by their radii end at dhat).
// Two ranks' terms (half the nodes each) give every node the same radius as one.
TEST(SelfContactTerm, MotionWithinTheFarTrustRadiiKeepsEveryPairOutsideTheBarrier) {
  const double gap = 3e-3;
  const Mesh mesh = crossing_wedges(gap / 1e-2);
  const Partition part = one_rank(mesh);
  SelfContactSpec spec = between_the_wedges();
  spec.max_trust_radius = 5e-3;
  const SelfContactTerm term(mesh, part, 0, spec);
  ASSERT_EQ(term.n_pairs() + term.n_edge_pairs(), 0);  // nothing within dhat + r
  // The edges' nodes (0, 1 of a; 4, 5 of b) are gap apart; the others farther.
  for (int a : {0, 1, 4, 5}) EXPECT_NEAR(term.trust_radius(a), 0.5 * (gap - spec.dhat), 1e-12);
  for (int a : {2, 3, 6, 7}) EXPECT_GT(term.trust_radius(a), 0.5 * (gap - spec.dhat) + 1e-4);
  Partition two = part;
  two.n_parts = 2;
  two.node_begin = {0, 4, 8};
  for (int rank : {0, 1}) {
    const SelfContactTerm half(mesh, two, rank, spec);
    for (int a = 0; a < 8; ++a) EXPECT_EQ(half.trust_radius(a), term.trust_radius(a)) << "rank " << rank;
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    RowMatrixXd u(mesh.n_nodes(), 3);
    for (int a = 0; a < mesh.n_nodes(); ++a) {
      Eigen::RowVector3d v(uniform(rng), uniform(rng), uniform(rng));
      u.row(a) = term.trust_radius(a) * std::abs(uniform(rng)) * v.normalized();
    }
    EXPECT_EQ(term_energy(term, mesh, u), 0.0);  // inside the trust region
    EXPECT_GE(smallest_distance_between_wedges(mesh, u), spec.dhat * (1 - 1e-12)) << "trial " << trial;
  }
  RowMatrixXd closing = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  for (int a : {0, 1}) closing(a, 2) = term.trust_radius(a);
  for (int a : {4, 5}) closing(a, 2) = -term.trust_radius(a);
  EXPECT_NEAR(smallest_distance_between_wedges(mesh, closing), spec.dhat, 1e-12);
  EXPECT_EQ(term_energy(term, mesh, 1.001 * closing), std::numeric_limits<double>::infinity());
}

// Squeezing the 4 mm plate by 0.6 mm is past r/2 (0.5 mm) but well inside the far
// radius (1.5 mm): the tight trust region must rebuild, the far one keeps its
// (empty) candidates.
TEST(SelfContactTerm, FarTrustRadiiRebuildLess) {
  const Mesh mesh = thin_plate(1);
  const Partition part = one_rank(mesh);
  RowMatrixXd squeeze = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  for (int a = 0; a < mesh.n_nodes(); ++a) squeeze(a, 2) = -0.6e-3 * mesh.X(a, 2) / 0.004;
  SelfContactSpec spec = across_the_plate();
  spec.inflation = 1e-3;
  SelfContactTerm tight(mesh, part, 0, spec);
  spec.max_trust_radius = 5e-3;
  SelfContactTerm far(mesh, part, 0, spec);
  EXPECT_EQ(term_energy(tight, mesh, squeeze), std::numeric_limits<double>::infinity());
  EXPECT_EQ(term_energy(far, mesh, squeeze), 0.0);
  EXPECT_TRUE(tight.refresh_pieces(squeeze));
  EXPECT_FALSE(far.refresh_pieces(squeeze));
  EXPECT_EQ(far.n_refreshes(), 0);
}
