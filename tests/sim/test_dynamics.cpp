// Implicit dynamics through the real solver (IncrementalSolver + InertiaTerm):
//  - the assembled inertia and damping terms against finite differences, and
//    history that a rejected step attempt leaves untouched;
//  - free flight under gravity: x = x0 + v0 t + g t^2/2 exactly with Newmark and
//    BDF2 (also with growing steps), error g h t/2 (first order) with implicit Euler;
//  - a cantilever swinging from an initial velocity (no damping, no gravity):
//    total energy within 2 % over 100 steps with Newmark; BDF2 and implicit Euler
//    dissipate; Kelvin-Voigt damping dissipates what the energy balance says;
//  - axial vibration of a nu = 0 bar: period against the analytic 4 L / c;
//  - the local truncation error estimate scales as h^3.
// Set MORPHFEM_DYNAMICS_REPORT=1 to print the energy table.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "fem/damping.h"
#include "fem/elastic.h"
#include "fem/inertia.h"
#include "fem/loads.h"
#include "fem/material.h"
#include "fem/solver.h"
#include "mesh/geometry.h"

using namespace morphfem;

namespace {

constexpr double kDensity = 1000.0;  // [kg/m^3]

bool report() { return std::getenv("MORPHFEM_DYNAMICS_REPORT") != nullptr; }

Mesh make_mesh(const std::string& type, double lx, double ly, double lz, double mesh_size, int order) {
  ParamSet p("dynamics test " + type);
  p.set_string("type", type);
  const bool bar = type == "cantilever";
  p.set(bar ? "L" : "lx", lx);
  p.set(bar ? "b" : "ly", ly);
  p.set(bar ? "h" : "lz", lz);
  p.set("mesh_size", mesh_size);
  p.set("order", order);
  p.set("structured", 1);
  return build_geometry(p);
}

// Neo-Hookean, shear modulus mu [Pa], Poisson's ratio nu.
std::shared_ptr<const Material> neo_hookean(double mu, double nu) {
  ParamSet p("dynamics test material");
  p.set_string("model", "neo_hookean");
  p.set("mu", mu);
  p.set("nu", nu);
  return make_material(p);
}

SolverOptions fixed_steps(double t_end, double dt) {
  SolverOptions opt;
  opt.t_end = t_end;
  opt.dt_initial = dt;
  opt.dt_max = dt;
  opt.grow = 1.0;
  return opt;
}

DirichletCondition clamp(const Mesh& mesh, const std::string& surface) {
  return {surface, mesh.nodes_of_surface(surface), {true, true, true}, [](const Eigen::Vector3d&, double) {
            return Eigen::Vector3d::Zero();
          }};
}

// One body (region "body"): elastic + inertia (+ gravity, + damping).
struct Scene {
  Mesh mesh;
  Partition part;
  std::unique_ptr<Assembler> assembler;
  std::shared_ptr<TimeIntegrator> integrator;
  std::shared_ptr<InertiaTerm> inertia;
  std::shared_ptr<DampingTerm> damping;
  int elastic_index = -1, gravity_index = -1;

  Scene(Mesh m, double mu, double nu, InertiaOptions options, const Eigen::Vector3d& gravity, double eta = 0.0)
      : mesh(std::move(m)) {
    part = partition_mesh(mesh, 1);
    assembler = std::make_unique<Assembler>(mesh, part, PETSC_COMM_WORLD);
    std::vector<std::shared_ptr<const Material>> materials(mesh.regions.size());
    const int body = mesh.region("body", 3).id;
    materials[body] = neo_hookean(mu, nu);
    std::vector<double> density(mesh.regions.size(), 0.0);
    density[body] = kDensity;
    integrator = std::make_shared<TimeIntegrator>(options);
    inertia = std::make_shared<InertiaTerm>(mesh, part, 0, density, integrator, options.lumped);
    assembler->add_term(inertia);
    elastic_index = static_cast<int>(assembler->terms().size());
    assembler->add_term(std::make_shared<ElasticTerm>(mesh, part, 0, materials));
    if (gravity.norm() > 0) {
      std::vector<int> cells(mesh.n_cells());
      for (int c = 0; c < mesh.n_cells(); ++c) cells[c] = c;
      const Eigen::Vector3d b = kDensity * gravity;  // [N/m^3]
      gravity_index = static_cast<int>(assembler->terms().size());
      assembler->add_term(std::make_shared<BodyForceTerm>(
          mesh, part, 0, cells, [b](const Eigen::Vector3d&, double) { return b; }, 2 * mesh.order));
    }
    if (eta > 0) {
      std::vector<double> viscosity(mesh.regions.size(), 0.0);
      viscosity[body] = eta;
      damping = std::make_shared<DampingTerm>(mesh, part, 0, viscosity, std::vector<double>{}, integrator);
      assembler->add_term(damping);
    }
  }

