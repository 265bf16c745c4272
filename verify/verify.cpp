#include "verify/verify.h"

#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <set>

#include "core/errors.h"
#include "core/json.h"
#include "core/strings.h"
#include "fem/element.h"
#include "fem/material.h"
#include "sim/simulation.h"
#include "verify/verify_cases.h"
#include "verify/verify_contact.h"
#include "verify/verify_gas.h"
#include "verify/verify_hard.h"
#include "verify/verify_self_contact.h"

namespace morphfem {

double relative_error(double value, double reference) { return std::abs(value - reference) / std::abs(reference); }

void VerificationRecord::compare(double measured, double exact) {
  value = measured;
  reference = exact;
  rel_error = relative_error(measured, exact);
}

std::string VerificationRecord::json() const {
  Json j;
  j.add("case", case_name)
      .add("quantity", quantity)
      .add("level", level)
      .add("order", order)
      .add("h", h)
      .add("value", value)
      .add("reference", reference)
      .add("rel_error", rel_error)
      .add("rate", rate)
      .add("dofs", dofs)
      .add("wall_s", wall_s)
      .add("newton_its", newton_its)
      .add("steps", steps)
      .add("step_cuts", step_cuts);
  return j.str();
}

ParamSet verification_params(std::initializer_list<std::pair<const char*, double>> numbers, const char* text_key,
                             const char* text) {
  ParamSet p("verification");
  for (const auto& [k, v] : numbers) p.set(k, v);
  if (text_key) p.set_string(text_key, text);
  return p;
}

ParamSet cube_geometry(double L, double h, int order, bool structured, double distort) {
  ParamSet p = verification_params({{"lx", L}, {"ly", L}, {"lz", L}, {"mesh_size", h}, {"order", double(order)}},
                                   "type", "block");
  if (structured) p.set("structured", 1.0);
  if (distort > 0) p.set("distort", distort);
  return p;
}

Scene verification_scene(const std::string& name, ParamSet geometry, ParamSet material) {
  Scene s;
  s.name = name;
  s.geometry = std::move(geometry);
  s.materials["body"] = std::move(material);
  return s;
}

VerificationRecord verification_record(const std::string& case_name, const std::string& quantity, int level, int order,
                                       double h, const SimulationResult& r) {
  return verification_record(case_name, quantity, level, order, h, r.dofs, r.stats);
}

VerificationRecord verification_record(const std::string& case_name, const std::string& quantity, int level, int order,
                                       double h, long dofs, const RunStats& stats) {
  VerificationRecord rec;
  rec.case_name = case_name;
  rec.quantity = quantity;
  rec.level = level;
  rec.order = order;
  rec.h = h;
  rec.dofs = dofs;
  rec.wall_s = stats.wall_s;
  rec.newton_its = stats.newton_its;
  rec.steps = stats.steps;
  rec.step_cuts = stats.step_cuts;
  return rec;
}

void require_completed(const SimulationResult& r, const std::string& what) {
  if (!r.stats.completed) throw SolveError(what + ": " + r.stats.failure);
}

namespace {

constexpr double kPi = 3.14159265358979323846;

// Deformation gradient of the discrete field at reference point xi of cell c.
Mat3 cell_F(const Mesh& mesh, const RowMatrixXd& u, int c, const Eigen::Vector3d& xi, Eigen::Matrix3d* grad_u = nullptr,
            double* detJ0 = nullptr, Eigen::Vector3d* X_at = nullptr, Eigen::Vector3d* u_at = nullptr) {
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  tet_shape(mesh.order, xi, N, dN);
  const int n = mesh.nodes_per_cell();
  Eigen::MatrixXd X(n, 3), U(n, 3);
  for (int a = 0; a < n; ++a) {
    X.row(a) = mesh.X.row(mesh.cells(c, a));
    U.row(a) = u.row(mesh.cells(c, a));
  }
  const Eigen::Matrix3d J0 = X.transpose() * dN;
  const Eigen::MatrixXd dNdX = dN * J0.inverse();
  const Eigen::Matrix3d G = U.transpose() * dNdX;
  if (grad_u) *grad_u = G;
  if (detJ0) *detJ0 = J0.determinant();
  if (X_at) *X_at = X.transpose() * N;
  if (u_at) *u_at = U.transpose() * N;
  return Mat3::Identity() + G;
}

// Prescribes every component of u = field(X, t) on the six faces of a block mesh.
void prescribe_on_block_faces(Scene& s, const std::function<Eigen::Vector3d(const Eigen::Vector3d&, double)>& field) {
  for (const char* face : {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}) {
    BoundarySpec b;
    b.surface = face;
    b.components = {true, true, true};
    b.field = field;
    s.boundary.push_back(b);
  }
}

// ---------------------------------------------------------------- case 1: patch test
// Affine u = (F - I) X imposed on the whole boundary of a distorted block: the
// discrete solution must be exactly affine (nodes and F in every cell).
void patch_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  Mat3 F;
  F << 1.10, 0.05, 0.00, 0.02, 0.95, 0.03, 0.00, 0.04, 1.05;
  const double L = 0.01;
  std::vector<int> divisions = opt.quick ? std::vector<int>{2, 3} : std::vector<int>{2, 3, 4};
  for (int order : {1, 2})
    for (size_t level = 0; level < divisions.size(); ++level) {
      const double h = L / divisions[level];
      Scene s = verification_scene("patch", cube_geometry(L, h, order, false, 0.25),
                                   verification_params({{"mu", 1e5}, {"kappa", 5e5}}, "model", "neo_hookean"));
      const Mat3 G = F - Mat3::Identity();
      prescribe_on_block_faces(s, [G](const Eigen::Vector3d& X, double t) { return Eigen::Vector3d(t * G * X); });
      s.solver.t_end = 1.0;
      s.solver.dt_initial = 0.5;
      auto r = run_scene(s, comm, {false, opt.progress});
      require_completed(r, "patch test");
      double err_u = 0, scale_u = 0, err_F = 0;
      for (int n = 0; n < r.mesh.n_nodes(); ++n) {
        const Eigen::Vector3d exact = G * r.mesh.X.row(n).transpose();
        err_u = std::max(err_u, (r.u.row(n).transpose() - exact).norm());
        scale_u = std::max(scale_u, exact.norm());
      }
      for (int c = 0; c < r.mesh.n_cells(); ++c)
        err_F = std::max(err_F, (cell_F(r.mesh, r.u, c, Eigen::Vector3d(0.25, 0.25, 0.25)) - F).norm() / G.norm());
      auto rec = verification_record("patch", "max_rel_error_u_and_F", int(level), order, h, r);
      rec.value = std::max(err_u / scale_u, err_F);
      rec.reference = 0.0;
      rec.rel_error = rec.value;
      out.push_back(rec);
    }
}

// ------------------------------------------------------- case 2: manufactured solution
// u_k = a sin(c w_k.X + phi_k); body force B = -Div P(F(u)),
// (Div P)_i = sum_{J,k,L} A_iJkL d2u_k/dX_J dX_L, with A = dP/dF at the exact F.
struct Manufactured {
  double a, c;
  Eigen::Matrix3d w;  // row k: w_k
  Eigen::Vector3d phi;
  Eigen::Vector3d u(const Eigen::Vector3d& X) const {
    Eigen::Vector3d out;
    for (int k = 0; k < 3; ++k) out[k] = a * std::sin(c * w.row(k).dot(X) + phi[k]);
    return out;
  }
  Eigen::Matrix3d grad(const Eigen::Vector3d& X) const {  // du_k/dX_J
    Eigen::Matrix3d G;
    for (int k = 0; k < 3; ++k) G.row(k) = a * c * std::cos(c * w.row(k).dot(X) + phi[k]) * w.row(k);
    return G;
  }
};

void mms_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  const double L = 0.1;
  Manufactured m;
  m.c = kPi / L;
  m.a = 0.04 / m.c;  // strains of a few percent
  m.w << 1.0, 0.5, 0.3, 0.2, 1.0, 0.7, 0.6, 0.4, 1.0;
  m.phi = Eigen::Vector3d(0.1, 0.7, 1.3);
  ParamSet material = verification_params({{"mu", 1e5}, {"kappa", 3e5}}, "model", "neo_hookean");
  std::shared_ptr<const Material> law = make_material(material);
  auto body_force = [m, law](const Eigen::Vector3d& X, double) {
    Mat3 F = Mat3::Identity() + m.grad(X);
    double W;
    Mat3 P;
    Tangent A;
    law->evaluate(F, W, P, &A);
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 3; ++J)
        for (int k = 0; k < 3; ++k)
          for (int Lx = 0; Lx < 3; ++Lx) {
            const double d2u = -m.a * m.c * m.c * m.w(k, J) * m.w(k, Lx) * std::sin(m.c * m.w.row(k).dot(X) + m.phi[k]);
            b[i] -= A(3 * i + J, 3 * k + Lx) * d2u;
          }
    return b;
  };
  std::map<int, std::vector<int>> ladder = opt.quick ? std::map<int, std::vector<int>>{{1, {2, 4}}, {2, {2, 4}}}
                                                     : std::map<int, std::vector<int>>{{1, {4, 8, 16}}, {2, {2, 4, 8}}};
  for (auto& [order, divisions] : ladder) {
    ConvergenceRate rates[2];  // L2, H1
    for (size_t level = 0; level < divisions.size(); ++level) {
      const double h = L / divisions[level];
      Scene s = verification_scene("mms", cube_geometry(L, h, order, true), material);
      prescribe_on_block_faces(s, [m](const Eigen::Vector3d& X, double t) { return Eigen::Vector3d(t * m.u(X)); });
      s.body_force = [body_force](const Eigen::Vector3d& X, double t) { return Eigen::Vector3d(t * body_force(X, t)); };
      s.body_force_degree = 6;
      s.solver.t_end = 1.0;
      s.solver.dt_initial = 0.5;
      auto r = run_scene(s, comm, {false, opt.progress});
      require_completed(r, "manufactured solution");
      // Errors by degree-6 quadrature: ||u_h - u||_L2 / ||u||_L2, |u_h - u|_H1 / |u|_H1.
      double e_L2 = 0, n_L2 = 0, e_H1 = 0, n_H1 = 0;
      for (int c = 0; c < r.mesh.n_cells(); ++c)
        for (const auto& q : tet_quadrature(6)) {
          Eigen::Matrix3d Gh;
          double detJ0;
          Eigen::Vector3d X, uh;
          cell_F(r.mesh, r.u, c, q.xi, &Gh, &detJ0, &X, &uh);
          const double dV = q.weight * detJ0;
          const Eigen::Vector3d ue = m.u(X);
          const Eigen::Matrix3d Ge = m.grad(X);
          e_L2 += dV * (uh - ue).squaredNorm();
          n_L2 += dV * ue.squaredNorm();
          e_H1 += dV * (Gh - Ge).squaredNorm();
          n_H1 += dV * Ge.squaredNorm();
        }
      const double L2 = std::sqrt(e_L2 / n_L2), H1 = std::sqrt(e_H1 / n_H1);
      for (int which = 0; which < 2; ++which) {
        auto rec = verification_record("mms", which == 0 ? "L2_error" : "H1_error", int(level), order, h, r);
        rec.value = which == 0 ? L2 : H1;
        rec.reference = 0;
        rec.rel_error = rec.value;
        rec.rate = rates[which].next(rec.value, h);
        out.push_back(rec);
      }
    }
  }
}

