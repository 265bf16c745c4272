#include "actuation/gas_cavity.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "actuation/cavity.h"
#include "core/errors.h"
#include "fem/loads.h"
#include "fem/petsc_check.h"

namespace morphfem {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

// Smallest alpha in (0, 1] with f(alpha) <= 0 for the cubic through
// (0, f0), (1/3, f1), (2/3, f2), (1, f3); 2 (none) if f stays positive.
double first_nonpositive(double f0, double f1, double f2, double f3) {
  // Lagrange form on the nodes 0, 1/3, 2/3, 1.
  auto f = [&](double a) {
    const double n0 = 0.0, n1 = 1.0 / 3.0, n2 = 2.0 / 3.0, n3 = 1.0;
    const double l0 = (a - n1) * (a - n2) * (a - n3) / ((n0 - n1) * (n0 - n2) * (n0 - n3));
    const double l1 = (a - n0) * (a - n2) * (a - n3) / ((n1 - n0) * (n1 - n2) * (n1 - n3));
    const double l2 = (a - n0) * (a - n1) * (a - n3) / ((n2 - n0) * (n2 - n1) * (n2 - n3));
    const double l3 = (a - n0) * (a - n1) * (a - n2) / ((n3 - n0) * (n3 - n1) * (n3 - n2));
    return f0 * l0 + f1 * l1 + f2 * l2 + f3 * l3;
  };
  const int samples = 64;
  double lo = 0.0;
  for (int i = 1; i <= samples; ++i) {
    const double a = double(i) / samples;
    if (f(a) <= 0.0) {
      double hi = a;
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (f(mid) <= 0.0 ? hi : lo) = mid;
      }
      return hi;
    }
    lo = a;
  }
  return 2.0;
}
}  // namespace

// ================================================================ CavityVolumeTerm

CavityVolumeTerm::CavityVolumeTerm(const Mesh& mesh, const Partition& partition, int rank, CavityWallSpec wall)
    : mesh_(mesh), wall_(std::move(wall)) {
  check_cavity_axes(wall_.name, wall_.axes, wall_.open_axis);
  if (!(wall_.symmetry_factor >= 1.0))
    throw std::invalid_argument("cavity '" + wall_.name + "': symmetry_factor must be >= 1");
  n_axes_ = wall_.axes[0] + wall_.axes[1] + wall_.axes[2];
  std::vector<int> all;
  for (const auto& surface : wall_.surfaces) {
    auto f = mesh.faces_of(surface);
    all.insert(all.end(), f.begin(), f.end());
  }
  faces_ = owned_faces(mesh, partition, rank, all);
  table_ = make_triangle_table(mesh.order, 2 * mesh.order);  // exact (see cavity.cpp)
  // Reference volume from every wall face (each rank holds the whole mesh).
  const int n = mesh.nodes_per_face();
  Eigen::MatrixXd x(n, 3);
  double model = 0.0;
  for (int f : all) {
    for (int a = 0; a < n; ++a) x.row(a) = mesh.X.row(mesh.faces(f, a));
    model -= cavity_wall_integral(table_, wall_.axes, wall_.open_axis, x, x, nullptr, nullptr) / n_axes_;
  }
  reference_volume_ = wall_.symmetry_factor * model;
  if (!(reference_volume_ > 0))
    throw std::invalid_argument("cavity '" + wall_.name + "': the reference volume is not positive (" +
                                std::to_string(reference_volume_) +
                                " m^3): check the wall surfaces, their orientation and the volume axes");
  volume_ = converged_volume_ = reference_volume_;
}

void CavityVolumeTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int f = faces_[k];
  nodes.assign(mesh_.faces.row(f).data(), mesh_.faces.row(f).data() + mesh_.nodes_per_face());
}

// Meshed part's volume of face k: V_f = -(1/|S|) int (S x).(a x b), and its
// derivatives w.r.t. the face's nodal positions.
double CavityVolumeTerm::face_volume(int k, const Eigen::MatrixXd& x, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  Eigen::MatrixXd X(x.rows(), 3);
  for (Eigen::Index a = 0; a < x.rows(); ++a) X.row(a) = mesh_.X.row(mesh_.faces(faces_[k], a));
  const double f = cavity_wall_integral(table_, wall_.axes, wall_.open_axis, X, x, g, H);
  if (g) *g *= -1.0 / n_axes_;
  if (H) *H *= -1.0 / n_axes_;
  return -f / n_axes_;
}