  // Kinetic + elastic + gravitational potential energy [J] at the converged state u.
  double total_energy(Vec u) {
    const std::vector<double> e = assembler->term_energies(u);
    double total = inertia->kinetic_energy(*assembler) + e[elastic_index];
    if (gravity_index >= 0) total += e[gravity_index];
    return total;
  }
};

// Largest nodal deviation [m] of u from the field exact(X).
double max_deviation(Assembler& assembler, Vec u, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& exact) {
  const RowMatrixXd field = assembler.gather_all(u);
  double worst = 0.0;
  for (int a = 0; a < assembler.mesh().n_nodes(); ++a)
    worst = std::max(worst, (field.row(a).transpose() - exact(assembler.mesh().X.row(a).transpose())).norm());
  return worst;
}

// Sets the owned entries of u from a function of X.
void set_field(Assembler& assembler, Vec u, const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& f) {
  RowMatrixXd field(assembler.mesh().n_nodes(), 3);
  for (int a = 0; a < assembler.mesh().n_nodes(); ++a)
    field.row(a) = f(assembler.mesh().X.row(a).transpose()).transpose();
  assembler.scatter_all(field, u);
}

const Eigen::Vector3d kGravity(0, 0, -9.81);  // [m/s^2]
const Eigen::Vector3d kV0(0.3, -0.2, 1.0);    // [m/s]

}  // namespace

// The assembled incremental potential (inertia with history + damping + elastic):
// directional derivatives of the energy and of the gradient against the gradient
// and Hessian; a second begin_step with another h and back leaves it unchanged.
TEST(Dynamics, AssembledTermsMatchFiniteDifferencesAndRetriesKeepHistory) {
  for (TimeScheme scheme : {TimeScheme::newmark, TimeScheme::bdf2, TimeScheme::implicit_euler}) {
    InertiaOptions options;
    options.scheme = scheme;
    Scene scene(make_mesh("block", 0.02, 0.02, 0.02, 0.01, 2), 1e5, 0.45, options, kGravity, 300.0);
    Assembler& assembler = *scene.assembler;
    assembler.setup();
    scene.inertia->set_initial_velocity([](const Eigen::Vector3d& X) { return Eigen::Vector3d(X.y(), -X.x(), 0.5); });
    Vec u0 = assembler.create_vector(), u = assembler.create_vector(), d = assembler.create_vector(),
        g = assembler.create_vector(), gp = assembler.create_vector(), gm = assembler.create_vector(),
        w = assembler.create_vector(), Hd = assembler.create_vector();
    set_field(assembler, u0, [](const Eigen::Vector3d& X) { return Eigen::Vector3d(0.1 * X.y(), 0.05 * X.z(), 0.0); });
    // A first step from rest at u = 0 to u0, so that the second step uses the
    // schemes' history (BDF2's two-step formula, the trapezoidal strain rate).
    const double h = 2e-3;
    Vec zero = assembler.create_vector();
    scene.inertia->begin_step(assembler, zero, 0.0, h);
    scene.damping->begin_step(assembler, zero, 0.0, h);
    scene.inertia->end_step(assembler, u0, h);
    scene.damping->end_step(assembler, u0, h);
    VecDestroy(&zero);
    scene.inertia->begin_step(assembler, u0, h, 2.5 * h);
    scene.damping->begin_step(assembler, u0, h, 2.5 * h);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    set_field(assembler, u, [&](const Eigen::Vector3d& X) {
      return Eigen::Vector3d(0.1 * X.y() + 2e-4 * unit(rng), 0.05 * X.z() + 2e-4 * unit(rng), 2e-4 * unit(rng));
    });
    set_field(assembler, d, [&](const Eigen::Vector3d&) { return Eigen::Vector3d(unit(rng), unit(rng), unit(rng)); });
    Mat H = assembler.create_matrix();
    const double e_u = assembler.energy(u);
    assembler.gradient(u, g);
    assembler.hessian(u, H);
    MatMult(H, d, Hd);
    const double eps = 1e-7;
    VecWAXPY(w, eps, d, u);
    const double ep = assembler.gradient(w, gp);
    VecWAXPY(w, -eps, d, u);
    const double em = assembler.gradient(w, gm);
    PetscScalar slope;
    VecDot(g, d, &slope);
    EXPECT_NEAR((ep - em) / (2 * eps), slope, 1e-6 * std::abs(slope));
    VecAXPY(gp, -1.0, gm);
    VecScale(gp, 1.0 / (2 * eps));
    VecAXPY(gp, -1.0, Hd);
    PetscReal diff, ref;
    VecNorm(gp, NORM_2, &diff);
    VecNorm(Hd, NORM_2, &ref);
    EXPECT_LE(diff, 1e-6 * ref);
    // A retried attempt (another h, then the same again) sees the same potential.
    scene.inertia->begin_step(assembler, u0, h, 1.7 * h);
    scene.inertia->begin_step(assembler, u0, h, 2.5 * h);
    EXPECT_EQ(assembler.energy(u), e_u);
    for (Vec* v : {&u0, &u, &d, &g, &gp, &gm, &w, &Hd}) VecDestroy(v);
    MatDestroy(&H);
  }
}

