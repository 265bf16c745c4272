// Contact verification cases (see verify_contact.h). Units: SI (m, s, kg, N, Pa).
#include "verify/verify_contact.h"

#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>

#include "contact/barrier.h"
#include "contact/ground.h"
#include "core/errors.h"
#include "fem/element.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "verify/verify_cases.h"

namespace morphfem {

namespace {

constexpr double kPi = 3.14159265358979323846;

// "0.001" rather than "0.001000": a number for record labels.
std::string short_number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", v);
  return buffer;
}

// Observed convergence rate log(e_prev / e) / log(h_prev / h) (0 without a previous level).
double observed_rate(double error_prev, double h_prev, double error, double h) {
  if (!(error_prev > 0 && error > 0 && h_prev > 0 && h > 0) || h_prev == h) return 0.0;
  return std::log(error_prev / error) / std::log(h_prev / h);
}

// ------------------------------------------------------------ case 9: rolling
// A solid cylinder of radius R, axis along y through the origin, on the plane
// n . (x - p0) = 0 with p0 = -(R + gap0) n (n the unit normal, t the downhill unit
// tangent, both normal to the axis). Gravity is split into its normal part, on from
// t = 0 so the body settles onto the barrier without sliding, and its downhill part,
// switched on at t_release:
//   b(t) = rho g (-cos(theta) n + [t > t_release] sin(theta) t)     [N/m^3]
// "tilted gravity": n = e_z, t = e_x (the plane is level, gravity is tilted);
// "inclined plane": n = (sin, 0, cos), t = (cos, 0, -sin) (after release b = -rho g e_z).
struct RollingSetup {
  double radius = 0.02, length = 0.01;  // [m]
  double inner_radius = 0;              // > 0: a thick-walled tube [m]
  double mesh_size = 0.005;             // [m]
  double dt = 1e-3;                     // implicit-Euler step [s]
  double mu = 1.0;                      // friction coefficient (static = kinetic)
  bool inclined_plane = false;
  double t_release = 0.02, t_roll = 0.1;  // settle time, rolling time [s]
};

constexpr double kGravity = 9.8, kSlope = kPi / 6;  // [m/s^2], 30 deg
constexpr double kRollDensity = 1000.0;             // [kg/m^3]

struct RollingResult {
  double acceleration = 0;  // fitted centre acceleration along the slope [m/s^2]
  SimulationResult run;
};

RollingResult run_rolling(const RollingSetup& setup, const VerifyOptions& opt, MPI_Comm comm) {
  const double c = std::cos(kSlope), s = std::sin(kSlope);
  const Eigen::Vector3d n = setup.inclined_plane ? Eigen::Vector3d(s, 0, c) : Eigen::Vector3d(0, 0, 1);
  const Eigen::Vector3d t_dir = setup.inclined_plane ? Eigen::Vector3d(c, 0, -s) : Eigen::Vector3d(1, 0, 0);
  const double dhat = 1e-5;  // barrier width [m] = R / 2000
  // Stiff (E = 2 mu (1 + nu) = 7.8 MPa) so the cylinder rolls as a nearly rigid body.
  Scene scene = verification_scene(
      "rolling",
      verification_params({{"radius", setup.radius},
                           {"length", setup.length},
                           {"inner_radius", setup.inner_radius},
                           {"mesh_size", setup.mesh_size},
                           {"order", 2}},
                          "type", "solid_cylinder"),
      verification_params({{"mu", 3e6}, {"nu", 0.3}, {"density", kRollDensity}}, "model", "neo_hookean"));
  const double t_release = setup.t_release;
  scene.body_force = [n, t_dir, c, s, t_release](const Eigen::Vector3d&, double t) {
    Eigen::Vector3d b = -kRollDensity * kGravity * c * n;
    if (t > t_release + 1e-12) b += kRollDensity * kGravity * s * t_dir;
    return b;
  };
  scene.body_force_degree = 2;
  scene.dynamics.emplace().inertia.scheme = TimeScheme::implicit_euler;
  GroundContactSpec& ground = scene.ground.emplace();
  ground.surfaces = {"outer"};
  ground.normal = n;
  ground.dhat = dhat;
  ground.point = -(setup.radius + 0.9 * dhat) * n;  // barely inside the barrier: settles without a drop
  FrictionSpec& friction = scene.friction.emplace();
  friction.eps_v = 1e-3;  // [m/s]; rolling needs mu N >= f = m g sin / 3: creep ~ 0.1 eps_v
  friction.regions.push_back({"outer", TimeFunction::constant(setup.mu), TimeFunction::constant(setup.mu)});
  scene.solver.t_end = setup.t_release + setup.t_roll;
  scene.solver.dt_initial = scene.solver.dt_max = setup.dt;
  scene.solver.output_times = {setup.t_release};

  std::vector<double> weights, times, travel;
  double weight_sum = 0;
  RunOptions run{false, opt.progress};
  run.on_step = [&](double t, const Mesh& mesh, const RowMatrixXd& u, const SimulationResult&) {
    if (weights.empty()) {
      weights = nodal_volume_weights(mesh);
      for (double w : weights) weight_sum += w;
    }
    if (t < setup.t_release - 1e-12) return;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int a = 0; a < mesh.n_nodes(); ++a) centre += weights[a] * u.row(a).transpose();
    times.push_back(t - setup.t_release);
    travel.push_back(t_dir.dot(centre) / weight_sum);
  };
  RollingResult result;
  result.run = run_scene(scene, comm, run);
  require_completed(result.run, "rolling cylinder");
  result.acceleration = fitted_acceleration(times, travel);
  return result;
}

