#include "fem/damping.h"

#include <mpi.h>

#include <stdexcept>

#include "core/errors.h"
#include "fem/assembly.h"
#include "fem/kinematics.h"
#include "fem/term_state.h"

namespace morphfem {

namespace {

Mat3 deviator(const Mat3& A) { return A - A.trace() / 3.0 * Mat3::Identity(); }

}  // namespace

std::vector<Mat3> green_lagrange_at_points(const ShapeTable& table, const Eigen::MatrixXd& X,
                                           const Eigen::MatrixXd& u) {
  std::vector<Mat3> E(table.points.size());
  Eigen::MatrixXd dN_dX;
  for (size_t q = 0; q < table.points.size(); ++q) {
    physical_gradients(X, table.dN[q], dN_dX);
    const Mat3 F = Mat3::Identity() + u.transpose() * dN_dX;
    E[q] = 0.5 * (F.transpose() * F - Mat3::Identity());
  }
  return E;
}

// Per point, dE = E(F) - E*, h = h_eff:
//   D   = eta/h |dev dE|^2 + zeta/(2h) (tr dE)^2                 [Pa]
//   S_v = 2 eta/h dev dE + zeta/h tr(dE) I,  P_v = F S_v         [Pa]
//   dP_v = dF S_v + F dS_v,  dS_v = 2 eta/h dev dE' + zeta/h tr(dE') I,
//   dE' = sym(F^T dF)                                            (tangent, column by column)
double viscous_damping_kernel(const ShapeTable& table, const Eigen::MatrixXd& X, const Eigen::MatrixXd& u,
                              const std::vector<Mat3>& E_star, double eta, double zeta, double h_eff,
                              Eigen::VectorXd* g, Eigen::MatrixXd* H) {
  const double h = h_eff;
  const int n = static_cast<int>(X.rows());
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  const double a = 2.0 * eta / h, b = zeta / h;
  auto viscous_stress = [&](const Mat3& dE) -> Mat3 { return a * deviator(dE) + b * dE.trace() * Mat3::Identity(); };
  Eigen::MatrixXd dN_dX, B;
  double energy = 0.0;
  for (size_t q = 0; q < table.points.size(); ++q) {
    const double dV = table.points[q].weight * physical_gradients(X, table.dN[q], dN_dX);
    const Mat3 F = Mat3::Identity() + u.transpose() * dN_dX;
    const Mat3 dE = 0.5 * (F.transpose() * F - Mat3::Identity()) - E_star[q];
    const double trace = dE.trace();
    energy += dV * (eta / h * deviator(dE).squaredNorm() + 0.5 * b * trace * trace);
    if (!g && !H) continue;
    const Mat3 S = viscous_stress(dE);
    deformation_gradient_map(dN_dX, B);  // dF/du
    if (g) *g += dV * B.transpose() * flatten(F * S);
    if (H) {
      Tangent A;
      for (int k = 0; k < 3; ++k)
        for (int L = 0; L < 3; ++L) {
          Mat3 dF = Mat3::Zero();
          dF(k, L) = 1.0;
          const Mat3 FtdF = F.transpose() * dF;
          const Mat3 dS = viscous_stress(0.5 * (FtdF + FtdF.transpose()));
          A.col(3 * k + L) = flatten(dF * S + F * dS);
        }
      H->noalias() += dV * B.transpose() * A * B;
    }
  }
  return energy;
}

DampingTerm::DampingTerm(const Mesh& mesh, const Partition& partition, int rank, std::vector<double> shear_viscosity,
                         std::vector<double> bulk_viscosity, std::shared_ptr<const TimeIntegrator> integrator,
                         int quadrature_degree)
    : mesh_(mesh), integrator_(std::move(integrator)) {
  if (!integrator_) throw std::invalid_argument("damping: needs the time integrator");
  for (int c = 0; c < mesh.n_cells(); ++c) {
    if (partition.cell_part[c] != rank) continue;
    const int region = mesh.cell_region[c];
    const double eta = shear_viscosity.at(region);
    const double zeta = bulk_viscosity.empty() ? 0.0 : bulk_viscosity.at(region);
    if (eta < 0 || zeta < 0)
      throw std::invalid_argument("damping: negative viscosity in region '" + mesh.regions[region].name + "'");
    if (eta == 0 && zeta == 0) continue;
    cells_.push_back(c);
    eta_.push_back(eta);
    zeta_.push_back(zeta);
  }
  table_ = make_tet_table(mesh.order, quadrature_degree > 0 ? quadrature_degree : (mesh.order == 1 ? 1 : 2));
}

void DampingTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int c = cells_[k];
  nodes.assign(mesh_.cells.row(c).data(), mesh_.cells.row(c).data() + mesh_.nodes_per_cell());
}

double DampingTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  if (E_star_.empty()) {  // no step begun: no dissipation
    const int n = static_cast<int>(s.u.rows());
    if (g) g->setZero(3 * n);
    if (H) H->setZero(3 * n, 3 * n);
    return 0.0;
  }
  return viscous_damping_kernel(table_, s.X, s.u, E_star_[k], eta_[k], zeta_[k], rule_.h / rule_.kappa, g, H);
}

namespace {
// Reference coordinates and displacement of one piece from the assembler's ghost array.
void piece_state(const Mesh& mesh, const Assembler& assembler, const std::vector<double>& local,
                 const std::vector<int>& nodes, Eigen::MatrixXd& X, Eigen::MatrixXd& u) {
  const int n = static_cast<int>(nodes.size());
  X.resize(n, 3);
  u.resize(n, 3);
  for (int a = 0; a < n; ++a) {
    const int slot = assembler.node_slot(nodes[a]);
    for (int i = 0; i < 3; ++i) {
      X(a, i) = mesh.X(nodes[a], i);
      u(a, i) = local[3 * slot + i];
    }
  }
}
}  // namespace