// Free flight: every node follows v0 t + g t^2/2 (no strain). Newmark and BDF2 are
// exact for this quadratic motion (BDF2 also with growing steps and after a short
// step), for consistent
// P1/P2 and lumped P1 masses; implicit Euler is off by exactly g h t/2 (first order).
TEST(Dynamics, FreeFlightUnderGravity) {
  const double t_end = 0.2;
  auto exact = [&](double t) {
    return [t](const Eigen::Vector3d&) -> Eigen::Vector3d { return kV0 * t + 0.5 * kGravity * t * t; };
  };
  struct Case {
    TimeScheme scheme;
    int order;
    bool lumped;
    bool growing;
  };
  for (const Case& c : {Case{TimeScheme::newmark, 1, false, false}, Case{TimeScheme::newmark, 2, false, false},
                        Case{TimeScheme::newmark, 1, true, true}, Case{TimeScheme::bdf2, 1, false, false},
                        Case{TimeScheme::bdf2, 2, false, true}, Case{TimeScheme::bdf2, 1, true, true}}) {
    InertiaOptions options;
    options.scheme = c.scheme;
    options.lumped = c.lumped;
    Scene scene(make_mesh("block", 0.04, 0.02, 0.02, c.order == 1 ? 0.01 : 0.02, c.order), 1e5, 0.45, options,
                kGravity);
    scene.inertia->set_initial_velocity([](const Eigen::Vector3d&) { return kV0; });
    SolverOptions opt = fixed_steps(t_end, 0.02);
    // A short step landing on an output time makes the next one 4 times longer
    // (BDF2 takes it as a trapezoidal step).
    if (!c.growing) opt.output_times = {0.105};
    if (c.growing) {
      opt.dt_initial = 0.005;
      opt.dt_max = 0.05;
      opt.grow = 1.5;
    }
    IncrementalSolver solver(*scene.assembler, {}, opt);
    int steps = 0;
    const RunStats stats = solver.run([&](const StepReport&) { ++steps; });
    ASSERT_TRUE(stats.completed) << stats.failure;
    const std::string what = "scheme " + std::to_string(int(c.scheme)) + " order " + std::to_string(c.order) +
                             (c.lumped ? " lumped" : "") + (c.growing ? " growing steps" : "");
    EXPECT_LE(max_deviation(*scene.assembler, solver.solution(), exact(t_end)), 1e-10) << what;
    Vec v_exact = scene.assembler->create_vector();
    set_field(*scene.assembler, v_exact, [&](const Eigen::Vector3d&) { return kV0 + kGravity * t_end; });
    VecAXPY(v_exact, -1.0, scene.inertia->velocity());
    PetscReal v_error;
    VecNorm(v_exact, NORM_INFINITY, &v_error);
    VecDestroy(&v_exact);
    EXPECT_LE(v_error, 1e-8) << what;
    EXPECT_LE(scene.inertia->last_error(), 1e-12) << what << ": constant acceleration has no truncation error";
    if (c.growing) {
      EXPECT_LT(steps, 10) << what;
    }
  }
  // Implicit Euler: u_n = v0 t + g t^2/2 + g h t/2, halving h halves the error.
  double previous = 0.0;
  for (double dt : {0.02, 0.01}) {
    InertiaOptions options;
    options.scheme = TimeScheme::implicit_euler;
    Scene scene(make_mesh("block", 0.04, 0.02, 0.02, 0.01, 1), 1e5, 0.45, options, kGravity);
    scene.inertia->set_initial_velocity([](const Eigen::Vector3d&) { return kV0; });
    IncrementalSolver solver(*scene.assembler, {}, fixed_steps(t_end, dt));
    ASSERT_TRUE(solver.run().completed);
    const double error = max_deviation(*scene.assembler, solver.solution(), exact(t_end));
    EXPECT_NEAR(error, kGravity.norm() * dt * t_end / 2, 1e-10) << "dt " << dt;
    EXPECT_NEAR(scene.inertia->last_error(), kGravity.norm() * dt * dt / 2, 1e-10);  // h^2/2 |u''|
    if (previous > 0) {
      EXPECT_NEAR(previous / error, 2.0, 1e-6);
    }
    previous = error;
  }
}

