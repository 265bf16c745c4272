#include "fem/inertia.h"

#include <petscksp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fem/assembly.h"
#include "fem/petsc_check.h"
#include "fem/term_state.h"

namespace morphfem {

const std::map<std::string, TimeScheme>& time_schemes() {
  static const std::map<std::string, TimeScheme> table{{"implicit_euler", TimeScheme::implicit_euler},
                                                       {"bdf1", TimeScheme::implicit_euler},
                                                       {"bdf2", TimeScheme::bdf2},
                                                       {"newmark", TimeScheme::newmark}};
  return table;
}

ShapeTable make_mass_table(int order) { return make_tet_table(order, order == 1 ? 2 : 6); }

// M_ab = rho sum_q w_q det(J0_q) N_a(xi_q) N_b(xi_q) [kg]; HRZ lumping keeps the
// diagonal, scaled so that it sums to the element mass rho V.
Eigen::MatrixXd element_mass_matrix(const ShapeTable& table, const Eigen::MatrixXd& X, double density, bool lumped) {
  const int n = static_cast<int>(X.rows());
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (size_t q = 0; q < table.points.size(); ++q) {
    const Eigen::Matrix3d J0 = X.transpose() * table.dN[q];
    const double dV = table.points[q].weight * J0.determinant();
    M.noalias() += (density * dV) * table.N[q] * table.N[q].transpose();
  }
  if (lumped) {
    const double total = M.sum();
    const Eigen::VectorXd diagonal = M.diagonal();
    M = (diagonal * (total / diagonal.sum())).asDiagonal();
  }
  return M;
}

double inertia_kernel(const Eigen::MatrixXd& mass, double c, const Eigen::MatrixXd& w, Eigen::VectorXd* g,
                      Eigen::MatrixXd* H) {
  const int n = static_cast<int>(w.rows());
  const Eigen::MatrixXd Mw = mass * w;  // n x 3 [kg m]
  if (g) {
    g->resize(3 * n);
    for (int a = 0; a < n; ++a)
      for (int i = 0; i < 3; ++i) (*g)[3 * a + i] = c * Mw(a, i);
  }
  if (H) {
    H->setZero(3 * n, 3 * n);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (int i = 0; i < 3; ++i) (*H)(3 * a + i, 3 * b + i) = c * mass(a, b);
  }
  return 0.5 * c * w.cwiseProduct(Mw).sum();
}

InertiaTerm::InertiaTerm(const Mesh& mesh, const Partition& partition, int rank, std::vector<double> density,
                         InertiaOptions options)
    : mesh_(mesh), opt_(options) {
  if (!(opt_.newmark_beta > 0 && opt_.newmark_beta <= 0.5))
    throw std::invalid_argument("inertia: newmark beta must be in (0, 1/2]");
  if (!(opt_.newmark_gamma >= 0.5 && opt_.newmark_gamma <= 1.0))
    throw std::invalid_argument("inertia: newmark gamma must be in [1/2, 1]");
  if (!(opt_.error_tolerance > 0)) throw std::invalid_argument("inertia: error_tolerance must be positive");
  const ShapeTable table = make_mass_table(mesh.order);
  const int n = mesh.nodes_per_cell();
  Eigen::MatrixXd X(n, 3);
  for (int c = 0; c < mesh.n_cells(); ++c) {
    if (partition.cell_part[c] != rank) continue;
    const double rho = density.at(mesh.cell_region[c]);
    if (rho < 0)
      throw std::invalid_argument("inertia: negative density in region '" + mesh.regions[mesh.cell_region[c]].name +
                                  "'");
    if (rho == 0) continue;
    for (int a = 0; a < n; ++a) X.row(a) = mesh.X.row(mesh.cells(c, a));
    cells_.push_back(c);
    mass_.push_back(element_mass_matrix(table, X, rho, opt_.lumped));
  }
}

InertiaTerm::~InertiaTerm() {
  for (Vec* v : {&u_n_, &v_n_, &a_n_, &u_nm1_, &v_nm1_, &pred_, &v_new_, &a_new_, &err_})
    if (*v) VecDestroy(v);
}

void InertiaTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int c = cells_[k];
  nodes.assign(mesh_.cells.row(c).data(), mesh_.cells.row(c).data() + mesh_.nodes_per_cell());
}

double InertiaTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  if (suppressed_ || pred_piece_.empty()) {
    const int n = static_cast<int>(s.u.rows());
    if (g) g->setZero(3 * n);
    if (H) H->setZero(3 * n, 3 * n);
    return 0.0;
  }
  return inertia_kernel(mass_[k], c_, s.u - pred_piece_[k], g, H);
}

void InertiaTerm::set_initial_velocity(std::function<Eigen::Vector3d(const Eigen::Vector3d& X)> v0) {
  if (initialized()) throw std::logic_error("inertia: the initial velocity must be set before the first step");
  v0_ = std::move(v0);
}

void InertiaTerm::allocate(Assembler& assembler) {
  for (Vec* v : {&u_n_, &v_n_, &a_n_, &u_nm1_, &v_nm1_, &pred_, &v_new_, &a_new_, &err_})
    if (!*v) *v = assembler.create_vector();
}

void InertiaTerm::initialize(Assembler& assembler, Vec u0, double t0) {
  if (initialized()) return;
  allocate(assembler);
  PETSC_CHECK(VecCopy(u0, u_n_));
  PETSC_CHECK(VecCopy(u0, u_nm1_));
  // v_0 = v0(X) on the free dofs; constrained dofs start at rest.
  if (v0_) {
    PetscScalar* a;
    PETSC_CHECK(VecGetArray(v_n_, &a));
    const PetscInt begin = assembler.owned_dof_begin();
    for (PetscInt node = begin / 3; node < assembler.owned_dof_end() / 3; ++node) {
      const Eigen::Vector3d v = v0_(mesh_.X.row(node).transpose());
      for (int i = 0; i < 3; ++i)
        if (!assembler.constrained()[3 * node + i]) a[3 * node + i - begin] = v[i];
    }
    PETSC_CHECK(VecRestoreArray(v_n_, &a));
  }
  PETSC_CHECK(VecCopy(v_n_, v_nm1_));
  steps_done_ = 0;
  h_prev_ = 0.0;
  have_a0_ = false;
  if (opt_.equilibrium_initial_acceleration && opt_.scheme != TimeScheme::implicit_euler) {
    equilibrium_acceleration(assembler, u0, t0);
    have_a0_ = true;
  }
}

// a_0 from M a_0 = f(u_0, t_0) = -(gradient of every other term at t_0) [m/s^2]:
// CG + Jacobi on the assembled mass matrix (identity rows on constrained dofs,
// where a_0 = 0). Leaves every term's time at t0.
void InertiaTerm::equilibrium_acceleration(Assembler& assembler, Vec u0, double t0) {
  for (const auto& term : assembler.terms()) term->set_time(t0);
  Vec force = assembler.create_vector();
  suppressed_ = true;
  try {
    assembler.gradient(u0, force);
  } catch (...) {
    suppressed_ = false;
    VecDestroy(&force);
    throw;
  }
  suppressed_ = false;
  PETSC_CHECK(VecScale(force, -1.0));

  Mat M = assembler.create_matrix();
  PETSC_CHECK(MatZeroEntries(M));
  std::vector<int> nodes;
  std::vector<PetscInt> idx;
  const auto& constrained = assembler.constrained();
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    idx.clear();
    for (int node : nodes)
      for (int i = 0; i < 3; ++i) idx.push_back(constrained[3 * node + i] ? -1 : 3 * node + i);
    Eigen::MatrixXd Me;
    inertia_kernel(mass_[k], 1.0, Eigen::MatrixXd::Zero(static_cast<int>(nodes.size()), 3), nullptr, &Me);
    const PetscInt m = static_cast<PetscInt>(idx.size());
    PETSC_CHECK(MatSetValues(M, m, idx.data(), m, idx.data(), Me.data(), ADD_VALUES));
  }
  for (PetscInt d = assembler.owned_dof_begin(); d < assembler.owned_dof_end(); ++d)
    if (constrained[d]) PETSC_CHECK(MatSetValue(M, d, d, 1.0, ADD_VALUES));
  PETSC_CHECK(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY));
  PETSC_CHECK(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY));

  KSP ksp;
  PC pc;
  PETSC_CHECK(KSPCreate(assembler.comm(), &ksp));
  PETSC_CHECK(KSPSetOperators(ksp, M, M));
  PETSC_CHECK(KSPSetType(ksp, KSPCG));
  PETSC_CHECK(KSPGetPC(ksp, &pc));
  PETSC_CHECK(PCSetType(pc, PCJACOBI));
  PETSC_CHECK(KSPSetTolerances(ksp, 1e-14, 1e-300, PETSC_DEFAULT, 2000));
  PETSC_CHECK(KSPSolve(ksp, force, a_n_));
  KSPConvergedReason reason;
  PETSC_CHECK(KSPGetConvergedReason(ksp, &reason));
  PETSC_CHECK(KSPDestroy(&ksp));
  PETSC_CHECK(MatDestroy(&M));
  PETSC_CHECK(VecDestroy(&force));
  if (reason < 0) throw std::runtime_error("inertia: the mass-matrix solve for the initial acceleration failed");
}

