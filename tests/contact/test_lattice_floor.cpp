// The lattice floor contact (contact/lattice_floor.h): interpolation weights, the
// piece's gradient and Hessian against finite differences (barrier and lagged
// friction, P1 and P2), exact CCD, the growing radius's catch-up rule, bad input,
// and the robot_voxel lattice's voxel count against the voxel study's 1428.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "contact/lattice_floor.h"
#include "core/errors.h"
#include "fem/assembly.h"
#include "mesh/robot.h"
#include "tests/support/block_mesh.h"
#include "tests/support/finite_differences.h"
#include "tests/support/petsc_environment.h"
#include "tests/support/piece_state.h"

using namespace morphfem;
using morphfem::testing::one_rank;

namespace {

Mesh block(int order) { return morphfem::testing::block_mesh({0.02, 0.01, 0.01}, 0.005, order); }

std::vector<int> all_cells(const Mesh& mesh) {
  std::vector<int> cells(mesh.n_cells());
  for (int e = 0; e < mesh.n_cells(); ++e) cells[e] = e;
  return cells;
}

// The material point at the block's centre (0.01, 0.005, 0.005), radius r(t) = r0 + rate t.
LatticePoint whole_block_point(const Mesh& mesh, double r0, double rate = 0.0) {
  LatticePoint p;
  p.owner_cell = interpolation_weights(mesh, all_cells(mesh), Eigen::Vector3d(0.01, 0.005, 0.005), p.nodes, p.weights);
  p.area = 2e-4;
  p.radius = [r0, rate](double t) { return r0 + rate * t; };
  p.mu = TimeFunction::constant(0.8);
  return p;
}

LatticeFloorSpec floor_at(double z) {
  LatticeFloorSpec spec;
  spec.point = Eigen::Vector3d(0, 0, z);
  spec.dhat = 1e-3;
  spec.kappa = 1e6;
  spec.eps_v = 1e-3;
  return spec;
}

}  // namespace

// The weights interpolate: they sum to 1, give the reference point back, move
// exactly with an affine deformation, and come from a cell that contains the point
// (P1 and P2); a point outside every cell takes the nearest cell.
TEST(LatticeFloor, InterpolationWeightsFollowAffineMotionFromTheContainingCell) {
  Eigen::Matrix3d A;
  A << 1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.3;
  const Eigen::Vector3d b(0.3, -0.1, 0.02);
  for (int order : {1, 2}) {
    const Mesh mesh = block(order);
    for (const Eigen::Vector3d& X : {Eigen::Vector3d(0.0123, 0.0041, 0.0077), Eigen::Vector3d(0.005, 0.005, 0.005),
                                     Eigen::Vector3d(0.025, 0.005, 0.005)}) {
      std::vector<int> nodes;
      std::vector<double> w;
      const int cell = interpolation_weights(mesh, all_cells(mesh), X, nodes, w);
      ASSERT_EQ(static_cast<int>(nodes.size()), mesh.nodes_per_cell());
      double sum = 0.0;
      Eigen::Vector3d c = Eigen::Vector3d::Zero(), moved = Eigen::Vector3d::Zero();
      for (size_t a = 0; a < nodes.size(); ++a) {
        sum += w[a];
        c += w[a] * mesh.X.row(nodes[a]).transpose();
        moved += w[a] * (A * mesh.X.row(nodes[a]).transpose() + b);
        EXPECT_EQ(nodes[a], mesh.cells(cell, a));
      }
      EXPECT_NEAR(sum, 1.0, 1e-12) << order;
      EXPECT_LT((c - X).norm(), 1e-12) << order;
      EXPECT_LT((moved - (A * X + b)).norm(), 1e-12) << order;
      if (X.x() < 0.02) {  // inside the block: a containing cell, all its shape functions' vertex parts >= 0
        const Eigen::Vector3d x0 = mesh.X.row(mesh.cells(cell, 0)).transpose();
        Eigen::Matrix3d J;
        for (int i = 0; i < 3; ++i) J.col(i) = mesh.X.row(mesh.cells(cell, i + 1)).transpose() - x0;
        const Eigen::Vector3d xi = J.inverse() * (X - x0);
        EXPECT_GE(std::min(1.0 - xi.sum(), xi.minCoeff()), -1e-12) << order;
      } else {  // outside (x = 0.025 > 0.02): a cell on the face x = 0.02
        EXPECT_NEAR(mesh.X.col(0).maxCoeff(), 0.02, 1e-15);
        bool on_face = false;
        for (int a = 0; a < 4; ++a) on_face = on_face || std::abs(mesh.X(mesh.cells(cell, a), 0) - 0.02) < 1e-12;
        EXPECT_TRUE(on_face) << order;
      }
    }
  }
  const Mesh mesh = block(1);
  std::vector<int> nodes;
  std::vector<double> w;
  EXPECT_THROW(interpolation_weights(mesh, {}, Eigen::Vector3d::Zero(), nodes, w), InputError);
}