// ------------------------------------------------------------ case 10: Hertz
constexpr double kHertzRadius = 0.01, kHertzE = 1e6, kHertzNu = 0.49, kHertzIndent = 1e-4;  // m, Pa, -, m

struct HertzSetup {
  double indent = kHertzIndent;  // d [m]
  double contact_size = 2.5e-4;  // element size within refine_radius of the pole [m]
  double dhat = 1e-6;            // barrier width [m]
};

struct HertzResult {
  double force = 0;           // total contact force of the whole sphere [N]
  double contact_radius = 0;  // from the force-weighted second moment [m]
  SimulationResult run;
};

// A quarter of the lower hemisphere (x, y >= 0, z <= 0) pressed by u_z = -d on its
// flat face (free to slide: the mid-plane of a sphere between two plates) onto the
// plane z = -R - dhat (the barrier starts at the pole with zero force). The contact
// force of node a is A_a kappa (-phi'(g_a / dhat)) (contact/ground.h) at the final
// gap g_a; the whole sphere carries 4 x the quarter's sum. Hertz pressure
// p = p0 sqrt(1 - r^2/a^2) has int p r^2 dA / int p dA = (2/5) a^2, so the contact
// radius is measured as a = sqrt(5/2 <r^2>_F) (nodal forces as weights).
HertzResult run_hertz(const HertzSetup& setup, const VerifyOptions& opt, MPI_Comm comm) {
  const double R = kHertzRadius, d = setup.indent;
  const double mu = kHertzE / (2 * (1 + kHertzNu));
  Scene scene = verification_scene("hertz",
                                   verification_params({{"radius", R},
                                                        {"mesh_size", R / 2.5},
                                                        {"contact_size", setup.contact_size},
                                                        {"refine_radius", 1.5 * std::sqrt(R * d)},
                                                        {"order", 2}},
                                                       "type", "hemisphere"),
                                   verification_params({{"mu", mu}, {"nu", kHertzNu}}, "model", "neo_hookean"));
  BoundarySpec press;
  press.surface = "flat";
  press.components = {false, false, true};
  press.displacement = Eigen::Vector3d(0, 0, -d);
  scene.boundary.push_back(press);
  for (auto [face, axis] : std::vector<std::pair<const char*, int>>{{"sym_x", 0}, {"sym_y", 1}}) {
    BoundarySpec b;
    b.surface = face;
    b.components[axis] = true;
    scene.boundary.push_back(b);
  }
  GroundContactSpec& ground = scene.ground.emplace();
  ground.surfaces = {"sphere"};
  ground.dhat = setup.dhat;
  ground.kappa = kHertzE;  // barrier stiffness [Pa]
  ground.point = Eigen::Vector3d(0, 0, -R - setup.dhat);
  scene.solver.t_end = 1.0;
  scene.solver.dt_initial = 0.25;
  scene.solver.dt_max = 0.5;

  HertzResult result;
  result.run = run_scene(scene, comm, {false, opt.progress});
  require_completed(result.run, "Hertz contact");
  const Mesh& mesh = result.run.mesh;
  const std::vector<double> area = nodal_area_weights(mesh, mesh.faces_of("sphere"));
  double force = 0, moment = 0;  // quarter: sum f_a, sum f_a r_a^2
  for (int a = 0; a < mesh.n_nodes(); ++a) {
    if (area[a] <= 0) continue;
    const Eigen::Vector3d x = mesh.X.row(a).transpose() + result.run.u.row(a).transpose();
    const double gap = x.z() - scene.ground->point.z();
    if (gap >= setup.dhat) continue;
    if (!(gap > 0)) throw SolveError("Hertz contact: a node passed through the plane");
    const double f = area[a] * scene.ground->kappa * -barrier_dphi(gap / setup.dhat);
    force += f;
    moment += f * (x.x() * x.x() + x.y() * x.y());
  }
  result.force = 4 * force;
  result.contact_radius = force > 0 ? std::sqrt(2.5 * moment / force) : 0.0;
  return result;
}

}  // namespace