void InertiaTerm::begin_step(Assembler& assembler, Vec u0, double t0, double t1) {
  if (!initialized()) {
    initialize(assembler, u0, t0);
    for (const auto& term : assembler.terms()) term->set_time(t1);
  }
  h_ = t1 - t0;
  if (!(h_ > 0)) throw std::invalid_argument("inertia: the time step must be positive");
  const double h = h_;
  PetscScalar coeff[4];
  Vec vecs[4];
  int count = 0;
  if (opt_.scheme == TimeScheme::implicit_euler || (opt_.scheme == TimeScheme::bdf2 && steps_done_ == 0 && !have_a0_)) {
    // u_pred = u_n + h v_n, c = 1/h^2
    kind_ = StepKind::implicit_euler;
    c_ = 1.0 / (h * h);
    coeff[0] = 1.0, vecs[0] = u_n_;
    coeff[1] = h, vecs[1] = v_n_;
    count = 2;
  } else if (opt_.scheme == TimeScheme::newmark || steps_done_ == 0 || h > kBdf2MaxStepRatio * h_prev_) {
    // u_pred = u_n + h v_n + h^2 (1/2 - beta) a_n, c = 1/(beta h^2); the first bdf2
    // step and one that grows too much are trapezoidal (beta = 1/4, gamma = 1/2).
    kind_ = StepKind::newmark;
    const bool own = opt_.scheme == TimeScheme::newmark;
    beta_ = own ? opt_.newmark_beta : 0.25;
    gamma_ = own ? opt_.newmark_gamma : 0.5;
    c_ = 1.0 / (beta_ * h * h);
    coeff[0] = 1.0, vecs[0] = u_n_;
    coeff[1] = h, vecs[1] = v_n_;
    coeff[2] = h * h * (0.5 - beta_), vecs[2] = a_n_;
    count = 3;
  } else {
    kind_ = StepKind::bdf2;
    w_ = h / h_prev_;
    const double alpha0 = (1 + 2 * w_) / (1 + w_), alpha1 = -(1 + w_), alpha2 = w_ * w_ / (1 + w_);
    c_ = alpha0 * alpha0 / (h * h);
    coeff[0] = -alpha1 / alpha0, vecs[0] = u_n_;
    coeff[1] = -alpha2 / alpha0, vecs[1] = u_nm1_;
    coeff[2] = -h * alpha1 / (alpha0 * alpha0), vecs[2] = v_n_;
    coeff[3] = -h * alpha2 / (alpha0 * alpha0), vecs[3] = v_nm1_;
    count = 4;
  }
  PETSC_CHECK(VecSet(pred_, 0.0));
  PETSC_CHECK(VecMAXPY(pred_, count, coeff, vecs));

  // Per-piece copy of the prediction (ghost values included).
  const std::vector<double>& local = assembler.gather(pred_);
  pred_piece_.resize(cells_.size());
  std::vector<int> nodes;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    Eigen::MatrixXd& p = pred_piece_[k];
    p.resize(static_cast<int>(nodes.size()), 3);
    for (size_t a = 0; a < nodes.size(); ++a) {
      const int slot = assembler.node_slot(nodes[a]);
      if (slot < 0) throw std::logic_error("inertia: piece node missing from the assembler (call setup first)");
      for (int i = 0; i < 3; ++i) p(static_cast<int>(a), i) = local[3 * slot + i];
    }
  }
}