namespace {

// Cantilever 10 x 2 x 2 cm (P1), clamped root, released at zero displacement with
// the transverse velocity v_z = V (x/L)^2 (no gravity). Returns the relative change
// of the total energy after `steps` steps of length dt, and the wall time.
struct SwingResult {
  double drift = 0, wall_s = 0, tip_max = 0, dissipated = 0, energy0 = 0, energy_end = 0;
};
SwingResult swing(TimeScheme scheme, double dt, int steps, double eta = 0.0) {
  const double L = 0.1, V = 1.0;  // [m], [m/s]
  InertiaOptions options;
  options.scheme = scheme;
  Scene scene(make_mesh("cantilever", L, 0.02, 0.02, 0.01, 1), 1e5, 0.45, options, Eigen::Vector3d::Zero(), eta);
  scene.inertia->set_initial_velocity(
      [&](const Eigen::Vector3d& X) { return Eigen::Vector3d(0, 0, V * (X.x() / L) * (X.x() / L)); });
  IncrementalSolver solver(*scene.assembler, {clamp(scene.mesh, "root")}, fixed_steps(steps * dt, dt));
  scene.inertia->initialize(*scene.assembler, solver.solution(), 0.0);
  SwingResult r;
  r.energy0 = scene.total_energy(solver.solution());
  const auto tip = scene.mesh.nodes_of_surface("tip");
  const auto start = std::chrono::steady_clock::now();
  const RunStats stats = solver.run([&](const StepReport&) {
    const RowMatrixXd field = scene.assembler->gather_all(solver.solution());
    for (int a : tip) r.tip_max = std::max(r.tip_max, std::abs(field(a, 2)));
  });
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_TRUE(stats.completed) << stats.failure;
  EXPECT_EQ(stats.steps, steps);
  r.energy_end = scene.total_energy(solver.solution());
  r.drift = (r.energy_end - r.energy0) / r.energy0;
  if (scene.damping) r.dissipated = scene.damping->total_dissipated();
  return r;
}

}  // namespace

// With no damping and no friction the second-order Newmark scheme keeps the total
// energy within 2 % over 100 steps of about 1/46 of the first period (T ~ 0.115 s,
// 2.2 periods, tip swinging 1.7 cm = 17 % of the length; measured drift -0.08 %);
// BDF2 (-5 %) and implicit Euler (-86 %) dissipate.
TEST(Dynamics, SwingingCantileverConservesEnergyWithNewmark) {
  const double dt = 2.5e-3;  // [s]
  const SwingResult newmark = swing(TimeScheme::newmark, dt, 100);
  const SwingResult bdf2 = swing(TimeScheme::bdf2, dt, 100);
  const SwingResult euler = swing(TimeScheme::implicit_euler, dt, 100);
  EXPECT_GT(newmark.tip_max, 0.01);
  EXPECT_LT(std::abs(newmark.drift), 0.02);
  EXPECT_LT(bdf2.drift, -0.02);
  EXPECT_LT(euler.drift, 2 * bdf2.drift);
  if (report()) {
    std::printf("scheme          dt [s]    steps  energy drift %%  tip max [m]  wall [s]\n");
    for (auto [name, r] : {std::pair{"newmark", newmark}, {"bdf2", bdf2}, {"implicit_euler", euler}})
      std::printf("%-15s %.2e  %5d  %+13.3f  %11.4f  %8.3f\n", name, dt, 100, 100 * r.drift, r.tip_max, r.wall_s);
  }
}

// Kelvin-Voigt damping (eta = 30 Pa s: damping ratio ~ omega eta / 2G ~ 1 % for the
// first mode): the energy decreases, and kinetic + elastic + dissipated stays at the
// initial energy to within Newmark's (undamped) drift.
TEST(Dynamics, KelvinVoigtDampingBalancesEnergy) {
  const double dt = 2.5e-3;
  const SwingResult damped = swing(TimeScheme::newmark, dt, 40, 30.0);
  EXPECT_LT(damped.drift, -0.05);
  const double balance = (damped.energy_end + damped.dissipated - damped.energy0) / damped.energy0;
  EXPECT_LT(std::abs(balance), 0.01) << "dissipated " << damped.dissipated << " J of " << damped.energy0 << " J";
  if (report())
    std::printf("damped newmark: energy %+.3f %%, dissipated %.4f J of %.4f J, balance %+.3f %%\n", 100 * damped.drift,
                damped.dissipated, damped.energy0, 100 * balance);
}

