// Ground contact and friction through the real solver (IncrementalSolver, PETSc):
// a block resting under gravity carries its weight; max_step never lets a node
// reach the plane; a block on a slope (tilted gravity or an inclined plane) sticks
// at tan(theta) = 0.9 mu and slides at 1.1 mu / at the VERIFICATION.md case-8
// slope with the acceleration g (sin theta - mu cos theta). The sliding tests use
// a small implicit-Euler inertia term local to this file (the solver's time
// stepping is pseudo-time; steps are fixed here).
#include <gtest/gtest.h>
#include <petscsys.h>

#include <cmath>
#include <random>

#include "contact/friction.h"
#include "contact/ground.h"
#include "contact/self_contact.h"
#include "fem/elastic.h"
#include "fem/loads.h"
#include "fem/material.h"
#include "fem/solver.h"
#include "mesh/geometry.h"

using namespace morphfem;

namespace {

constexpr double kSide = 0.1;      // block edge [m]
constexpr double kDensity = 1000;  // [kg/m^3]
constexpr double kG = 9.8;         // [m/s^2]

Mesh cube(int order, double mesh_size) {
  ParamSet p("contact test block");
  p.set_string("type", "block");
  p.set("lx", kSide);
  p.set("ly", kSide);
  p.set("lz", kSide);
  p.set("mesh_size", mesh_size);
  p.set("order", order);
  return build_geometry(p);
}

// Neo-Hookean with shear modulus mu [Pa] and bulk modulus 10 mu (nu = 0.4516).
std::shared_ptr<const Material> neo_hookean(double mu) {
  ParamSet p("contact test material");
  p.set_string("model", "neo_hookean");
  p.set("mu", mu);
  p.set("kappa", 10 * mu);
  return make_material(p);
}

// Implicit Euler inertia with lumped (row-sum, P1) masses m_a [kg]:
//   E = sum_a m_a / (2 h^2) |u_a - u_a^n - h v_a^n|^2,  v^{n+1} = (u^{n+1} - u^n)/h.
class TestInertia : public EnergyTerm {
 public:
  TestInertia(const Mesh& mesh, const Partition& part, int rank, double density)
      : mass_(mesh.n_nodes(), 0.0),
        velocity_(mesh.n_nodes(), Eigen::Vector3d::Zero()),
        start_(mesh.n_nodes(), Eigen::Vector3d::Zero()) {
    for (int c = 0; c < mesh.n_cells(); ++c) {
      Eigen::Matrix3d J;
      for (int i = 0; i < 3; ++i)
        J.col(i) = (mesh.X.row(mesh.cells(c, i + 1)) - mesh.X.row(mesh.cells(c, 0))).transpose();
      for (int a = 0; a < 4; ++a) mass_[mesh.cells(c, a)] += density * J.determinant() / 24.0;
    }
    for (int a = part.node_begin[rank]; a < part.node_begin[rank + 1]; ++a) nodes_.push_back(a);
  }
  std::string name() const override { return "test_inertia"; }
  int n_pieces() const override { return static_cast<int>(nodes_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override { nodes.assign(1, nodes_[k]); }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override {
    const int a = nodes_[k];
    const double c = mass_[a] / (h_ * h_);
    const Eigen::Vector3d r = s.u.row(0).transpose() - start_[a] - h_ * velocity_[a];
    if (g) *g = c * r;
    if (H) *H = c * Eigen::Matrix3d::Identity();
    return 0.5 * c * r.squaredNorm();
  }
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override {
    h_ = t1 - t0;
    const auto& u = assembler.gather(u0);
    for (int a : nodes_) start_[a] = Eigen::Vector3d::Map(&u[3 * assembler.node_slot(a)]);
  }
  void end_step(Assembler& assembler, Vec u1, double) override {
    const auto& u = assembler.gather(u1);
    for (int a : nodes_) velocity_[a] = (Eigen::Vector3d::Map(&u[3 * assembler.node_slot(a)]) - start_[a]) / h_;
  }

 private:
  std::vector<double> mass_;
  std::vector<Eigen::Vector3d> velocity_, start_;
  std::vector<int> nodes_;
  double h_ = 1.0;
};

// A cube (optionally rotated by theta about y so that its zmin face lies on an
// inclined plane), elastic, under gravity, on a ground plane with friction.
struct BlockScene {
  Mesh mesh;
  Partition part;
  std::unique_ptr<Assembler> assembler;
  std::shared_ptr<GroundContactTerm> ground;
  std::shared_ptr<FrictionTerm> friction;
  double weight = 0;       // [N]
  double initial_gap = 0;  // [m]
  Eigen::Vector3d downhill{1, 0, 0};

  // slope: tan(theta); inclined_plane: rotate the block and the plane (gravity
  // vertical) instead of tilting gravity. mu < 0: no friction.
  BlockScene(int order, double mesh_size, double slope, bool inclined_plane, double mu, bool inertia, double eps_v,
             double dhat, double shear_modulus = 1e5) {
    mesh = cube(order, mesh_size);
    part = partition_mesh(mesh, 1);
    const double theta = std::atan(slope);
    Eigen::Vector3d gravity(kG * std::sin(theta), 0, -kG * std::cos(theta));
    Eigen::Vector3d normal(0, 0, 1);
    if (inclined_plane) {
      Eigen::Matrix3d R;  // rotation about y by theta: e_z -> n, e_x -> downhill
      R << std::cos(theta), 0, std::sin(theta), 0, 1, 0, -std::sin(theta), 0, std::cos(theta);
      mesh.X = (mesh.X * R.transpose()).eval();
      gravity = Eigen::Vector3d(0, 0, -kG);
      normal = R.col(2);
      downhill = R.col(0);
    }
    weight = kDensity * kG * std::pow(kSide, 3);
    assembler = std::make_unique<Assembler>(mesh, part, PETSC_COMM_WORLD);
    std::vector<std::shared_ptr<const Material>> materials(mesh.regions.size());
    materials[mesh.region("body", 3).id] = neo_hookean(shear_modulus);
    assembler->add_term(std::make_shared<ElasticTerm>(mesh, part, 0, materials));
    std::vector<int> cells(mesh.n_cells());
    for (int c = 0; c < mesh.n_cells(); ++c) cells[c] = c;
    const Eigen::Vector3d body = kDensity * gravity;
    assembler->add_term(std::make_shared<BodyForceTerm>(
        mesh, part, 0, cells, [body](const Eigen::Vector3d&, double) { return body; }, 2 * order));
    GroundContactSpec gs;
    gs.surfaces = {"zmin"};
    gs.normal = normal;
    gs.dhat = dhat;
    gs.young_modulus = 2 * shear_modulus * (1 + 0.4516);  // E = 2 mu (1 + nu) [Pa]
    // Start at the gap that carries the weight's normal pressure (no launch, no drop).
    const double pressure = kDensity * kG * kSide * std::cos(theta);
    gs.point = -dhat * normal;
    initial_gap = GroundContactTerm(mesh, part, 0, gs).resting_gap(pressure);
    gs.point = -initial_gap * normal;
    ground = std::make_shared<GroundContactTerm>(mesh, part, 0, gs);
    assembler->add_term(ground);
    if (mu >= 0) {
      FrictionSpec fs;
      fs.regions = {{"zmin", TimeFunction::constant(mu), TimeFunction::constant(mu)}};
      fs.eps_v = eps_v;
      fs.lag_updates = 4;
      friction = std::make_shared<FrictionTerm>(mesh, part, 0, ground, fs);
      assembler->add_term(friction);
    }
    if (inertia) assembler->add_term(std::make_shared<TestInertia>(mesh, part, 0, kDensity));
  }

  // Mean displacement along `direction` [m] of all nodes, or of a surface's nodes.
  double mean_displacement(Vec u, const Eigen::Vector3d& direction, const std::string& surface = "") const {
    const RowMatrixXd field = assembler->gather_all(u);
    if (surface.empty()) return (field * direction).mean();
    double sum = 0;
    const auto nodes = mesh.nodes_of_surface(surface);
    for (int a : nodes) sum += field.row(a).dot(direction);
    return sum / nodes.size();
  }
};

SolverOptions fixed_steps(double t_end, double dt) {
  SolverOptions opt;
  opt.t_end = t_end;
  opt.dt_initial = dt;
  opt.dt_max = dt;
  opt.grow = 1.0;
  opt.max_newton_its = 50;
  return opt;
}

}  // namespace

// Frictionless block on flat ground, x and y held by symmetry planes (which carry
// no vertical force): the contact forces add up to the weight.
TEST(ContactSolver, RestingBlockCarriesItsWeight) {
  for (int order : {1, 2}) {
    BlockScene scene(order, 0.05, 0.0, false, -1.0, false, 0.0, 1e-4);
    std::vector<DirichletCondition> bcs(2);
    bcs[0] = {"xmin", scene.mesh.nodes_of_surface("xmin"), {true, false, false}, [](const Eigen::Vector3d&, double) {
                return Eigen::Vector3d::Zero();
              }};
    bcs[1] = {"ymin", scene.mesh.nodes_of_surface("ymin"), {false, true, false}, [](const Eigen::Vector3d&, double) {
                return Eigen::Vector3d::Zero();
              }};
    IncrementalSolver solver(*scene.assembler, bcs, fixed_steps(1.0, 1.0));
    const RunStats stats = solver.run();
    ASSERT_TRUE(stats.completed) << stats.failure;
    const Eigen::Vector3d force = scene.ground->total_force(*scene.assembler, solver.solution());
    EXPECT_NEAR(force.z(), scene.weight, 1e-6 * scene.weight) << "order " << order;
    EXPECT_NEAR(force.head<2>().norm(), 0.0, 1e-12);
    const double gap = scene.ground->min_gap(*scene.assembler, solver.solution());
    EXPECT_GT(gap, 0.0);
    EXPECT_LT(gap, scene.ground->dhat());
    const auto nodal = scene.ground->nodal_contact(*scene.assembler, solver.solution());
    int in_contact = 0;
    const auto bottom = scene.mesh.nodes_of_surface("zmin");
    for (int a : bottom) in_contact += nodal.status[a];
    EXPECT_GT(in_contact, 0.5 * bottom.size()) << "order " << order;
    for (int a : scene.mesh.nodes_of_surface("zmax")) EXPECT_EQ(nodal.status[a], 0) << "node " << a;
  }
}

// Random states near the plane and random (large) steps: u + alpha du keeps every
// gap above (1 - s) of its value, s = max_step_fraction, and alpha is the largest
// such fraction (one node lands exactly on the bound when alpha < 1).
TEST(ContactSolver, MaxStepNeverAllowsPenetration) {
  BlockScene scene(1, 0.05, 0.0, false, -1.0, false, 0.0, 1e-3);
  Assembler& assembler = *scene.assembler;
  assembler.setup();
  Vec u = assembler.create_vector(), du = assembler.create_vector(), w = assembler.create_vector();  // w = u + alpha du
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int n = scene.mesh.n_nodes();
  const double s = scene.ground->spec().max_step_fraction;
  int limited = 0;
  for (int trial = 0; trial < 200; ++trial) {
    RowMatrixXd field(n, 3), step(n, 3);
    for (int a = 0; a < n; ++a) {
      field.row(a) = Eigen::RowVector3d(unit(rng), unit(rng), 0.45 * unit(rng)) * 1e-3;  // gaps stay > 0.05 mm
      step.row(a) = Eigen::RowVector3d(unit(rng), unit(rng), unit(rng)) * std::pow(10.0, -4 + 3 * (unit(rng) + 1));
    }
    assembler.scatter_all(field, u);
    assembler.scatter_all(step, du);
    const double alpha = scene.ground->max_step(assembler, u, du);
    ASSERT_GT(alpha, 0.0);
    ASSERT_LE(alpha, 1.0);
    VecWAXPY(w, alpha, du, u);
    double worst = std::numeric_limits<double>::infinity();  // min over nodes of gap_new / gap_old
    for (int a : scene.ground->contact_nodes()) {
      const Eigen::Vector3d X = scene.mesh.X.row(a).transpose();
      const double g0 = scene.ground->gap(X + field.row(a).transpose());
      const double g1 = scene.ground->gap(X + (field.row(a) + alpha * step.row(a)).transpose());
      ASSERT_GT(g1, 0.0) << "trial " << trial << " node " << a;
      worst = std::min(worst, g1 / g0);
    }
    EXPECT_GE(worst, 1 - s - 1e-9);
    if (alpha < 1) {
      ++limited;
      EXPECT_NEAR(worst, 1 - s, 1e-9);
    }
  }
  EXPECT_GT(limited, 50);
  VecDestroy(&u);
  VecDestroy(&du);
  VecDestroy(&w);
}

// Quasi-static block on a slope tan(theta) = 0.9 mu (tilted gravity): it sticks;
// the creep over 1 s of pseudo-time is about 0.68 eps_v x 1 s.
TEST(ContactSolver, QuasiStaticBlockSticksBelowTheFrictionLimit) {
  const double mu = 0.5, eps_v = 1e-5;
  BlockScene scene(1, 0.05, 0.9 * mu, false, mu, false, eps_v, 1e-4);
  IncrementalSolver solver(*scene.assembler, {}, fixed_steps(1.0, 0.1));
  double creep_start = 0;
  const RunStats stats = solver.run([&](const StepReport& r) {
    if (r.step == 1) creep_start = scene.mean_displacement(solver.solution(), scene.downhill);
  });
  ASSERT_TRUE(stats.completed) << stats.failure;
  const double creep = scene.mean_displacement(solver.solution(), scene.downhill) - creep_start;
  EXPECT_GT(creep, 0.0);
  EXPECT_LT(creep, 2 * eps_v);     // creep speed below eps_v
  EXPECT_LT(creep, 1e-3 * kSide);  // issue 4: below 0.1 % of the block size over 1 s
  const Eigen::Vector3d normal_force = scene.ground->total_force(*scene.assembler, solver.solution());
  const auto fr = scene.friction->nodal_friction(*scene.assembler, solver.solution());
  const Eigen::Vector3d friction_force = fr.force.colwise().sum().transpose();
  const double theta = std::atan(0.9 * mu);
  EXPECT_NEAR(normal_force.z(), scene.weight * std::cos(theta), 1e-6 * scene.weight);
  EXPECT_NEAR(friction_force.x(), -scene.weight * std::sin(theta), 1e-6 * scene.weight);
  for (int a : scene.mesh.nodes_of_surface("zmin")) EXPECT_NE(fr.status[a], 2) << "node " << a;  // none slips
}

// Dynamic block on a slope, both ways of modelling the slope (tilted gravity, an
// inclined plane): at tan(theta) = 0.9 mu it sticks (slip of the bottom face over
// 1 s below 0.1 % of the block size), at 1.1 mu it slides, and at the
// VERIFICATION.md case-8 slope atan(0.5) with mu = 0.49 it slides with
// a = g (sin theta - mu cos theta) = 0.087654 m/s^2. Implicit Euler from rest with
// a constant acceleration gives s_N = a h^2 N (N + 1) / 2 exactly, which the test
// compares with (s(2.5 s) = 0.27392 m continuous, +h/t = 2 % for implicit Euler).
// A stiff block (mu = 10 MPa) keeps the elastic start-up transient (the block
// shears while gravity switches on, its base sticks briefly) below 0.5 %.
TEST(ContactSolver, DynamicBlockOnASlopeSticksOrSlidesAsCoulombPredicts) {
  const double h = 0.05, stiff = 1e7;
  for (bool inclined : {false, true}) {
    {
      const double mu = 0.5;
      BlockScene scene(1, 0.05, 0.9 * mu, inclined, mu, true, 1e-5, 1e-4, stiff);
      IncrementalSolver solver(*scene.assembler, {}, fixed_steps(1.0, h));
      const RunStats stats = solver.run();
      ASSERT_TRUE(stats.completed) << stats.failure;
      const double slip = scene.mean_displacement(solver.solution(), scene.downhill, "zmin");
      EXPECT_LT(std::abs(slip), 1e-3 * kSide) << "inclined " << inclined;
      EXPECT_LT(std::abs(slip), 1e-5) << "inclined " << inclined;  // creep ~0.68 eps_v x 1 s
    }
    for (auto [slope, mu] : {std::pair{1.1 * 0.5, 0.5}, std::pair{0.5, 0.49}}) {
      const double t_end = 2.5;
      BlockScene scene(1, 0.05, slope, inclined, mu, true, 1e-4, 1e-4, stiff);
      IncrementalSolver solver(*scene.assembler, {}, fixed_steps(t_end, h));
      std::vector<double> x;  // mean displacement downhill after each step
      const RunStats stats = solver.run(
          [&](const StepReport&) { x.push_back(scene.mean_displacement(solver.solution(), scene.downhill)); });
      ASSERT_TRUE(stats.completed) << stats.failure;
      const double theta = std::atan(slope);
      const double a = kG * (std::sin(theta) - mu * std::cos(theta));
      const size_t n = x.size();
      ASSERT_EQ(n, 50u);
      const double expected = a * h * h * n * (n + 1) / 2;
      EXPECT_NEAR(x.back(), expected, 0.005 * expected) << "inclined " << inclined << " slope " << slope;
      const double a_late = (x[n - 1] - 2 * x[n - 2] + x[n - 3]) / (h * h);
      EXPECT_NEAR(a_late, a, 1e-3 * a) << "inclined " << inclined << " slope " << slope;
      if (slope == 0.5) {
        EXPECT_NEAR(0.5 * a * t_end * t_end, 0.27392, 1e-5);
      }
      RecordProperty("slide_m_slope" + std::to_string(slope) + "_inclined" + std::to_string(inclined),
                     std::to_string(x.back()));
    }
  }
}

// Self-contact between the two faces of a thin plate: random states and random
// large steps; the conservative CCD bound keeps every candidate pair's distance
// above (1 - s) of its start value and every node inside the trust region.
TEST(ContactSolver, SelfContactMaxStepNeverAllowsPenetration) {
  ParamSet p("plate");
  p.set_string("type", "block");
  p.set("lx", 0.04);
  p.set("ly", 0.04);
  p.set("lz", 0.004);
  p.set("mesh_size", 0.02);
  Mesh mesh = build_geometry(p);
  Partition part = partition_mesh(mesh, 1);
  SelfContactSpec spec;
  spec.pairs = {{"zmin", "zmax"}};
  spec.dhat = 1e-3;
  spec.kappa = 1e6;
  spec.inflation = 0.006;
  auto term = std::make_shared<SelfContactTerm>(mesh, part, 0, spec);
  Assembler assembler(mesh, part, PETSC_COMM_WORLD);
  assembler.add_term(term);
  assembler.setup();
  Vec u = assembler.create_vector(), du = assembler.create_vector(), w = assembler.create_vector();
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int n = mesh.n_nodes();
  int limited = 0;
  for (int trial = 0; trial < 100; ++trial) {
    RowMatrixXd field(n, 3), step(n, 3);
    for (int a = 0; a < n; ++a) {
      field.row(a) = Eigen::RowVector3d(unit(rng), unit(rng), unit(rng)) * 4e-4;
      step.row(a) = Eigen::RowVector3d(unit(rng), unit(rng), unit(rng)) * std::pow(10.0, -4 + 2 * (unit(rng) + 1));
    }
    assembler.scatter_all(field, u);
    assembler.scatter_all(step, du);
    const double d0 = term->min_distance(assembler, u);
    ASSERT_GT(d0, 0.0);
    const double alpha = term->max_step(assembler, u, du);
    ASSERT_GT(alpha, 0.0);
    VecWAXPY(w, alpha, du, u);
    EXPECT_GE(term->min_distance(assembler, w), (1 - spec.max_step_fraction) * d0 * (1 - 1e-9));
    EXPECT_TRUE(std::isfinite(assembler.energy(w))) << "trial " << trial;
    limited += alpha < 1;
  }
  EXPECT_GT(limited, 20);
  VecDestroy(&u);
  VecDestroy(&du);
  VecDestroy(&w);
}