std::vector<double> nodal_volume_weights(const Mesh& mesh) {
  std::vector<double> w(mesh.n_nodes(), 0.0);
  const int n = mesh.nodes_per_cell();
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  Eigen::MatrixXd X(n, 3);
  for (int c = 0; c < mesh.n_cells(); ++c) {
    for (int a = 0; a < n; ++a) X.row(a) = mesh.X.row(mesh.cells(c, a));
    for (const auto& q : tet_quadrature(2 * mesh.order)) {
      tet_shape(mesh.order, q.xi, N, dN);
      const double dV = q.weight * (X.transpose() * dN).determinant();
      for (int a = 0; a < n; ++a) w[mesh.cells(c, a)] += N[a] * dV;
    }
  }
  return w;
}

double fitted_acceleration(const std::vector<double>& t, const std::vector<double>& s) {
  if (t.size() != s.size() || t.size() < 3) throw SolveError("fitted_acceleration: needs at least 3 samples of (t, s)");
  Eigen::MatrixXd A(t.size(), 3);
  Eigen::VectorXd b(t.size());
  for (size_t i = 0; i < t.size(); ++i) {
    A.row(i) << 1.0, t[i], 0.5 * t[i] * t[i];
    b[i] = s[i];
  }
  const Eigen::Vector3d coefficients = A.colPivHouseholderQr().solve(b);
  return coefficients[2];
}