// ------------------------------------------------ case 4: thick cylinder, plane strain
// Incompressible neo-Hookean: P/mu = ln(la/lb) + 1/(2 lb^2) - 1/(2 la^2),
// lb^2 = 1 + (la^2 - 1)(A/B)^2.
double cylinder_pressure(double la, double ratio) {
  const double lb = std::sqrt(1.0 + (la * la - 1.0) * ratio * ratio);
  return std::log(la / lb) + 0.5 / (lb * lb) - 0.5 / (la * la);
}

void cylinder_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  const double A = 0.01, B = 0.02, mu = 1e5;
  const double p_over_mu = 0.574054;  // VERIFICATION.md case 4, A/B = 0.5, la = 2.0
  std::vector<double> sizes = opt.quick ? std::vector<double>{A / 2} : std::vector<double>{A / 2, A / 4, A / 8};
  std::vector<int> orders = opt.quick ? std::vector<int>{2} : std::vector<int>{1, 2};
  // Runs: every (order, level) at kappa = 1000 mu; on the finest P2 level also
  // kappa = 100 mu and 10000 mu, to show how much of the error compressibility explains.
  struct Run {
    int order;
    size_t level;
    double kappa_ratio;
  };
  std::vector<Run> runs;
  for (int order : orders)
    for (size_t level = 0; level < sizes.size(); ++level) runs.push_back({order, level, 1000.0});
  if (!opt.quick) {
    runs.push_back({2, sizes.size() - 1, 100.0});
    runs.push_back({2, sizes.size() - 1, 10000.0});
  }
  for (const Run& run : runs) {
    const int order = run.order;
    const size_t level = run.level;
    const double h = sizes[level], kappa = run.kappa_ratio * mu;
    const std::string suffix =
        run.kappa_ratio == 1000.0 ? "" : " (kappa/mu=" + std::to_string(int(run.kappa_ratio)) + ")";
    Scene s = verification_scene(
        "cylinder",
        verification_params({{"inner_radius", A}, {"outer_radius", B}, {"mesh_size", h}, {"order", double(order)}},
                            "type", "thick_cylinder"),
        verification_params({{"mu", mu}, {"kappa", kappa}}, "model", "neo_hookean"));
    for (auto [face, axis] :
         std::vector<std::pair<const char*, int>>{{"sym_x", 0}, {"sym_y", 1}, {"zmin", 2}, {"zmax", 2}}) {
      BoundarySpec b;
      b.surface = face;
      b.components[axis] = true;
      s.boundary.push_back(b);
    }
    CavitySpec cavity;
    cavity.name = "bore";
    cavity.surfaces = {"inner"};
    cavity.axes = {true, true, false};
    cavity.pressure = TimeFunction::ramp(p_over_mu * mu, 1.0);
    s.cavities.push_back(cavity);
    s.solver.t_end = 1.0;
    s.solver.dt_initial = 0.1;
    s.solver.dt_max = 0.25;
    auto r = run_scene(s, comm, {false, opt.progress});
    require_completed(r, "thick cylinder");
    // Inner stretch from the inner wall's vertices: la = mean |x_xy| / A.
    std::set<int> vertices;
    for (int f : r.mesh.faces_of("inner"))
      for (int a = 0; a < 3; ++a) vertices.insert(r.mesh.faces(f, a));
    double sum = 0;
    for (int n : vertices) {
      Eigen::Vector3d x = r.mesh.X.row(n).transpose() + r.u.row(n).transpose();
      sum += std::hypot(x[0], x[1]);
    }
    const double la = sum / vertices.size() / A;
    auto rec = verification_record("cylinder", "P/mu at computed inner stretch" + suffix, int(level), order, h, r);
    rec.compare(p_over_mu, cylinder_pressure(la, A / B));
    out.push_back(rec);
    auto srec = verification_record("cylinder", "inner stretch (reference 2.0)" + suffix, int(level), order, h, r);
    srec.compare(la, 2.0);
    out.push_back(srec);
  }
}