// Volume of the meshed part [m^3] from this rank's ghosted displacement (collective).
double CavityVolumeTerm::meshed_volume(const Assembler& assembler, const std::vector<double>& u_local) const {
  return cavity_wall_volume(*this, mesh_, assembler, u_local, table_, wall_.axes, wall_.open_axis);
}

void CavityVolumeTerm::prepare(const Assembler& assembler, const std::vector<double>& u_local) {
  volume_ = wall_.symmetry_factor * meshed_volume(assembler, u_local);
}

double CavityVolumeTerm::model_volume_at(Assembler& assembler, Vec u) const {
  return meshed_volume(assembler, assembler.gather(u));
}

double CavityVolumeTerm::volume(Assembler& assembler, Vec u) const { return model_volume_at(assembler, u); }

double CavityVolumeTerm::local_model_volume(const RowMatrixXd& u_all) const {
  std::vector<int> nodes;
  Eigen::MatrixXd x;
  double sum = 0.0;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    x.resize(static_cast<Eigen::Index>(nodes.size()), 3);
    for (size_t a = 0; a < nodes.size(); ++a) x.row(a) = mesh_.X.row(nodes[a]) + u_all.row(nodes[a]);
    sum += face_volume(k, x, nullptr, nullptr);
  }
  return sum;
}

Eigen::VectorXd CavityVolumeTerm::local_volume_gradient(const RowMatrixXd& u_all) const {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(3 * mesh_.n_nodes());
  std::vector<int> nodes;
  Eigen::MatrixXd x;
  Eigen::VectorXd g;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    x.resize(static_cast<Eigen::Index>(nodes.size()), 3);
    for (size_t a = 0; a < nodes.size(); ++a) x.row(a) = mesh_.X.row(nodes[a]) + u_all.row(nodes[a]);
    face_volume(k, x, &g, nullptr);
    for (size_t a = 0; a < nodes.size(); ++a) v.segment<3>(3 * nodes[a]) += g.segment<3>(3 * a);
  }
  return v;
}

// Piece k (one wall face). The cavity energy E_m = Phi(V)/s is not a sum over
// faces; each face carries the share E_m V_f / V_m = Phi(V) V_f / V (the shares
// add up to E_m), and the exact gradient/sparse Hessian parts of the face:
//   g_f = Phi'(V) dV_f/du,   H_f = Phi'(V) d2V_f/du2,
// V (whole cavity) being the value reduced by prepare().
double CavityVolumeTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const double V = volume_;
  const double phi = energy_of_volume(V);
  if (!(V > 0) || !std::isfinite(phi)) return kInf;
  const Eigen::MatrixXd x = s.X + s.u;
  const double Vf = face_volume(k, x, g, H);
  const double dphi = energy_derivative(V);
  if (g) *g *= dphi;
  if (H) *H *= dphi;
  return phi * Vf / V;
}

// v = dV_m/du assembled over every rank's faces (zero on constrained dofs), and
// c = s Phi''(V) at u.
void CavityVolumeTerm::low_rank(Assembler& assembler, Vec u, std::vector<LowRank>& out) {
  const auto& ghost = assembler.gather(u);
  Vec v = assembler.create_vector();
  PETSC_CHECK(VecSetOption(v, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE));
  std::vector<int> nodes;
  std::vector<PetscInt> idx;
  Eigen::MatrixXd x;
  Eigen::VectorXd g;
  const auto& constrained = assembler.constrained();
  double local = 0.0;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    x.resize(static_cast<Eigen::Index>(nodes.size()), 3);
    idx.clear();
    for (size_t a = 0; a < nodes.size(); ++a) {
      const int slot = assembler.node_slot(nodes[a]);
      for (int i = 0; i < 3; ++i) {
        x(a, i) = mesh_.X(nodes[a], i) + ghost[3 * slot + i];
        const int dof = 3 * nodes[a] + i;
        idx.push_back(constrained[dof] ? -1 : dof);
      }
    }
    local += face_volume(k, x, &g, nullptr);
    PETSC_CHECK(VecSetValues(v, static_cast<PetscInt>(idx.size()), idx.data(), g.data(), ADD_VALUES));
  }
  PETSC_CHECK(VecAssemblyBegin(v));
  PETSC_CHECK(VecAssemblyEnd(v));
  double total = 0.0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, assembler.comm());
  const double V = wall_.symmetry_factor * total;
  const double c = wall_.symmetry_factor * energy_second_derivative(V);
  out.push_back({v, std::isfinite(c) ? c : 0.0});
}