// Ladders (each run once, records per ladder with the observed rate against the
// previous rung): time step at mesh R/4 (implicit Euler's numerical damping of the
// rotation), mesh size at dt = 1 ms, slip (mu = 0.1) over dt, and the inclined plane
// beside tilted gravity at (R/4, 1 ms). Measured (2026-11): the mesh error dominates
// (1.24 %, 0.68 %, 0.34 % at R/3, R/4, R/6: second order, the faceted contact
// line); a moves by < 0.3 % over dt = 0.5 .. 4 ms (implicit Euler's damping of the
// rolling is below that there) and drops by 3.1 % at dt = 8 ms. Quick level: (R/3, 2 ms).
void rolling_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  const double R = RollingSetup{}.radius;
  struct Run {
    double mesh_size, dt, mu;
    bool inclined;
    bool operator<(const Run& o) const {
      return std::tie(mesh_size, dt, mu, inclined) < std::tie(o.mesh_size, o.dt, o.mu, o.inclined);
    }
  };
  struct Ladder {
    std::string name;
    bool over_dt;  // rungs differ in dt (else in mesh size)
    std::vector<Run> rungs;
  };
  std::vector<Ladder> ladders;
  if (opt.quick) {
    ladders = {{"dt ladder", true, {{R / 3, 2e-3, 1.0, false}}}, {"slip", true, {{R / 3, 2e-3, 0.1, false}}}};
  } else {
    ladders = {{"dt ladder", true, {}}, {"mesh ladder", false, {}}, {"slip", true, {}}};
    for (double dt : {8e-3, 4e-3, 2e-3, 1e-3}) ladders[0].rungs.push_back({R / 4, dt, 1.0, false});
    for (double h : {R / 3, R / 4, R / 6}) ladders[1].rungs.push_back({h, 1e-3, 1.0, false});
    for (double dt : {2e-3, 1e-3}) ladders[2].rungs.push_back({R / 4, dt, 0.1, false});
  }
  std::map<Run, RollingResult> done;
  auto result_of = [&](const Run& run) -> const RollingResult& {
    auto it = done.find(run);
    if (it != done.end()) return it->second;
    RollingSetup setup;
    setup.mesh_size = run.mesh_size;
    setup.dt = run.dt;
    setup.mu = run.mu;
    setup.inclined_plane = run.inclined;
    return done.emplace(run, run_rolling(setup, opt, comm)).first->second;
  };
  // Quantity: "rolling a [m/s^2]" or "slip a [m/s^2], mu=0.1", then `detail`.
  auto record = [&](const Run& run, const std::string& detail, int level) {
    const RollingResult& r = result_of(run);
    const bool slip = run.mu < std::tan(kSlope) / 3;
    const double reference =
        slip ? kGravity * (std::sin(kSlope) - run.mu * std::cos(kSlope)) : 2.0 / 3.0 * kGravity * std::sin(kSlope);
    const std::string quantity =
        (slip ? "slip a [m/s^2], mu=" + short_number(run.mu) : std::string("rolling a [m/s^2]")) + detail;
    auto rec = verification_record("rolling", quantity, level, 2, run.mesh_size, r.run);
    rec.compare(r.acceleration, reference);
    return rec;
  };
  for (const Ladder& ladder : ladders)
    for (size_t level = 0; level < ladder.rungs.size(); ++level) {
      // dt ladders: one label per dt (as the slope case); the mesh ladder: one series.
      const std::string detail =
          ladder.over_dt ? ", dt=" + short_number(ladder.rungs[level].dt) : ", " + ladder.name + ", dt=0.001";
      auto rec = record(ladder.rungs[level], detail, int(level));
      if (level > 0) {
        const Run& prev = ladder.rungs[level - 1];
        const Run& run = ladder.rungs[level];
        rec.rate = observed_rate(relative_error(result_of(prev).acceleration, rec.reference),
                                 ladder.over_dt ? prev.dt : prev.mesh_size, rec.rel_error,
                                 ladder.over_dt ? run.dt : run.mesh_size);
      }
      out.push_back(rec);
    }
  if (opt.quick) return;
  // The slope as an inclined ground plane (gravity vertical) beside tilted gravity.
  const Run tilted{R / 4, 1e-3, 1.0, false}, inclined{R / 4, 1e-3, 1.0, true};
  out.push_back(record(inclined, ", inclined plane, dt=0.001", 0));
  auto diff = verification_record("rolling", "inclined plane vs tilted gravity a, dt=0.001", 0, 2, R / 4,
                                  result_of(inclined).run);
  diff.compare(result_of(inclined).acceleration, result_of(tilted).acceleration);
  out.push_back(diff);
  // A thick-walled tube, inner radius r = 0.8 R: I = m (R^2 + r^2) / 2, rolling
  // a = g sin / (1 + (1 + r^2/R^2) / 2) (-> g sin / 2 for a thin wall); needs
  // mu >= tan(theta) k / (1 + k), k = (1 + r^2/R^2) / 2 = 0.82: 0.26.
  RollingSetup tube;
  tube.inner_radius = 0.8 * R;
  tube.mesh_size = R / 5;
  const RollingResult r = run_rolling(tube, opt, comm);
  const double k = 0.5 * (1 + 0.64);
  auto rec = verification_record("rolling", "tube r=0.8R rolling a [m/s^2], dt=0.001", 0, 2, tube.mesh_size, r.run);
  rec.compare(r.acceleration, kGravity * std::sin(kSlope) / (1 + k));
  out.push_back(rec);
}