// ------------------------------------------ case 7: cantilever, dead end load (elastica)
void cantilever_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  const double L = 0.1, h = L / 50, b = h, mu = 1e6;
  const double E = 2 * mu, I = b * h * h * h / 12.0;  // nu = 0: E = 2 mu, kappa = 2 mu / 3
  const std::map<int, double> reference{{1, 0.30172}, {2, 0.49346}, {5, 0.71379}, {10, 0.81061}};
  const double k_max = opt.quick ? 1.0 : 10.0;
  std::vector<double> sizes = opt.quick ? std::vector<double>{h} : std::vector<double>{2 * h, h, h / 2};
  for (int order : {1, 2}) {
    if (opt.quick && order == 1) continue;
    for (size_t level = 0; level < sizes.size(); ++level) {
      const double size = sizes[level];
      Scene s = verification_scene(
          "cantilever",
          verification_params(
              {{"L", L}, {"b", b}, {"h", h}, {"mesh_size", size}, {"order", double(order)}, {"structured", 1}}, "type",
              "cantilever"),
          verification_params({{"mu", mu}, {"kappa", 2 * mu / 3}}, "model", "neo_hookean"));
      BoundarySpec clamp;
      clamp.surface = "root";
      clamp.components = {true, true, true};
      s.boundary.push_back(clamp);
      // k = P L^2 / (E I) grows linearly with t: k(t) = k_max t.
      TractionSpec tip;
      tip.surface = "tip";
      tip.traction = Eigen::Vector3d(0, 0, -k_max * E * I / (L * L) / (b * h));
      tip.scale = TimeFunction::ramp(1.0, 1.0);
      s.tractions.push_back(tip);
      s.solver.t_end = 1.0;
      s.solver.dt_initial = 0.05;
      s.solver.dt_max = 0.1;
      for (const auto& [k, v] : reference)
        if (k <= k_max) s.solver.output_times.push_back(k / k_max);
      std::map<int, double> deflection;
      RunOptions run{false, opt.progress};
      run.on_step = [&](double t, const Mesh& mesh, const RowMatrixXd& u, const SimulationResult&) {
        for (const auto& [k, v] : reference)
          if (std::abs(t - k / k_max) < 1e-9) {
            auto nodes = mesh.nodes_of_surface("tip");
            double w = 0;
            for (int n : nodes) w -= u(n, 2);
            deflection[k] = w / nodes.size() / L;
          }
      };
      auto r = run_scene(s, comm, run);
      require_completed(r, "cantilever");
      for (const auto& [k, v] : deflection) {
        auto rec =
            verification_record("cantilever", "tip deflection v/L, k=" + std::to_string(k), int(level), order, size, r);
        rec.compare(v, reference.at(k));
        out.push_back(rec);
      }
    }
  }
}

