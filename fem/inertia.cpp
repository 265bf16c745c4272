#include "fem/inertia.h"

#include <petscksp.h>

#include <stdexcept>

#include "fem/assembly.h"
#include "fem/petsc_check.h"

namespace morphfem {

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
                         std::shared_ptr<TimeIntegrator> integrator, bool lumped)
    : mesh_(mesh), integrator_(std::move(integrator)) {
  if (!integrator_) throw std::invalid_argument("inertia: needs a time integrator");
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
    mass_.push_back(element_mass_matrix(table, X, rho, lumped));
  }
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
  return inertia_kernel(mass_[k], integrator_->c(), s.u - pred_piece_[k], g, H);
}

void InertiaTerm::initialize(Assembler& assembler, Vec u0, double t0) {
  integrator_->initialize(assembler, u0, [&](Vec a0) { equilibrium_acceleration(assembler, u0, t0, a0); });
}

// a_0 from M a_0 = f(u_0, t_0) = -(gradient of every other term at t_0) [m/s^2]:
// CG + Jacobi on the assembled mass matrix (identity rows on constrained dofs,
// where a_0 = 0). Leaves every term's time at t0.
void InertiaTerm::equilibrium_acceleration(Assembler& assembler, Vec u0, double t0, Vec a0) {
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
  PETSC_CHECK(KSPSolve(ksp, force, a0));
  KSPConvergedReason reason;
  PETSC_CHECK(KSPGetConvergedReason(ksp, &reason));
  PETSC_CHECK(KSPDestroy(&ksp));
  PETSC_CHECK(MatDestroy(&M));
  PETSC_CHECK(VecDestroy(&force));
  if (reason < 0) throw std::runtime_error("inertia: the mass-matrix solve for the initial acceleration failed");
}

void InertiaTerm::begin_step(Assembler& assembler, Vec u0, double t0, double t1) {
  if (!integrator_->initialized()) {
    initialize(assembler, u0, t0);
    for (const auto& term : assembler.terms()) term->set_time(t1);
  }
  integrator_->begin_step(t0, t1);
  // Per-piece copy of the prediction (ghost values included).
  const std::vector<double>& local = assembler.gather(integrator_->predictor());
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

EnergyTerm::StepAdvice InertiaTerm::advise_step(Assembler& assembler, Vec u1, double, double) {
  return integrator_->advise_step(assembler, u1);
}

void InertiaTerm::end_step(Assembler& assembler, Vec u1, double /*t1*/) { integrator_->end_step(assembler, u1); }

void InertiaTerm::save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) {
  integrator_->save_state(assembler, prefix, state);
}

void InertiaTerm::load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) {
  integrator_->load_state(assembler, prefix, state);
}

// 1/2 v_n^T M v_n summed over this rank's cells, then over ranks [J].
double InertiaTerm::kinetic_energy(Assembler& assembler) {
  if (!integrator_->initialized()) throw std::logic_error("inertia: kinetic_energy before initialize");
  const std::vector<double>& local = assembler.gather(integrator_->velocity());
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