// v_{n+1} and a_{n+1} of the current step from its converged displacement u1.
void InertiaTerm::step_accelerations(Vec u1, Vec v1, Vec a1) {
  const double h = h_;
  switch (kind_) {
    case StepKind::implicit_euler:  // v1 = (u1 - u_n)/h, a1 = (v1 - v_n)/h
      PETSC_CHECK(VecWAXPY(v1, -1.0, u_n_, u1));
      PETSC_CHECK(VecScale(v1, 1.0 / h));
      PETSC_CHECK(VecWAXPY(a1, -1.0, v_n_, v1));
      PETSC_CHECK(VecScale(a1, 1.0 / h));
      break;
    case StepKind::newmark:  // a1 = c (u1 - u_pred), v1 = v_n + h ((1 - gamma) a_n + gamma a1)
      PETSC_CHECK(VecWAXPY(a1, -1.0, pred_, u1));
      PETSC_CHECK(VecScale(a1, c_));
      PETSC_CHECK(VecCopy(v_n_, v1));
      PETSC_CHECK(VecAXPBYPCZ(v1, h * (1 - gamma_), h * gamma_, 1.0, a_n_, a1));
      break;
    case StepKind::bdf2: {  // v1 = (alpha0 u1 + alpha1 u_n + alpha2 u_{n-1})/h, a1 likewise from v
      const double alpha0 = (1 + 2 * w_) / (1 + w_), alpha1 = -(1 + w_), alpha2 = w_ * w_ / (1 + w_);
      PETSC_CHECK(VecCopy(u1, v1));
      PETSC_CHECK(VecScale(v1, alpha0 / h));
      PETSC_CHECK(VecAXPBYPCZ(v1, alpha1 / h, alpha2 / h, 1.0, u_n_, u_nm1_));
      PETSC_CHECK(VecCopy(v1, a1));
      PETSC_CHECK(VecScale(a1, alpha0 / h));
      PETSC_CHECK(VecAXPBYPCZ(a1, alpha1 / h, alpha2 / h, 1.0, v_n_, v_nm1_));
      break;
    }
  }
}

// Local truncation error estimate (see the header) on the free dofs [m] and the
// step that would meet the tolerance.
double InertiaTerm::error_of(Assembler& assembler, Vec v1, Vec a1, double& dt_next) {
  const double h = h_;
  int order = 2;
  if (kind_ == StepKind::implicit_euler) {  // e = h/2 (v1 - v_n)
    order = 1;
    PETSC_CHECK(VecWAXPY(err_, -1.0, v_n_, v1));
    PETSC_CHECK(VecScale(err_, 0.5 * h));
  } else {
    const double constant =
        kind_ == StepKind::newmark ? beta_ - 1.0 / 6.0 : (1 + w_) * (1 + w_) / (6 * w_ * (1 + 2 * w_));
    PETSC_CHECK(VecWAXPY(err_, -1.0, a_n_, a1));
    PETSC_CHECK(VecScale(err_, std::abs(constant) * h * h));
  }
  PetscScalar* e;
  PETSC_CHECK(VecGetArray(err_, &e));
  const PetscInt begin = assembler.owned_dof_begin();
  for (PetscInt d = begin; d < assembler.owned_dof_end(); ++d)
    if (assembler.constrained()[d]) e[d - begin] = 0.0;
  PETSC_CHECK(VecRestoreArray(err_, &e));
  PetscReal error;
  PETSC_CHECK(VecNorm(err_, NORM_INFINITY, &error));
  double factor = opt_.error_max_factor;
  if (error > 0) factor = opt_.error_safety * std::pow(opt_.error_tolerance / error, 1.0 / (order + 1));
  dt_next = h * std::clamp(factor, opt_.error_min_factor, opt_.error_max_factor);
  return error;
}

// Accepts the step if the local error estimate is within twice the tolerance
// (the next step aims at the tolerance itself).
EnergyTerm::StepAdvice InertiaTerm::advise_step(Assembler& assembler, Vec u1, double, double) {
  if (!opt_.adaptive) return {};
  double dt_next = 1e300;
  const double err = estimate_error(assembler, u1, dt_next);
  return {err <= 2.0 * opt_.error_tolerance, dt_next};
}