// A stiff 2 cm block (P1, mu = 10 MPa) on the ground plane z = 0 under gravity
// g = 9.8 tilted by the slope atan(0.5) (x is downhill), with implicit-Euler
// inertia, barrier contact started at the resting gap and friction mu(t) on its
// bottom face; time step dt up to t_end.
Scene sliding_block_scene(const std::string& name, const TimeFunction& mu, double eps_v, double t_end, double dt) {
  const double g = 9.8, slope = std::atan(0.5), L = 0.02, dhat = 1e-5;
  Scene s =
      verification_scene(name, cube_geometry(L, L / 2, 1),
                         verification_params({{"mu", 1e7}, {"nu", 0.3}, {"density", 1000}}, "model", "neo_hookean"));
  s.gravity = Eigen::Vector3d(g * std::sin(slope), 0, -g * std::cos(slope));
  s.dynamics.emplace().inertia.scheme = TimeScheme::implicit_euler;
  GroundContactSpec& ground = s.ground.emplace();
  ground.surfaces = {"zmin"};
  ground.dhat = dhat;
  ground.point = Eigen::Vector3d(0, 0, -0.9985 * dhat);  // the resting barrier gap under the weight
  FrictionSpec& friction = s.friction.emplace();
  friction.eps_v = eps_v;  // stick creep ~ eps_v (1 - sqrt(1 - q)) per second, q = load / (mu N)
  friction.regions.push_back({"zmin", mu, mu});
  s.solver.t_end = t_end;
  s.solver.dt_initial = s.solver.dt_max = dt;
  return s;
}