// The grid-narrowed locator picks the same cell (so the same weights) as the full
// scan, for random points inside and outside the block and for points on the
// mesh's vertices, edges and faces (a lattice of 2.5 mm steps over a 5 mm mesh),
// where several cells contain the point.
TEST(LatticeFloor, CellLocatorFindsTheFullScansCell) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(-0.004, 0.024), yz(-0.002, 0.012);
  for (int order : {1, 2}) {
    const Mesh mesh = block(order);
    const CellLocator locator(mesh, all_cells(mesh));
    std::vector<Eigen::Vector3d> points;
    for (int k = 0; k < 300; ++k) points.emplace_back(x(rng), yz(rng), yz(rng));
    for (int i = 0; i <= 8; ++i)
      for (int j = 0; j <= 4; ++j)
        for (int l = 0; l <= 4; ++l) points.emplace_back(0.0025 * i, 0.0025 * j, 0.0025 * l);
    int outside = 0;
    for (const Eigen::Vector3d& X : points) {
      std::vector<int> nodes_scan, nodes_grid;
      std::vector<double> w_scan, w_grid;
      const int scan = interpolation_weights(mesh, all_cells(mesh), X, nodes_scan, w_scan);
      ASSERT_EQ(locator.weights(X, nodes_grid, w_grid), scan) << order << " X = " << X.transpose();
      EXPECT_EQ(nodes_grid, nodes_scan);
      EXPECT_EQ(w_grid, w_scan);
      outside += X.x() < 0 || X.x() > 0.02 || X.y() < 0 || X.y() > 0.01 || X.z() < 0 || X.z() > 0.01;
    }
    EXPECT_GT(outside, 50) << "the random points must test the fall-back to the full scan";
  }
  EXPECT_THROW(CellLocator(block(1), {}), InputError);
}

// Barrier and friction together, exact Hessian, slips in the stick range, the
// smoothing's end and sliding; P1 and P2 points.
TEST(LatticeFloor, GradientAndHessianMatchFiniteDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int order : {1, 2}) {
    const Mesh mesh = block(order);
    const Partition part = one_rank(mesh);
    // Centre at z = 0.005, radius 0.004: the sphere 1 mm above a floor at z = 0.
    LatticeFloorTerm term(mesh, part, 0, floor_at(-0.0004), {whole_block_point(mesh, 0.004)});
    term.set_exact_hessian(true);
    const double h = 0.05;
    term.set_step_length(h);
    const double eps = term.spec().eps_v * h;
    ASSERT_EQ(term.n_pieces(), 1);
    std::vector<int> nodes;
    term.piece_nodes(0, nodes);
    for (double slip_over_eps : {0.3, 0.9, 1.5, 4.0}) {
      // A random small deformation that keeps the centre inside the barrier (gap
      // 0.2..0.8 dhat): the centre moves down 0.6 mm and sideways by the slip.
      RowMatrixXd u = RowMatrixXd::Zero(mesh.n_nodes(), 3);
      for (int a = 0; a < mesh.n_nodes(); ++a)
        for (int i = 0; i < 3; ++i) u(a, i) = 5e-5 * unit(rng);
      PieceState s = morphfem::testing::piece_state(mesh, nodes, u);
      const Eigen::Vector3d c_rest = term.centre(0, s);
      const Eigen::Vector3d shift(slip_over_eps * eps, 0.3 * slip_over_eps * eps,
                                  -(c_rest.z() - 0.0041) + 1e-4 * unit(rng));
      for (int a = 0; a < s.u.rows(); ++a) s.u.row(a) += shift.transpose();  // weights sum to 1: c moves by shift
      term.set_lagged(0, 0.7, c_rest, 0.004);
      Eigen::VectorXd g, g_fd;
      Eigen::MatrixXd H, H_fd;
      const double e = term.piece(0, s, &g, &H);
      ASSERT_TRUE(std::isfinite(e));
      const double d = term.centre(0, s).z() + 0.0004 - 0.004;
      ASSERT_GT(d, 0.0);
      ASSERT_LT(d, 1e-3);
      morphfem::testing::piece_finite_differences(term, 0, s, 1e-3 * std::min(eps, d), g_fd, H_fd);
      EXPECT_LT((g - g_fd).norm(), 1e-6 * g.norm()) << "order " << order << " slip/eps " << slip_over_eps;
      EXPECT_LT((H - H_fd).norm(), 1e-5 * H.norm()) << "order " << order << " slip/eps " << slip_over_eps;
    }
  }
}