// Records: F and a on the contact-size ladder (dhat = 1e-6 m = d/100), then F
// against dhat on one mesh level (the barrier's offset error shrinks with dhat).
void hertz_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  const double R = kHertzRadius, d = kHertzIndent;
  const double E_star = kHertzE / (1 - kHertzNu * kHertzNu);  // 1/E* = (1 - nu^2)/E (rigid plane)
  const double F_ref = 4.0 / 3.0 * E_star * std::sqrt(R) * std::pow(d, 1.5);
  const double a_ref = std::sqrt(R * d);
  const std::vector<double> sizes =
      opt.quick ? std::vector<double>{2.5e-4} : std::vector<double>{5e-4, 3.5e-4, 2.5e-4, 1.75e-4};
  double prev_F = 0, prev_a = 0, prev_h = 0;
  for (size_t level = 0; level < sizes.size(); ++level) {
    HertzSetup setup;
    setup.contact_size = sizes[level];
    const HertzResult r = run_hertz(setup, opt, comm);
    auto F = verification_record("hertz", "contact force F [N], d/R=0.01, dhat=" + short_number(setup.dhat), int(level),
                                 2, setup.contact_size, r.run);
    F.compare(r.force, F_ref);
    F.rate = level > 0 ? observed_rate(prev_F, prev_h, F.rel_error, setup.contact_size) : 0.0;
    out.push_back(F);
    auto a = verification_record("hertz", "contact radius a [m], sqrt(5/2 <r^2>_F)", int(level), 2, setup.contact_size,
                                 r.run);
    a.compare(r.contact_radius, a_ref);
    a.rate = level > 0 ? observed_rate(prev_a, prev_h, a.rel_error, setup.contact_size) : 0.0;
    out.push_back(a);
    prev_F = F.rel_error;
    prev_a = a.rel_error;
    prev_h = setup.contact_size;
  }
  if (opt.quick) return;
  for (double dhat : {1e-5, 4e-6, 2e-6, 5e-7}) {
    HertzSetup setup;
    setup.contact_size = 2.5e-4;
    setup.dhat = dhat;
    const HertzResult r = run_hertz(setup, opt, comm);
    auto F = verification_record("hertz", "contact force F [N], d/R=0.01, dhat=" + short_number(dhat),
                                 int(sizes.size()), 2, setup.contact_size, r.run);
    F.compare(r.force, F_ref);
    out.push_back(F);
  }
  // The remaining difference from Hertz is the model's (finite sphere, finite strain),
  // not the mesh's: it shrinks with d/R. d/R = 0.0025 (a = 0.5 mm), elements a/4.
  HertzSetup shallow;
  shallow.indent = d / 4;
  shallow.contact_size = 1.25e-4;
  shallow.dhat = 2.5e-7;
  const HertzResult r = run_hertz(shallow, opt, comm);
  auto F = verification_record("hertz", "contact force F [N], d/R=0.0025, dhat=" + short_number(shallow.dhat),
                               int(sizes.size()) + 1, 2, shallow.contact_size, r.run);
  F.compare(r.force, F_ref / 8);  // F ~ d^(3/2)
  out.push_back(F);
}

}  // namespace morphfem
