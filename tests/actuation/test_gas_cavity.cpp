// Gas-filled and volume-controlled cavities without PETSc: the energy, gradient and
// full Hessian (sparse face parts plus the dense rank-1 part c v v^T) of the whole
// term against finite differences at random states (P1 and P2 octant shells), the
// implicit valve step, and the valve's fill-time scaling for a rigid cavity.
// (Assembled-vector paths, volume control hitting V* and the FE fill test need
// PETSc: tests/verify/test_verify_gas.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "actuation/gas_cavity.h"
#include "core/params.h"
#include "mesh/geometry.h"
#include "mesh/partition.h"

using namespace morphfem;

namespace {

Mesh octant_shell(int order, double A, double B, double h) {
  ParamSet p("test");
  p.set_string("type", "spherical_shell");
  p.set("inner_radius", A);
  p.set("outer_radius", B);
  p.set("mesh_size", h);
  p.set("order", double(order));
  return build_geometry(p);
}

// Whole-term energy, dense gradient and Hessian at displacement u (n_nodes x 3),
// assembled the way Assembler + IncrementalSolver do on one process.
double term_energy(CavityVolumeTerm& term, const Mesh& mesh, const RowMatrixXd& u, Eigen::VectorXd* g,
                   Eigen::MatrixXd* H) {
  term.set_cavity_volume(term.wall().symmetry_factor * term.local_model_volume(u));
  const int n = 3 * mesh.n_nodes();
  if (g) g->setZero(n);
  if (H) H->setZero(n, n);
  double e = 0;
  std::vector<int> nodes;
  PieceState s;
  Eigen::VectorXd gk;
  Eigen::MatrixXd Hk;
  for (int k = 0; k < term.n_pieces(); ++k) {
    term.piece_nodes(k, nodes);
    const int m = static_cast<int>(nodes.size());
    s.X.resize(m, 3);
    s.u.resize(m, 3);
    for (int a = 0; a < m; ++a) {
      s.X.row(a) = mesh.X.row(nodes[a]);
      s.u.row(a) = u.row(nodes[a]);
    }
    e += term.piece(k, s, g ? &gk : nullptr, H ? &Hk : nullptr);
    for (int a = 0; a < m; ++a)
      for (int i = 0; i < 3; ++i) {
        if (g) (*g)[3 * nodes[a] + i] += gk[3 * a + i];
        if (H)
          for (int b = 0; b < m; ++b)
            for (int j = 0; j < 3; ++j) (*H)(3 * nodes[a] + i, 3 * nodes[b] + j) += Hk(3 * a + i, 3 * b + j);
      }
  }
  if (H) {
    const Eigen::VectorXd v = term.local_volume_gradient(u);
    *H += term.low_rank_coefficient() * v * v.transpose();
  }
  return e;
}

// Random state: a uniform inflation plus random wall displacements.
RowMatrixXd random_state(const Mesh& mesh, double A, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-1.0, 1.0);
  RowMatrixXd u(mesh.n_nodes(), 3);
  for (int n = 0; n < mesh.n_nodes(); ++n)
    for (int i = 0; i < 3; ++i) u(n, i) = 0.15 * mesh.X(n, i) + 0.03 * A * d(rng);
  return u;
}

void check_derivatives(CavityVolumeTerm& term, const Mesh& mesh, double A, unsigned seed) {
  const RowMatrixXd u = random_state(mesh, A, seed);
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  term_energy(term, mesh, u, &g, &H);
  ASSERT_TRUE(g.allFinite());
  // Dofs of the wall nodes (everything else is zero): check each of a sample.
  std::vector<int> wall_dofs;
  std::vector<int> nodes;
  for (int k = 0; k < term.n_pieces(); ++k) {
    term.piece_nodes(k, nodes);
    for (int n : nodes)
      for (int i = 0; i < 3; ++i) wall_dofs.push_back(3 * n + i);
  }
  std::sort(wall_dofs.begin(), wall_dofs.end());
  wall_dofs.erase(std::unique(wall_dofs.begin(), wall_dofs.end()), wall_dofs.end());
  std::mt19937 rng(seed + 1);
  std::shuffle(wall_dofs.begin(), wall_dofs.end(), rng);
  if (wall_dofs.size() > 24) wall_dofs.resize(24);
  const double eps = 1e-7 * A;
  for (int j : wall_dofs) {
    RowMatrixXd up = u, um = u;
    up(j / 3, j % 3) += eps;
    um(j / 3, j % 3) -= eps;
    Eigen::VectorXd gp, gm;
    const double ep = term_energy(term, mesh, up, &gp, nullptr);
    const double em = term_energy(term, mesh, um, &gm, nullptr);
    EXPECT_NEAR(g[j], (ep - em) / (2 * eps), 1e-6 * g.cwiseAbs().maxCoeff()) << term.name() << " dof " << j;
    const Eigen::VectorXd fd = (gp - gm) / (2 * eps);
    EXPECT_LT((H.col(j) - fd).norm(), 1e-6 * H.col(j).norm() + 1e-9 * H.norm()) << term.name() << " dof " << j;
  }
  EXPECT_LT((H - H.transpose()).norm(), 1e-12 * H.norm());
}

}  // namespace