// V(u + alpha du) is a cubic in alpha (the face integrand is cubic in the nodal
// positions): sampled at 4 points it is known exactly; the step stops at 90 % of
// the way to its first zero.
double CavityVolumeTerm::max_step(Assembler& assembler, Vec u, Vec du) {
  Vec w;
  PETSC_CHECK(VecDuplicate(u, &w));
  double f[4];
  for (int i = 0; i < 4; ++i) {
    PETSC_CHECK(VecWAXPY(w, i / 3.0, du, u));
    f[i] = model_volume_at(assembler, w);
  }
  PETSC_CHECK(VecDestroy(&w));
  if (!(f[0] > 0)) return 1.0;  // already outside: let the line search reject it
  const double a = first_nonpositive(f[0], f[1], f[2], f[3]);
  return a > 1.0 ? 1.0 : 0.9 * a;
}

// ================================================================ GasCavityTerm

GasCavityTerm::GasCavityTerm(const Mesh& mesh, const Partition& partition, int rank, GasCavitySpec spec)
    : CavityVolumeTerm(mesh, partition, rank, spec.wall), spec_(std::move(spec)) {
  if (!(spec_.temperature > 0))
    throw std::invalid_argument("gas cavity '" + wall_.name + "': temperature must be > 0 K");
  if (!(spec_.atmospheric_pressure >= 0))
    throw std::invalid_argument("gas cavity '" + wall_.name + "': atmospheric_pressure must be >= 0 Pa");
  if (!std::isnan(spec_.fill_time)) {
    if (!(spec_.fill_time > 0)) throw std::invalid_argument("gas cavity '" + wall_.name + "': fill_time must be > 0 s");
    if (!(reference_volume_ > 0))
      throw std::invalid_argument("gas cavity '" + wall_.name + "': fill_time needs a reference volume > 0");
    spec_.conductance = TimeFunction::constant(time_constant(reference_volume_, 1.0) / spec_.fill_time);
  }
  if (std::isnan(spec_.initial_amount)) {
    const double p0 = spec_.atmospheric_pressure + spec_.initial_gauge_pressure;
    if (!(p0 > 0))
      throw std::invalid_argument("gas cavity '" + wall_.name + "': initial absolute pressure must be > 0 Pa");
    amount_ = p0 * reference_volume_ / (kGasConstant * spec_.temperature);
  } else {
    amount_ = spec_.initial_amount;
  }
  set_amount(amount_);
}

void GasCavityTerm::set_amount(double n) {
  if (!(n > 0)) throw std::invalid_argument("gas cavity '" + wall_.name + "': gas amount must be > 0 mol");
  amount_ = step_amount_ = n;
  reservoir_ = 0.0;
}

void GasCavityTerm::set_time(double t) {
  if (t <= converged_time_) {
    step_amount_ = amount_;
    reservoir_ = 0.0;
  }
}

void GasCavityTerm::begin_step(Assembler&, Vec, double t0, double t1) { begin_valve_step(t0, t1); }

void GasCavityTerm::end_step(Assembler& assembler, Vec u1, double t1) {
  end_valve_step(wall_.symmetry_factor * model_volume_at(assembler, u1), t1);
}

void GasCavityTerm::begin_valve_step(double t0, double t1) {
  const double dt = t1 - t0;
  const double C = spec_.conductance_at(t1);
  const double supply = spec_.atmospheric_pressure + spec_.supply_gauge_pressure(t1);  // absolute [Pa]
  if (!(C >= 0)) throw std::invalid_argument("gas cavity '" + wall_.name + "': conductance must be >= 0");
  if (!(supply >= 0))
    throw std::invalid_argument("gas cavity '" + wall_.name + "': supply gauge pressure " +
                                std::to_string(spec_.supply_gauge_pressure(t1)) + " Pa is below vacuum");
  // Backward Euler: m = n0 + dt C p_supply, V_r = dt C R T (see the header).
  step_dt_ = dt;
  step_amount_ = amount_ + dt * C * supply;
  reservoir_ = dt * C * kGasConstant * spec_.temperature;
}