// -------------------------------------------- case 8: block sliding down a slope
// Coulomb friction mu = 0.49 on a slope atan(0.5), g = 9.8 (gravity tilted):
// s(t) = a t^2 / 2, a = g (sin - mu cos) = 0.087654 m/s^2, s(2.5 s) = 0.27392 m.
// A time-step ladder with implicit Euler (first order); the block is stiff so its
// deformation does not add to the slide.
void slope_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  const double g = 9.8, slope = std::atan(0.5), mu = 0.49, T = 2.5;
  const double reference = 0.5 * g * (std::sin(slope) - mu * std::cos(slope)) * T * T;
  const double L = 0.02;
  std::vector<double> steps = opt.quick ? std::vector<double>{0.05, 0.025} : std::vector<double>{0.05, 0.025, 0.0125};
  ConvergenceRate rate;
  for (size_t level = 0; level < steps.size(); ++level) {
    const double dt = steps[level];
    Scene s = sliding_block_scene("slope", TimeFunction::constant(mu), 1e-4, T, dt);
    auto r = run_scene(s, comm, {false, opt.progress});
    require_completed(r, "block on a slope");
    double slide = 0;
    for (int n = 0; n < r.mesh.n_nodes(); ++n) slide += r.u(n, 0);
    slide /= r.mesh.n_nodes();
    auto rec = verification_record("slope", "slide s(2.5 s) [m], dt=" + std::to_string(dt).substr(0, 6), int(level), 1,
                                   L / 2, r);
    rec.compare(slide, reference);
    rec.rate = rate.next(rec.rel_error, dt);
    out.push_back(rec);
  }
}