class GasCavityFD : public ::testing::TestWithParam<int> {};

// Sealed gas, a gas cavity inside a valve step (reservoir V_r > 0), and a
// volume-controlled cavity, on an octant (symmetry_factor 8).
TEST_P(GasCavityFD, EnergyGradientAndFullHessianMatchFiniteDifferences) {
  const int order = GetParam();
  const double A = 0.01, B = 0.015;
  Mesh mesh = octant_shell(order, A, B, A);
  Partition partition = partition_mesh(mesh, 1);
  CavityWallSpec wall{"core", {"inner"}, {true, true, true}, 8.0};

  GasCavitySpec gas;
  gas.wall = wall;
  gas.initial_gauge_pressure = 30e3;
  GasCavityTerm sealed(mesh, partition, 0, gas);
  const double exact = 4.0 / 3.0 * M_PI * A * A * A;
  EXPECT_NEAR(sealed.reference_volume(), exact, (order == 1 ? 0.3 : 0.02) * exact);
  check_derivatives(sealed, mesh, A, 3);

  gas.supply_gauge_pressure = TimeFunction::constant(50e3);
  gas.conductance = TimeFunction::constant(1e-9);
  GasCavityTerm valve(mesh, partition, 0, gas);
  valve.begin_valve_step(0.0, 0.5);
  check_derivatives(valve, mesh, A, 5);

  VolumeControlSpec vc;
  vc.wall = wall;
  vc.volume = TimeFunction::constant(1.3 * 4.0 / 3.0 * M_PI * A * A * A);
  vc.penalty_modulus = 1e6;
  VolumeControlledCavityTerm control(mesh, partition, 0, vc);
  control.set_multiplier(20e3, 3e6 / control.reference_volume());
  check_derivatives(control, mesh, A, 7);
}

INSTANTIATE_TEST_SUITE_P(Orders, GasCavityFD, ::testing::Values(1, 2));

// The gauge pressure the wall sees is -Phi'(V); for the sealed gas it is
// n R T / V - p_atm, and the energy is +inf for V <= 0.
TEST(GasCavity, PressureFollowsBoyleAndDomainIsPositiveVolume) {
  Mesh mesh = octant_shell(1, 0.01, 0.015, 0.01);
  Partition partition = partition_mesh(mesh, 1);
  GasCavitySpec gas;
  gas.wall = {"core", {"inner"}, {true, true, true}, 8.0};
  gas.initial_gauge_pressure = 20e3;
  GasCavityTerm term(mesh, partition, 0, gas);
  const double V0 = term.reference_volume();
  EXPECT_NEAR(term.pressure(), 20e3, 1e-8);
  EXPECT_NEAR(-term.energy_derivative(V0), 20e3, 1e-8);
  // Boyle: doubling the volume halves the absolute pressure.
  EXPECT_NEAR(-term.energy_derivative(2 * V0) + gas.atmospheric_pressure, 0.5 * (101325.0 + 20e3), 1e-8);
  EXPECT_TRUE(std::isinf(term.energy_of_volume(0.0)));
  EXPECT_TRUE(std::isinf(term.energy_of_volume(-V0)));
  EXPECT_THROW(term.set_amount(-1.0), std::invalid_argument);
}

// The implicit step satisfies n1 = n0 + dt C (p_s - n1 R T / V1) exactly.
TEST(GasCavity, ImplicitValveStepSatisfiesBackwardEuler) {
  Mesh mesh = octant_shell(1, 0.01, 0.015, 0.01);
  Partition partition = partition_mesh(mesh, 1);
  GasCavitySpec gas;
  gas.wall = {"core", {"inner"}, {true, true, true}, 8.0};
  gas.supply_gauge_pressure = TimeFunction::constant(50e3);
  gas.conductance = TimeFunction::constant(2e-9);
  GasCavityTerm term(mesh, partition, 0, gas);
  const double n0 = term.amount(), V1 = 1.2 * term.reference_volume(), dt = 0.3;
  const double RT = kGasConstant * gas.temperature;
  term.begin_valve_step(0.0, dt);
  const double p1 = -term.energy_derivative(V1) + gas.atmospheric_pressure;  // absolute
  term.end_valve_step(V1, dt);
  const double n1 = term.amount();
  EXPECT_NEAR(n1, n0 + dt * 2e-9 * (101325.0 + 50e3 - n1 * RT / V1), 1e-12 * n1);
  EXPECT_NEAR(p1, n1 * RT / V1, 1e-9 * p1);
  EXPECT_NEAR(term.absolute_pressure(), p1, 1e-9 * p1);
  EXPECT_NEAR(term.molar_flow_rate(), (n1 - n0) / dt, 1e-12 * n1);
}