void GasCavityTerm::end_valve_step(double V1, double t1) {
  const double n1 = step_amount_ * V1 / (V1 + reservoir_);
  flow_rate_ = step_dt_ > 0 ? (n1 - amount_) / step_dt_ : 0.0;
  amount_ = step_amount_ = n1;
  reservoir_ = 0.0;
  volume_ = converged_volume_ = V1;
  converged_time_ = t1;
}

// Phi(V) = -m R T ln((V + V_r)/V_0) + p_atm (V - V_0)
double GasCavityTerm::energy_of_volume(double V) const {
  if (!(V > 0)) return kInf;
  const double RT = kGasConstant * spec_.temperature;
  return -step_amount_ * RT * std::log((V + reservoir_) / reference_volume_) +
         spec_.atmospheric_pressure * (V - reference_volume_);
}

// Phi'(V) = -(m R T / (V + V_r) - p_atm) = -(gauge pressure)
double GasCavityTerm::energy_derivative(double V) const {
  return -(step_amount_ * kGasConstant * spec_.temperature / (V + reservoir_) - spec_.atmospheric_pressure);
}

// Phi''(V) = m R T / (V + V_r)^2
double GasCavityTerm::energy_second_derivative(double V) const {
  const double d = V + reservoir_;
  return step_amount_ * kGasConstant * spec_.temperature / (d * d);
}

double GasCavityTerm::absolute_pressure() const {
  return amount_ * kGasConstant * spec_.temperature / converged_volume_;
}

// ===================================================== VolumeControlledCavityTerm

VolumeControlledCavityTerm::VolumeControlledCavityTerm(const Mesh& mesh, const Partition& partition, int rank,
                                                       VolumeControlSpec spec)
    : CavityVolumeTerm(mesh, partition, rank, spec.wall), spec_(std::move(spec)) {
  if (!(spec_.penalty_modulus > 0))
    throw std::invalid_argument("volume-controlled cavity '" + wall_.name + "': penalty_modulus must be > 0 Pa");
  if (!(spec_.tolerance > 0))
    throw std::invalid_argument("volume-controlled cavity '" + wall_.name + "': tolerance must be > 0");
  if (spec_.volume_is_ratio) {
    std::vector<std::pair<double, double>> points = spec_.volume.points();
    for (auto& [t, v] : points) v *= reference_volume_;
    spec_.volume = TimeFunction(points);
    spec_.volume_is_ratio = false;
  }
  base_penalty_ = penalty_ = spec_.penalty_modulus / reference_volume_;
  history_.push_back({reference_volume_, 0.0});
  set_time(0.0);
}

void VolumeControlledCavityTerm::set_time(double t) {
  target_ = spec_.volume(t);
  if (t <= converged_time_) multiplier_ = converged_pressure_;
}

void VolumeControlledCavityTerm::begin_step(Assembler&, Vec, double, double t1) {
  target_ = spec_.volume(t1);
  has_previous_solve_ = false;
  const auto [V1, p1] = history_.back();
  multiplier_ = p1;
  penalty_ = base_penalty_;
  if (history_.size() == 2) {
    const auto [V0, p0] = history_.front();
    if (std::abs(V1 - V0) > 1e-9 * V1) {
      // Secant slope K_s of the equilibrium p-V curve: predictor and penalty.
      const double Ks = (p1 - p0) / (V1 - V0);
      multiplier_ = p1 + Ks * (target_ - V1);
      penalty_ = std::max(base_penalty_, 10.0 * std::abs(Ks));
    }
  }
}

bool VolumeControlledCavityTerm::update_after_solve(Assembler& assembler, Vec u1) {
  const double V = wall_.symmetry_factor * model_volume_at(assembler, u1);
  const double e = V - target_;
  if (std::abs(e) <= spec_.tolerance * std::abs(target_)) return false;
  // First update of a step: lambda <- p = lambda - k (V - V*). Later ones: secant on
  // the smooth, increasing map lambda -> V(lambda) (slope 1/(K_s + k)) through the
  // last two solves, which converges superlinearly instead of by K_s/(K_s + k).
  double next = multiplier_ - penalty_ * e;
  if (has_previous_solve_ && std::abs(V - previous_volume_) > 1e-14 * std::abs(target_)) {
    const double secant = multiplier_ - e * (multiplier_ - previous_multiplier_) / (V - previous_volume_);
    if (std::isfinite(secant)) next = secant;
  }
  has_previous_solve_ = true;
  previous_multiplier_ = multiplier_;
  previous_volume_ = V;
  multiplier_ = next;
  ++outer_updates_;
  return true;
}