void DampingTerm::begin_step(Assembler& assembler, Vec u0, double t0, double t1) {
  if (!(t1 - t0 > 0)) throw std::invalid_argument("damping: the time step must be positive");
  rule_ = integrator_->rate_rule(t1 - t0, h_prev_, steps_done_ > 0);
  const std::vector<double>& local = assembler.gather(u0);
  E_n_.resize(cells_.size());
  E_star_.resize(cells_.size());
  std::vector<int> nodes;
  Eigen::MatrixXd X, u;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    piece_state(mesh_, assembler, local, nodes, X, u);
    E_n_[k] = green_lagrange_at_points(table_, X, u);
    E_star_[k] = E_n_[k];
    if (!rule_.uses_history()) continue;
    for (size_t q = 0; q < E_n_[k].size(); ++q) E_star_[k][q] = rule_.anchor(E_n_[k][q], E_nm1_[k][q], Edot_n_[k][q]);
  }
}

void DampingTerm::end_step(Assembler& assembler, Vec u1, double /*t1*/) {
  const std::vector<double>& local = assembler.gather(u1);
  Edot_n_.resize(cells_.size());
  E_nm1_.resize(cells_.size());
  std::vector<int> nodes;
  Eigen::MatrixXd X, u, dN_dX;
  double sum = 0.0;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    piece_state(mesh_, assembler, local, nodes, X, u);
    const std::vector<Mat3> E1 = green_lagrange_at_points(table_, X, u);
    std::vector<Mat3> Edot1(E1.size());
    for (size_t q = 0; q < E1.size(); ++q) {
      Edot1[q] = rule_.rate(E1[q], E_star_[k][q]);
      // Viscous stress of the rate that does the work: S_v(Edot) = 2 eta dev Edot + zeta tr(Edot) I
      // (Edot_n exists where the rule uses the history).
      const Mat3 rate = rule_.uses_history() ? rule_.work_rate(Edot_n_[k][q], Edot1[q]) : Edot1[q];
      const Mat3 S = 2 * eta_[k] * deviator(rate) + zeta_[k] * rate.trace() * Mat3::Identity();
      const double dV = table_.points[q].weight * physical_gradients(X, table_.dN[q], dN_dX);
      sum += dV * (S.array() * (E1[q] - E_n_[k][q]).array()).sum();
    }
    Edot_n_[k] = std::move(Edot1);
    E_nm1_[k] = E_n_[k];
  }
  MPI_Allreduce(&sum, &last_dissipated_, 1, MPI_DOUBLE, MPI_SUM, assembler.comm());
  total_dissipated_ += last_dissipated_;
  h_prev_ = rule_.h;
  ++steps_done_;
}

namespace {
// Per piece, per point 3x3 tensors <-> one flat array (9 values per point, column-major).
std::vector<double> flatten(const std::vector<std::vector<Mat3>>& tensors) {
  std::vector<double> out;
  for (const auto& piece : tensors)
    for (const Mat3& m : piece) out.insert(out.end(), m.data(), m.data() + 9);
  return out;
}

void unflatten(const std::vector<double>& flat, std::vector<std::vector<Mat3>>& tensors, int n_pieces, int points,
               const std::string& where) {
  if (flat.size() != static_cast<size_t>(n_pieces) * points * 9)
    throw InputError(where, "damping history has " + std::to_string(flat.size()) + " values, expected " +
                                std::to_string(static_cast<size_t>(n_pieces) * points * 9));
  tensors.assign(n_pieces, std::vector<Mat3>(points));
  for (int k = 0; k < n_pieces; ++k)
    for (int q = 0; q < points; ++q)
      tensors[k][q] = Eigen::Map<const Mat3>(&flat[(static_cast<size_t>(k) * points + q) * 9]);
}
}  // namespace

void DampingTerm::save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) {
  state.integers[prefix + ".steps_done"] = steps_done_;
  state.set_number(prefix + ".h_prev", h_prev_);
  state.set_number(prefix + ".last_dissipated", last_dissipated_);
  state.set_number(prefix + ".total_dissipated", total_dissipated_);
  save_rank_data(assembler.comm(), flatten(Edot_n_), prefix + ".Edot_n", state);
  save_rank_data(assembler.comm(), flatten(E_nm1_), prefix + ".E_nm1", state);
}

void DampingTerm::load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) {
  const std::string where = "checkpoint: " + prefix;
  steps_done_ = static_cast<int>(state.integer(prefix + ".steps_done", where));
  h_prev_ = state.number(prefix + ".h_prev", where);
  last_dissipated_ = state.number(prefix + ".last_dissipated", where);
  total_dissipated_ = state.number(prefix + ".total_dissipated", where);
  const auto edot = load_rank_data(assembler.comm(), state, prefix + ".Edot_n", where);
  const auto e_nm1 = load_rank_data(assembler.comm(), state, prefix + ".E_nm1", where);
  const int points = static_cast<int>(table_.points.size());
  if (edot.empty() && e_nm1.empty()) {  // no step yet on this rank's pieces
    Edot_n_.clear();
    E_nm1_.clear();
    return;
  }
  unflatten(edot, Edot_n_, n_pieces(), points, where);
  unflatten(e_nm1, E_nm1_, n_pieces(), points, where);
}

}  // namespace morphfem