namespace {
// Rigid cavity (V fixed at the reference volume) filled through the valve from
// gauge 0: time [s] at which the gauge pressure first reaches `target` [Pa].
double rigid_fill_time(const Mesh& mesh, const Partition& partition, const GasCavitySpec& gas, double target,
                       double dt) {
  const double supply = gas.supply_gauge_pressure(0.0);
  GasCavityTerm term(mesh, partition, 0, gas);
  const double V = term.reference_volume();
  double t = 0, p_prev = term.pressure();
  for (int step = 0; step < 100000; ++step) {
    term.begin_valve_step(t, t + dt);
    term.end_valve_step(V, t + dt);
    const double p = term.pressure();
    if ((p - target) * (supply - target) >= 0 && (p_prev - target) * (supply - target) < 0)
      return t + dt * (target - p_prev) / (p - p_prev);  // linear interpolation in the step
    t += dt;
    p_prev = p;
  }
  return -1;
}

GasCavitySpec rigid_valve(double supply, double C) {
  GasCavitySpec gas;
  gas.wall = {"core", {"inner"}, {true, true, true}, 8.0};
  gas.supply_gauge_pressure = TimeFunction::constant(supply);
  gas.conductance = TimeFunction::constant(C);
  return gas;
}
}  // namespace

// Rigid cavity: p(t) = p_s + (p(0) - p_s) exp(-t/tau), tau = V/(C R T), so the
// time to a gauge target p* from 0 is tau ln(p_s / (p_s - p*)): it halves when C
// doubles and depends on the supply pressure as that formula says.
TEST(GasCavity, RigidFillTimeScalesWithConductanceAndSupply) {
  Mesh mesh = octant_shell(1, 0.01, 0.015, 0.01);
  Partition partition = partition_mesh(mesh, 1);
  GasCavitySpec gas;
  gas.wall = {"core", {"inner"}, {true, true, true}, 8.0};
  GasCavityTerm probe(mesh, partition, 0, gas);
  const double C = 1e-9;  // mol/(s Pa)
  const double tau = probe.time_constant(probe.reference_volume(), C);
  const double dt = tau / 400;
  const double target = 10e3;
  for (double supply : {50e3, 100e3}) {
    const double expected = tau * std::log(supply / (supply - target));
    const double t1 = rigid_fill_time(mesh, partition, rigid_valve(supply, C), target, dt);
    const double t2 = rigid_fill_time(mesh, partition, rigid_valve(supply, 2 * C), target, dt);
    EXPECT_NEAR(t1, expected, 0.01 * expected) << "supply " << supply;
    EXPECT_NEAR(t2, expected / 2, 0.01 * expected / 2) << "supply " << supply;
  }
  // Vacuum: from +50 kPa towards -80 kPa; time to reach 0 gauge is tau ln(130/80).
  const double expected = tau * std::log(130.0 / 80.0);
  GasCavitySpec vac;
  vac.wall = gas.wall;
  vac.initial_gauge_pressure = 50e3;
  vac.supply_gauge_pressure = TimeFunction::constant(-80e3);
  vac.conductance = TimeFunction::constant(C);
  GasCavityTerm term(mesh, partition, 0, vac);
  double t = 0;
  while (term.pressure() > 0) {
    term.begin_valve_step(t, t + dt);
    term.end_valve_step(term.reference_volume(), t + dt);
    t += dt;
  }
  EXPECT_NEAR(t, expected, 0.01 * expected);
  // A sealed cavity keeps its amount.
  GasCavityTerm sealed(mesh, partition, 0, gas);
  const double n = sealed.amount();
  sealed.begin_valve_step(0, 1);
  sealed.end_valve_step(sealed.reference_volume(), 1);
  EXPECT_DOUBLE_EQ(sealed.amount(), n);
}

// A valve given by its fill time tau instead of a conductance: the rigid cavity's
// time constant is tau whatever its volume (octant shells of two sizes), so the
// gauge reaches p* at tau ln(p_s / (p_s - p*)); tau <= 0 is refused.
TEST(GasCavity, FillTimeSetsTheRigidCavitysTimeConstant) {
  const double tau = 0.05, supply = 35e3, target = 20e3;
  const double expected = tau * std::log(supply / (supply - target));
  for (double A : {0.01, 0.02}) {
    Mesh mesh = octant_shell(1, A, 1.5 * A, A);
    Partition partition = partition_mesh(mesh, 1);
    GasCavitySpec gas = rigid_valve(supply, 1.0);  // the fill time overrides this conductance
    gas.fill_time = tau;
    GasCavityTerm term(mesh, partition, 0, gas);
    EXPECT_NEAR(term.time_constant(term.reference_volume(), term.spec().conductance(0.0)), tau, 1e-12 * tau);
    EXPECT_NEAR(rigid_fill_time(mesh, partition, gas, target, tau / 400), expected, 0.01 * expected)
        << "inner radius " << A;
    gas.fill_time = 0.0;
    EXPECT_THROW(GasCavityTerm(mesh, partition, 0, gas), std::invalid_argument);
  }
}