double InertiaTerm::estimate_error(Assembler& assembler, Vec u1, double& dt_next) {
  if (!initialized() || pred_piece_.empty()) throw std::logic_error("inertia: estimate_error before begin_step");
  step_accelerations(u1, v_new_, a_new_);
  return error_of(assembler, v_new_, a_new_, dt_next);
}

void InertiaTerm::end_step(Assembler& assembler, Vec u1, double /*t1*/) {
  step_accelerations(u1, v_new_, a_new_);
  last_error_ = error_of(assembler, v_new_, a_new_, suggested_dt_);
  PETSC_CHECK(VecCopy(u_n_, u_nm1_));
  PETSC_CHECK(VecCopy(v_n_, v_nm1_));
  PETSC_CHECK(VecCopy(u1, u_n_));
  PETSC_CHECK(VecCopy(v_new_, v_n_));
  PETSC_CHECK(VecCopy(a_new_, a_n_));
  h_prev_ = h_;
  ++steps_done_;
  have_a0_ = true;
}

// The history (u_n, v_n, a_n, u_{n-1}, v_{n-1}) and the step bookkeeping.
void InertiaTerm::save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) {
  state.integers[prefix + ".initialized"] = initialized();
  if (!initialized()) return;
  const std::pair<const char*, Vec> history[] = {
      {"u_n", u_n_}, {"v_n", v_n_}, {"a_n", a_n_}, {"u_nm1", u_nm1_}, {"v_nm1", v_nm1_}};
  for (const auto& [key, v] : history) save_vector(assembler, v, prefix + "." + key, state);
  state.integers[prefix + ".steps_done"] = steps_done_;
  state.integers[prefix + ".have_a0"] = have_a0_;
  state.set_number(prefix + ".h_prev", h_prev_);
  state.set_number(prefix + ".last_error", last_error_);
  state.set_number(prefix + ".suggested_dt", suggested_dt_);
}

void InertiaTerm::load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) {
  const std::string where = "checkpoint: " + prefix;
  if (!state.integer(prefix + ".initialized", where)) return;
  allocate(assembler);
  const std::pair<const char*, Vec> history[] = {
      {"u_n", u_n_}, {"v_n", v_n_}, {"a_n", a_n_}, {"u_nm1", u_nm1_}, {"v_nm1", v_nm1_}};
  for (const auto& [key, v] : history) load_vector(assembler, state, prefix + "." + key, v, where);
  steps_done_ = static_cast<int>(state.integer(prefix + ".steps_done", where));
  have_a0_ = state.integer(prefix + ".have_a0", where) != 0;
  h_prev_ = state.number(prefix + ".h_prev", where);
  last_error_ = state.number(prefix + ".last_error", where);
  suggested_dt_ = state.number(prefix + ".suggested_dt", where);
}

// 1/2 v_n^T M v_n summed over this rank's cells, then over ranks [J].
double InertiaTerm::kinetic_energy(Assembler& assembler) {
  if (!initialized()) throw std::logic_error("inertia: kinetic_energy before initialize");
  const std::vector<double>& local = assembler.gather(v_n_);
  std::vector<int> nodes;
  double sum = 0.0;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    Eigen::MatrixXd v(static_cast<int>(nodes.size()), 3);
    for (size_t a = 0; a < nodes.size(); ++a)
      for (int i = 0; i < 3; ++i) v(static_cast<int>(a), i) = local[3 * assembler.node_slot(nodes[a]) + i];
    sum += inertia_kernel(mass_[k], 1.0, v, nullptr, nullptr);
  }
  double total = 0.0;
  MPI_Allreduce(&sum, &total, 1, MPI_DOUBLE, MPI_SUM, assembler.comm());
  return total;
}

double InertiaTerm::mass(Assembler& assembler) const {
  double sum = 0.0, total = 0.0;
  for (const auto& m : mass_) sum += m.sum();
  MPI_Allreduce(&sum, &total, 1, MPI_DOUBLE, MPI_SUM, assembler.comm());
  return total;
}

}  // namespace morphfem