void VolumeControlledCavityTerm::end_step(Assembler& assembler, Vec u1, double t1) {
  const double V1 = wall_.symmetry_factor * model_volume_at(assembler, u1);
  converged_pressure_ = multiplier_ - penalty_ * (V1 - target_);
  volume_ = converged_volume_ = V1;
  converged_time_ = t1;
  history_.push_back({V1, converged_pressure_});
  if (history_.size() > 2) history_.erase(history_.begin());
}

// Phi(V) = -lambda (V - V*) + k/2 (V - V*)^2; +inf for V <= 0.
double VolumeControlledCavityTerm::energy_of_volume(double V) const {
  if (!(V > 0)) return kInf;
  const double e = V - target_;
  return -multiplier_ * e + 0.5 * penalty_ * e * e;
}

double VolumeControlledCavityTerm::energy_derivative(double V) const { return -multiplier_ + penalty_ * (V - target_); }

// ---------------------------------------------------------------- checkpoints

void CavityVolumeTerm::save_volumes(const std::string& prefix, StateRecord& state) const {
  state.set_number(prefix + ".volume", volume_);
  state.set_number(prefix + ".converged_volume", converged_volume_);
  state.set_number(prefix + ".converged_time", converged_time_);
}

void CavityVolumeTerm::load_volumes(const std::string& prefix, const StateRecord& state) {
  const std::string where = "checkpoint: " + prefix;
  volume_ = state.number(prefix + ".volume", where);
  converged_volume_ = state.number(prefix + ".converged_volume", where);
  converged_time_ = state.number(prefix + ".converged_time", where);
}

void GasCavityTerm::save_state(Assembler&, const std::string& prefix, StateRecord& state) {
  save_volumes(prefix, state);
  state.set_number(prefix + ".amount", amount_);
  state.set_number(prefix + ".flow_rate", flow_rate_);
  state.set_number(prefix + ".step_dt", step_dt_);
}

void GasCavityTerm::load_state(Assembler&, const std::string& prefix, const StateRecord& state) {
  const std::string where = "checkpoint: " + prefix;
  load_volumes(prefix, state);
  amount_ = step_amount_ = state.number(prefix + ".amount", where);
  reservoir_ = 0.0;  // between steps (as after end_valve_step)
  flow_rate_ = state.number(prefix + ".flow_rate", where);
  step_dt_ = state.number(prefix + ".step_dt", where);
}

void VolumeControlledCavityTerm::save_state(Assembler&, const std::string& prefix, StateRecord& state) {
  save_volumes(prefix, state);
  state.set_number(prefix + ".multiplier", multiplier_);
  state.set_number(prefix + ".penalty", penalty_);
  state.set_number(prefix + ".converged_pressure", converged_pressure_);
  state.integers[prefix + ".outer_updates"] = outer_updates_;
  std::vector<double> history;
  for (const auto& [V, p] : history_) history.insert(history.end(), {V, p});
  state.arrays[prefix + ".history"] = history;
}

void VolumeControlledCavityTerm::load_state(Assembler&, const std::string& prefix, const StateRecord& state) {
  const std::string where = "checkpoint: " + prefix;
  load_volumes(prefix, state);
  multiplier_ = state.number(prefix + ".multiplier", where);
  penalty_ = state.number(prefix + ".penalty", where);
  converged_pressure_ = state.number(prefix + ".converged_pressure", where);
  outer_updates_ = static_cast<int>(state.integer(prefix + ".outer_updates", where));
  const auto& history = state.array(prefix + ".history", where);
  if (history.empty() || history.size() > 4 || history.size() % 2)
    throw InputError(where, "volume history has " + std::to_string(history.size()) + " values, expected 2 or 4");
  history_.clear();
  for (size_t i = 0; i < history.size(); i += 2) history_.push_back({history[i], history[i + 1]});
  has_previous_solve_ = false;
}

}  // namespace morphfem