namespace {

// Axial vibration of a bar with nu = 0 (no lateral coupling), clamped at x = 0,
// free at x = L: u_x = (V/omega) sin(pi x / 2L) sin(omega t), omega = pi c / 2L,
// c = sqrt(E/rho), E = 2 mu. Returns the period measured from the tip's zero
// crossings (linear interpolation) [s] and the analytic period [s].
struct BarResult {
  double period = 0, exact = 0, error_estimate = 0;
};
BarResult axial_bar(TimeScheme scheme, int steps_per_period, double periods) {
  const double L = 0.1, mu = 1e5, E = 2 * mu, c = std::sqrt(E / kDensity);
  const double omega = M_PI * c / (2 * L), T = 2 * M_PI / omega, V = 1e-4 * L * omega;
  InertiaOptions options;
  options.scheme = scheme;
  Scene scene(make_mesh("cantilever", L, 0.0125, 0.0125, 0.0125, 2), mu, 0.0, options, Eigen::Vector3d::Zero());
  scene.inertia->set_initial_velocity(
      [&](const Eigen::Vector3d& X) { return Eigen::Vector3d(V * std::sin(M_PI * X.x() / (2 * L)), 0, 0); });
  const double dt = T / steps_per_period;
  const int steps = static_cast<int>(std::lround(periods * steps_per_period));
  IncrementalSolver solver(*scene.assembler, {clamp(scene.mesh, "root")}, fixed_steps(steps * dt, dt));
  const auto tip = scene.mesh.nodes_of_surface("tip");
  std::vector<double> times{0.0}, tip_u{0.0};
  const RunStats stats = solver.run([&](const StepReport& r) {
    const RowMatrixXd field = scene.assembler->gather_all(solver.solution());
    double sum = 0;
    for (int a : tip) sum += field(a, 0);
    times.push_back(r.t);
    tip_u.push_back(sum / tip.size());
  });
  EXPECT_TRUE(stats.completed) << stats.failure;
  // Zero crossings after t = 0: at T/2 (down) and T (up).
  std::vector<double> crossings;
  for (size_t i = 1; i + 1 < times.size(); ++i)
    if ((tip_u[i] > 0) != (tip_u[i + 1] > 0))
      crossings.push_back(times[i] + (times[i + 1] - times[i]) * tip_u[i] / (tip_u[i] - tip_u[i + 1]));
  BarResult r;
  r.exact = T;
  if (crossings.size() >= 2) r.period = crossings[1];
  r.error_estimate = scene.inertia->last_error();
  return r;
}

}  // namespace

// Newmark's period elongation is T_h / T = (omega h / 2) / atan(omega h / 2); with
// 40 steps per period the measured period matches it within 0.1 % (P2 bar, 8 cells
// along: spatial error ~ 1e-4).
TEST(Dynamics, AxialBarPeriodMatchesAnalytic) {
  const int steps_per_period = 40;
  const BarResult r = axial_bar(TimeScheme::newmark, steps_per_period, 1.25);
  const double x = M_PI / steps_per_period;  // omega h / 2
  const double elongation = x / std::atan(x);
  EXPECT_NEAR(r.period / r.exact, elongation, 1e-3) << "period " << r.period << " s, analytic " << r.exact << " s";
  if (report())
    std::printf("axial bar (newmark, %d steps/period): T = %.6f s, analytic %.6f s, ratio %.5f, expected %.5f\n",
                steps_per_period, r.period, r.exact, r.period / r.exact, elongation);
}

// The local truncation error estimate e = (beta - 1/6) h^2 (a_{n+1} - a_n) scales as
// h^3 (compared at the same time, T/2), like BDF2's (2/9) h^2 (a_{n+1} - a_n).
TEST(Dynamics, TruncationErrorEstimateIsThirdOrder) {
  for (TimeScheme scheme : {TimeScheme::newmark, TimeScheme::bdf2}) {
    const BarResult coarse = axial_bar(scheme, 16, 0.5), fine = axial_bar(scheme, 32, 0.5);
    const double ratio = coarse.error_estimate / fine.error_estimate;
    EXPECT_GT(ratio, 6.0) << "scheme " << int(scheme);
    EXPECT_LT(ratio, 10.0) << "scheme " << int(scheme);
  }
}