// ------------------------------- friction that switches on a schedule
// A block on a slope atan(0.5): mu = 0.9 (sticks) until t = 1 s, 0.2 (slides,
// a1 = g (sin - 0.2 cos)) until t = 2 s, then 0.9 again (decelerates with
// a2 = g (sin - 0.9 cos) < 0 until it stops). Exact slide:
// s = a1/2 (1 s)^2 + (a1 * 1 s)^2 / (2 |a2|); no motion before t = 1 s.
void friction_switch_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out) {
  const double g = 9.8, slope = std::atan(0.5), L = 0.02, T = 3.0;
  const double a1 = g * (std::sin(slope) - 0.2 * std::cos(slope)), a2 = g * (std::sin(slope) - 0.9 * std::cos(slope));
  const double reference = 0.5 * a1 + a1 * a1 / (2 * std::abs(a2));
  const TimeFunction mu({{0.0, 0.9}, {1.0, 0.9}, {1.0 + 1e-6, 0.2}, {2.0, 0.2}, {2.0 + 1e-6, 0.9}});
  std::vector<double> steps = opt.quick ? std::vector<double>{0.02} : std::vector<double>{0.02, 0.01, 0.005};
  ConvergenceRate rate;
  for (size_t level = 0; level < steps.size(); ++level) {
    const double dt = steps[level];
    Scene s = sliding_block_scene("friction_switch", mu, 1e-5, T, dt);
    s.solver.output_times = {1.0, 2.0};
    double slide_at_1 = 0;
    RunOptions run{false, opt.progress};
    run.on_step = [&](double t, const Mesh& mesh, const RowMatrixXd& u, const SimulationResult&) {
      if (std::abs(t - 1.0) < 1e-9) slide_at_1 = u.col(0).mean();
    };
    auto r = run_scene(s, comm, run);
    require_completed(r, "friction switch");
    const double slide = r.u.col(0).mean();
    auto rec = verification_record("friction_switch", "slide [m] over 3 s, dt=" + std::to_string(dt).substr(0, 5),
                                   int(level), 1, L / 2, r);
    rec.compare(slide, reference);
    rec.rate = rate.next(rec.rel_error, dt);
    out.push_back(rec);
    auto still = verification_record("friction_switch", "creep [m] while mu = 0.9 (t < 1 s)", int(level), 1, L / 2, r);
    still.value = slide_at_1;
    still.reference = 0;
    still.rel_error = std::abs(slide_at_1) / L;  // relative to the block size
    out.push_back(still);
  }
}

struct CaseEntry {
  VerificationCase run;
  bool hard;
};

// The one table of verification cases.
const std::map<std::string, CaseEntry>& cases() {
  static const std::map<std::string, CaseEntry> registry{
      {"patch", {patch_case, false}},
      {"mms", {mms_case, false}},
      {"cylinder", {cylinder_case, false}},
      {"cantilever", {cantilever_case, false}},
      {"slope", {slope_case, false}},
      {"friction_switch", {friction_switch_case, false}},
      {"tube_vacuum", {tube_vacuum_case, false}},  // case 11: self-contact (verify_self_contact.h)
      {"rolling", {rolling_case, false}},
      {"hertz", {hertz_case, false}},
      // The hard-case suite (morphfem verify --hard): near-incompressibility,
      // large compression and rotation, limit points.
      {"cook", {cook_case, true}},
      {"incompressible_block", {incompressible_block_case, true}},
      {"compression", {compression_case, true}},
      {"end_moment", {end_moment_case, true}},
      // Limit points: gas- and volume-controlled cavities, the valve model.
      {"gas_sphere", {gas_thick_sphere_case, true}},
      {"gas_balloon", {gas_balloon_case, true}},
      {"gas_mooney_balloon", {gas_mooney_balloon_case, true}},
      {"pressure_past_limit", {gas_pressure_control_failure_case, true}},
      {"valve", {gas_valve_case, true}},
  };
  return registry;
}

}  // namespace

std::vector<std::string> verification_case_names(bool hard) {
  std::vector<std::string> names;
  for (const auto& [name, entry] : cases())
    if (entry.hard == hard) names.push_back(name);
  return names;
}

std::vector<VerificationRecord> run_verification(const VerifyOptions& options, MPI_Comm comm) {
  std::vector<std::string> names = options.cases.empty() ? verification_case_names(options.hard) : options.cases;
  for (const auto& n : names)
    if (!cases().count(n))
      throw InputError("--case", "unknown verification case '" + n + "' (known: " + join_keys(cases(), ", ") + ")");
  std::vector<VerificationRecord> out;
  for (const auto& n : names) cases().at(n).run(options, comm, out);
  return out;
}

}  // namespace morphfem
