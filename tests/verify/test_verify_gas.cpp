// Gas-filled and volume-controlled cavities with PETSc: the assembled Newton
// operator (sparse Hessian + dense rank-1 vector) against finite differences of the
// assembled gradient, volume control hitting V*, quick coarse versions of the
// verification cases (verify/verify_gas.h), and graceful failure of pressure control
// past the balloon's pressure maximum.
#include <gtest/gtest.h>
#include <petscvec.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "actuation/gas_cavity.h"
#include "core/params.h"
#include "fem/elastic.h"
#include "fem/material.h"
#include "fem/solver.h"
#include "mesh/geometry.h"
#include "mesh/partition.h"
#include "verify/verify_gas.h"

using namespace morphfem;

namespace {

struct Shell {
  Mesh mesh;
  Partition partition;
  std::shared_ptr<ElasticTerm> elastic;
  std::vector<DirichletCondition> bcs;
  std::vector<int> constrained;
};

// Octant shell A = 10 mm, B = 15 mm (P1 or P2), neo-Hookean mu = 100 kPa, with
// symmetry conditions; the Assembler is made by the caller (it keeps references).
std::unique_ptr<Shell> make_shell(int order, double h) {
  auto s = std::make_unique<Shell>();
  ParamSet p("test");
  p.set_string("type", "spherical_shell");
  p.set("inner_radius", 0.01);
  p.set("outer_radius", 0.015);
  p.set("mesh_size", h);
  p.set("order", double(order));
  s->mesh = build_geometry(p);
  s->partition = partition_mesh(s->mesh, 1);
  ParamSet m("test");
  m.set_string("model", "neo_hookean");
  m.set("mu", 1e5);
  m.set("kappa", 1e7);
  std::vector<std::shared_ptr<const Material>> materials(s->mesh.regions.size());
  materials[s->mesh.region("body", 3).id] = make_material(m);
  s->elastic = std::make_shared<ElasticTerm>(s->mesh, s->partition, 0, materials);
  int axis = 0;
  for (const char* surface : {"sym_x", "sym_y", "sym_z"}) {
    DirichletCondition bc;
    bc.name = surface;
    bc.nodes = s->mesh.nodes_of_surface(surface);
    bc.components = {axis == 0, axis == 1, axis == 2};
    bc.value = [](const Eigen::Vector3d&, double) { return Eigen::Vector3d::Zero().eval(); };
    for (int n : bc.nodes) s->constrained.push_back(3 * n + axis);
    s->bcs.push_back(bc);
    ++axis;
  }
  return s;
}

// Sets v to a random vector (zero on constrained dofs), scaled by `scale`.
void random_vector(Assembler& assembler, const std::vector<int>& constrained, Vec v, double scale, unsigned seed) {
  RowMatrixXd field(assembler.mesh().n_nodes(), 3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  for (int n = 0; n < field.rows(); ++n)
    for (int i = 0; i < 3; ++i) field(n, i) = scale * d(rng);
  for (int dof : constrained) field(dof / 3, dof % 3) = 0;
  assembler.scatter_all(field, v);
}

}  // namespace

// (H + sum c v v^T) d against (g(u + e d) - g(u - e d)) / 2e, the assembled
// gradient of elasticity + gas cavity (in a valve step) + volume control.
TEST(GasCavityAssembled, NewtonOperatorMatchesFiniteDifferenceOfGradient) {
  for (int order : {1, 2}) {
    auto shell = make_shell(order, 0.01);
    Assembler assembler(shell->mesh, shell->partition, PETSC_COMM_WORLD);
    assembler.add_term(shell->elastic);
    GasCavitySpec gas;
    gas.wall = {"core", {"inner"}, {true, true, true}, 8.0};
    gas.initial_gauge_pressure = 20e3;
    gas.supply_gauge_pressure = TimeFunction::constant(50e3);
    gas.conductance = TimeFunction::constant(1e-9);
    auto gas_term = std::make_shared<GasCavityTerm>(shell->mesh, shell->partition, 0, gas);
    gas_term->begin_valve_step(0.0, 0.2);
    VolumeControlSpec vc;
    vc.wall = gas.wall;
    vc.volume = TimeFunction::constant(1.2 * gas_term->reference_volume());
    vc.penalty_modulus = 1e5;
    auto control = std::make_shared<VolumeControlledCavityTerm>(shell->mesh, shell->partition, 0, vc);
    control->set_multiplier(5e3, 2e5 / control->reference_volume());
    assembler.add_term(gas_term);
    assembler.add_term(control);
    assembler.set_constrained(shell->constrained);
    assembler.setup();
    Vec u = assembler.create_vector(), d = assembler.create_vector(), w = assembler.create_vector();
    Vec gp = assembler.create_vector(), gm = assembler.create_vector(), y = assembler.create_vector();
    random_vector(assembler, shell->constrained, u, 4e-4, 1);
    random_vector(assembler, shell->constrained, d, 1.0, 2);
    Mat H = assembler.create_matrix();
    assembler.hessian(u, H);
    std::vector<EnergyTerm::LowRank> low_rank;
    for (const auto& term : assembler.terms()) term->low_rank(assembler, u, low_rank);
    ASSERT_EQ(low_rank.size(), 2u);
    MatMult(H, d, y);
    for (auto& lr : low_rank) {
      PetscScalar dot;
      VecDot(lr.v, d, &dot);
      VecAXPY(y, lr.c * dot, lr.v);
    }
    const double eps = 1e-8;
    VecWAXPY(w, eps, d, u);
    assembler.gradient(w, gp);
    VecWAXPY(w, -eps, d, u);
    assembler.gradient(w, gm);
    VecAXPY(gp, -1.0, gm);
    VecScale(gp, 1.0 / (2 * eps));
    PetscReal ynorm, diff;
    VecNorm(y, NORM_2, &ynorm);
    VecAXPY(gp, -1.0, y);
    VecNorm(gp, NORM_2, &diff);
    EXPECT_LT(diff, 1e-6 * ynorm) << "order " << order;
    // Without the rank-1 parts the operator is wrong: the test sees them.
    PetscReal lr_norm = 0;
    VecNorm(low_rank[0].v, NORM_2, &lr_norm);
    EXPECT_GT(lr_norm, 0);
    for (auto& lr : low_rank) VecDestroy(&lr.v);
    for (Vec* v : {&u, &d, &w, &gp, &gm, &y}) VecDestroy(v);
    MatDestroy(&H);
  }
}

// Volume control: V* = 1.5 V_ref reached to the tolerance, with the pressure from
// the multiplier; a sealed gas cavity then holds that state at the same pressure.
TEST(GasCavityAssembled, VolumeControlHitsTargetAndGasHoldsIt) {
  auto shell = make_shell(1, 0.006);
  Assembler assembler(shell->mesh, shell->partition, PETSC_COMM_WORLD);
  assembler.add_term(shell->elastic);
  VolumeControlSpec vc;
  vc.wall = {"core", {"inner"}, {true, true, true}, 8.0};
  GasCavitySpec probe_spec;
  probe_spec.wall = vc.wall;
  const double V_ref = GasCavityTerm(shell->mesh, shell->partition, 0, probe_spec).reference_volume();
  vc.volume = TimeFunction({{0.0, V_ref}, {1.0, 1.5 * V_ref}});
  vc.penalty_modulus = 10 * (4.0 / 3.0) * 1e5 * (1 - std::pow(10.0 / 15.0, 3));
  vc.tolerance = 1e-7;
  auto control = std::make_shared<VolumeControlledCavityTerm>(shell->mesh, shell->partition, 0, vc);
  assembler.add_term(control);
  SolverOptions opt;
  opt.dt_initial = opt.dt_max = 0.25;
  IncrementalSolver solver(assembler, shell->bcs, opt);
  const RunStats stats = solver.run();
  ASSERT_TRUE(stats.completed) << stats.failure;
  EXPECT_NEAR(control->cavity_volume(), 1.5 * V_ref, 1e-7 * 1.5 * V_ref);
  EXPECT_NEAR(8 * control->volume(assembler, solver.solution()), 1.5 * V_ref, 1e-7 * 1.5 * V_ref);
  EXPECT_GT(control->pressure(), 0);
  EXPECT_LE(control->outer_updates(), 4 * stats.steps);
  // A sealed gas cavity with the amount that gives this pressure at this volume:
  // the state is an equilibrium (the first Newton residual is already tiny).
  GasCavitySpec gas = probe_spec;
  const double p_abs = control->pressure() + gas.atmospheric_pressure;
  gas.initial_amount = p_abs * 1.5 * V_ref / (kGasConstant * gas.temperature);
  auto gas_term = std::make_shared<GasCavityTerm>(shell->mesh, shell->partition, 0, gas);
  Assembler with_gas(shell->mesh, shell->partition, PETSC_COMM_WORLD);
  with_gas.add_term(shell->elastic);
  with_gas.add_term(gas_term);
  with_gas.set_constrained(shell->constrained);
  with_gas.setup();
  Vec g = with_gas.create_vector(), g_free = with_gas.create_vector();
  with_gas.gradient(solver.solution(), g);
  PetscReal norm, scale;
  VecNorm(g, NORM_2, &norm);
  // Scale: the elastic force alone at this state.
  Assembler elastic_only(shell->mesh, shell->partition, PETSC_COMM_WORLD);
  elastic_only.add_term(shell->elastic);
  elastic_only.set_constrained(shell->constrained);
  elastic_only.setup();
  elastic_only.gradient(solver.solution(), g_free);
  VecNorm(g_free, NORM_2, &scale);
  EXPECT_LT(norm, 1e-5 * scale);
  VecDestroy(&g);
  VecDestroy(&g_free);
}

// Quick coarse versions of the verification cases.
namespace {
VerifyOptions quick_options() {
  VerifyOptions opt;
  opt.quick = true;
  opt.progress = false;
  return opt;
}
const VerificationRecord* find(const std::vector<VerificationRecord>& records, const std::string& quantity) {
  for (const auto& r : records)
    if (r.quantity.find(quantity) != std::string::npos) return &r;
  return nullptr;
}
}  // namespace

TEST(VerifyGas, QuickThickSphereTracesThroughTheMaximum) {
  std::vector<VerificationRecord> out;
  gas_thick_sphere_case(quick_options(), PETSC_COMM_WORLD, out);
  ASSERT_FALSE(out.empty());
  ASSERT_EQ(out.size(), 5u);
  for (const auto& r : out) EXPECT_LT(r.rel_error, 0.01) << r.json();
  ASSERT_NE(find(out, "la=1.8"), nullptr);
  ASSERT_NE(find(out, "la=3"), nullptr);
}

TEST(VerifyGas, QuickBalloonMaximumAndPassed) {
  std::vector<VerificationRecord> out;
  gas_balloon_case(quick_options(), PETSC_COMM_WORLD, out);
  const auto* max = find(out, "maximum P");
  ASSERT_NE(max, nullptr);
  EXPECT_LT(max->rel_error, 0.02) << max->json();
  const auto* at2 = find(out, "l=2.0");
  ASSERT_NE(at2, nullptr);
  EXPECT_LT(at2->rel_error, 0.03) << at2->json();
  EXPECT_LT(at2->value, max->value);  // passed the maximum: the pressure fell
}

TEST(VerifyGas, PressureControlPastTheMaximumFailsGracefully) {
  const auto r = run_pressure_controlled_balloon(true, PETSC_COMM_WORLD);
  EXPECT_FALSE(r.stats.completed);
  EXPECT_NE(r.stats.failure.find("step "), std::string::npos) << r.stats.failure;
  EXPECT_NE(r.stats.failure.find("t = "), std::string::npos) << r.stats.failure;
  EXPECT_NE(r.stats.failure.find("Newton"), std::string::npos) << r.stats.failure;
  EXPECT_TRUE(r.state_finite);
  // The last converged state is just below the limit point (not a reset state).
  EXPECT_GT(r.last_pressure, 0.9 * r.max_pressure_exact);
  EXPECT_LT(r.last_pressure, 1.03 * r.max_pressure_exact);
  EXPECT_GT(r.last_volume_ratio, 1.5);
}

TEST(VerifyGas, QuickValveFillTimesScale) {
  std::vector<VerificationRecord> out;
  gas_valve_case(quick_options(), PETSC_COMM_WORLD, out);
  ASSERT_EQ(out.size(), 4u);
  for (const auto& r : out) EXPECT_LT(r.rel_error, 0.02) << r.json();
  EXPECT_NEAR(out[0].value / out[1].value, 2.0, 0.02);  // doubling C halves the fill time
  EXPECT_NEAR(out[0].value / out[2].value, std::log(5.0 / 4.0) / std::log(10.0 / 9.0), 0.02);
}