// Exact CCD: a full step into the floor is cut to close exactly max_step_fraction
// of the gap; a step away is not cut. Then the growing radius: it stops catch_up
// dhat from the floor at the step's start, never shrinks below the last radius while
// growing, and shrinks at once.
TEST(LatticeFloor, MaxStepIsExactAndAGrowingRadiusCatchesUp) {
  const Mesh mesh = block(1);
  const Partition part = one_rank(mesh);
  // Centre at z = 0.005; radius 0.004 + 0.01 t; floor at z = 0 (gap 1 mm at t = 0).
  auto term = std::make_shared<LatticeFloorTerm>(mesh, part, 0, floor_at(0.0),
                                                 std::vector<LatticePoint>{whole_block_point(mesh, 0.004, 0.01)});
  Assembler assembler(mesh, part, PETSC_COMM_SELF);
  assembler.add_term(term);
  assembler.setup();
  Vec u = assembler.create_vector(), du = assembler.create_vector();
  VecSet(u, 0.0);
  RowMatrixXd down = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  down.col(2).setConstant(-0.002);  // 2 mm down: twice the gap
  assembler.scatter_all(down, du);
  const double s = term->spec().max_step_fraction;
  EXPECT_NEAR(term->max_step(assembler, u, du), s * 0.001 / 0.002, 1e-12);
  VecScale(du, -1.0);
  EXPECT_EQ(term->max_step(assembler, u, du), 1.0);

  const double dhat = term->spec().dhat, catch_up = term->spec().catch_up;
  term->begin_step(assembler, u, 0.0, 0.05);  // r(t1) = 0.0045 < 0.005 - catch_up dhat = 0.0045: not limited
  EXPECT_NEAR(term->step_radius(0), 0.0045, 1e-15);
  term->begin_step(assembler, u, 0.05, 0.1);  // r(t1) = 0.005 would touch the floor: limited
  EXPECT_NEAR(term->step_radius(0), 0.005 - catch_up * dhat, 1e-15);
  VecSet(u, 0.0);
  RowMatrixXd up = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  up.col(2).setConstant(-0.0008);  // the body pressed 0.8 mm closer: keeps the last radius
  assembler.scatter_all(up, u);
  term->begin_step(assembler, u, 0.1, 0.15);
  EXPECT_NEAR(term->step_radius(0), 0.005 - catch_up * dhat, 1e-15);
  EXPECT_GT(term->total_normal_force(assembler, u), 0.0);
  VecSet(u, 0.0);
  term->begin_step(assembler, u, 0.0, 0.01);  // r(t1) = 0.0041: shrinks at once
  EXPECT_NEAR(term->step_radius(0), 0.0041, 1e-15);
  VecDestroy(&u);
  VecDestroy(&du);
}

TEST(LatticeFloor, RejectsASphereThatStartsInTheFloorAndBadSpecs) {
  const Mesh mesh = block(1);
  const Partition part = one_rank(mesh);
  try {
    LatticeFloorTerm term(mesh, part, 0, floor_at(0.002), {whole_block_point(mesh, 0.004)});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("starts 0.001 m inside the floor"), std::string::npos) << e.what();
  }
  LatticeFloorSpec spec = floor_at(-0.01);
  spec.kappa = 0;
  EXPECT_THROW(LatticeFloorTerm(mesh, part, 0, spec, {whole_block_point(mesh, 0.004)}), InputError);
  LatticePoint bad = whole_block_point(mesh, 0.004);
  bad.weights[0] += 0.1;
  EXPECT_THROW(LatticeFloorTerm(mesh, part, 0, floor_at(-0.01), {bad}), InputError);
}

// The voxel study's lattice has 1428 voxels (ROBOT.md: 2 skin layers of 15 x 22,
// eight bladder blocks of 3 x 16 voxels, two deflated voxels thick).
TEST(LatticeFloor, RobotVoxelLatticeHasTheStudysVoxels) {
  ParamSet p("test robot");
  p.set_string("type", "robot_voxel");
  p.set("mesh_size", 0.02);
  p.set("bladder_thickness", 0.004);  // as examples/voxel/*.yaml: two voxels at scale 0.2
  const auto boxes = robot_voxel_lattice(p, 0.01, 0.2);
  EXPECT_EQ(boxes.size(), 1428u);
  int skin = 0;
  for (const auto& b : boxes) {
    EXPECT_NEAR((b.hi - b.lo).x(), 0.01, 1e-12);
    EXPECT_NEAR((b.hi - b.lo).y(), 0.01, 1e-12);
    if (b.region == "skin") {
      ++skin;
      EXPECT_NEAR(b.base_scale.z(), 1.0, 1e-12);
    } else {
      EXPECT_NEAR(b.base_scale.z(), 0.2, 1e-12);
    }
  }
  EXPECT_EQ(skin, 660);
}
