#include "fem/assembly.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include "core/log_event.h"
#include "fem/petsc_check.h"

namespace morphfem {

Assembler::Assembler(const Mesh& mesh, const Partition& partition, MPI_Comm comm)
    : mesh_(mesh), partition_(partition), comm_(comm) {
  MPI_Comm_rank(comm, &rank_);
  constrained_.assign(3 * mesh.n_nodes(), 0);
  slot_.assign(mesh.n_nodes(), -1);
}

Assembler::~Assembler() {
  if (ghost_vec_) VecDestroy(&ghost_vec_);
  if (scatter_) VecScatterDestroy(&scatter_);
}

void Assembler::add_term(std::shared_ptr<EnergyTerm> term) {
  const std::string name = term->name();
  term_events_.push_back({log_event("E:" + name), log_event("G:" + name), log_event("H:" + name)});
  terms_.push_back(std::move(term));
}

void Assembler::set_constrained(const std::vector<int>& dofs) {
  std::fill(constrained_.begin(), constrained_.end(), 0);
  for (int d : dofs) constrained_.at(d) = 1;
}

Vec Assembler::create_vector() const {
  Vec v;
  PETSC_CHECK(VecCreate(comm_, &v));
  PETSC_CHECK(VecSetSizes(v, owned_dof_end() - owned_dof_begin(), n_dofs()));
  PETSC_CHECK(VecSetBlockSize(v, 3));
  PETSC_CHECK(VecSetFromOptions(v));
  PETSC_CHECK(VecSet(v, 0.0));
  return v;
}

Mat Assembler::create_matrix() const {
  Mat m;
  const PetscInt n_local = owned_dof_end() - owned_dof_begin();
  PETSC_CHECK(MatCreate(comm_, &m));
  PETSC_CHECK(MatSetType(m, MATAIJ));
  PETSC_CHECK(MatSetSizes(m, n_local, n_local, n_dofs(), n_dofs()));
  PETSC_CHECK(MatSetBlockSize(m, 3));
  // The pattern and the coordinate map of hessian() (PETSc may modify the index
  // arrays it is given).
  std::vector<PetscInt> i = coo_i_, j = coo_j_;
  PETSC_CHECK(MatSetPreallocationCOO(m, static_cast<PetscCount>(i.size()), i.data(), j.data()));
  PETSC_CHECK(MatSetOption(m, MAT_ROW_ORIENTED, PETSC_FALSE));  // Eigen is column-major
  PETSC_CHECK(MatSetOption(m, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  // Every term is an energy, so its Hessian, and the sum, is symmetric (projected or
  // not): the solver's LDL^T factorisation relies on it.
  PETSC_CHECK(MatSetOption(m, MAT_SYMMETRIC, PETSC_TRUE));
  PETSC_CHECK(MatSetOption(m, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  return m;
}

void Assembler::load_piece(int k, const EnergyTerm& term, PieceState& s, std::vector<int>& nodes) const {
  term.piece_nodes(k, nodes);
  const int n = static_cast<int>(nodes.size());
  s.X.resize(n, 3);
  s.u.resize(n, 3);
  for (int a = 0; a < n; ++a) {
    const int slot = slot_[nodes[a]];
    for (int i = 0; i < 3; ++i) {
      s.X(a, i) = mesh_.X(nodes[a], i);
      s.u(a, i) = ghost_u_[3 * slot + i];
    }
  }
}

void Assembler::setup() {
  // Nodes this rank needs: its owned nodes and every node of its pieces.
  std::fill(slot_.begin(), slot_.end(), -1);
  std::vector<char> needed(mesh_.n_nodes(), 0);
  for (int n = partition_.node_begin[rank_]; n < partition_.node_begin[rank_ + 1]; ++n) needed[n] = 1;
  std::vector<int> nodes;
  for (const auto& term : terms_)
    for (int k = 0; k < term->n_pieces(); ++k) {
      term->piece_nodes(k, nodes);
      for (int n : nodes) needed[n] = 1;
    }
  ghost_nodes_.clear();
  for (int n = 0; n < mesh_.n_nodes(); ++n)
    if (needed[n]) {
      slot_[n] = static_cast<int>(ghost_nodes_.size());
      ghost_nodes_.push_back(n);
    }
  ghost_u_.assign(3 * ghost_nodes_.size(), 0.0);

  if (ghost_vec_) VecDestroy(&ghost_vec_);
  if (scatter_) VecScatterDestroy(&scatter_);
  Vec u = create_vector();
  IS is;
  std::vector<PetscInt> block_ids(ghost_nodes_.begin(), ghost_nodes_.end());
  PETSC_CHECK(ISCreateBlock(PETSC_COMM_SELF, 3, static_cast<PetscInt>(block_ids.size()), block_ids.data(),
                            PETSC_COPY_VALUES, &is));
  PETSC_CHECK(VecCreateSeq(PETSC_COMM_SELF, 3 * static_cast<PetscInt>(ghost_nodes_.size()), &ghost_vec_));
  PETSC_CHECK(VecScatterCreate(u, is, ghost_vec_, nullptr, &scatter_));
  PETSC_CHECK(ISDestroy(&is));
  PETSC_CHECK(VecDestroy(&u));

  // Nonzero pattern: every piece's entries as a coordinate list, in the order
  // hessian() visits them, and every owned diagonal.
  std::vector<PetscInt> idx;
  coo_i_.clear();
  coo_j_.clear();
  coo_offset_.assign(terms_.size(), {});
  block_first_.assign(terms_.size(), {});
  block_offset_.assign(terms_.size(), {});
  block_values_.clear();
  for (size_t t = 0; t < terms_.size(); ++t) {
    if (terms_[t]->sparse_pieces()) {
      setup_shared_blocks(t);
      continue;
    }
    coo_offset_[t].resize(terms_[t]->n_pieces());
    for (int k = 0; k < terms_[t]->n_pieces(); ++k) {
      terms_[t]->piece_nodes(k, nodes);
      idx.clear();
      for (int n : nodes)
        for (int i = 0; i < 3; ++i) idx.push_back(constrained_[3 * n + i] ? -1 : 3 * n + i);
      coo_offset_[t][k] = coo_i_.size();
      for (PetscInt col : idx)
        for (PetscInt row : idx) {
          coo_i_.push_back(row);
          coo_j_.push_back(col);
        }
    }
  }
  coo_diagonal_ = coo_i_.size();
  for (PetscInt d = owned_dof_begin(); d < owned_dof_end(); ++d) {  // every diagonal (1 if constrained)
    coo_i_.push_back(d);
    coo_j_.push_back(d);
  }
  coo_v_.assign(coo_i_.size(), 0.0);
}

void Assembler::setup_shared_blocks(std::size_t t) {
  const EnergyTerm& term = *terms_[t];
  std::unordered_map<std::uint64_t, std::size_t> block;  // row node * n_nodes + column node -> first value
  std::vector<int> nodes;
  auto& first = block_first_[t];
  auto& offset = block_offset_[t];
  const std::size_t values_begin = coo_i_.size();
  first.resize(term.n_pieces() + 1);
  for (int k = 0; k < term.n_pieces(); ++k) {
    first[k] = offset.size();
    term.piece_nodes(k, nodes);
    for (int b : nodes)
      for (int a : nodes) {
        const std::uint64_t key = static_cast<std::uint64_t>(a) * mesh_.n_nodes() + static_cast<std::uint64_t>(b);
        auto [it, added] = block.try_emplace(key, coo_i_.size());
        if (added)
          for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i) {
              coo_i_.push_back(constrained_[3 * a + i] ? -1 : 3 * a + i);
              coo_j_.push_back(constrained_[3 * b + j] ? -1 : 3 * b + j);
            }
        offset.push_back(it->second);
      }
  }
  first[term.n_pieces()] = offset.size();
  block_values_.emplace_back(values_begin, coo_i_.size());
}

const std::vector<double>& Assembler::gather(Vec u) {
  PETSC_CHECK(VecScatterBegin(scatter_, u, ghost_vec_, INSERT_VALUES, SCATTER_FORWARD));
  PETSC_CHECK(VecScatterEnd(scatter_, u, ghost_vec_, INSERT_VALUES, SCATTER_FORWARD));
  const PetscScalar* a;
  PETSC_CHECK(VecGetArrayRead(ghost_vec_, &a));
  std::copy(a, a + ghost_u_.size(), ghost_u_.begin());
  PETSC_CHECK(VecRestoreArrayRead(ghost_vec_, &a));
  return ghost_u_;
}

// The one loop over pieces of every term. visit(term_index, piece_index, dof
// indices, energy, g, H) receives each piece's contribution.
template <class Visit>
double Assembler::sweep(Vec u, bool want_g, bool want_H, Visit&& visit) {
  gather(u);
  PieceState s;
  std::vector<int> nodes;
  std::vector<PetscInt> idx;
  Eigen::VectorXd g;
  Eigen::MatrixXd H;
  double local = 0.0;
  const int kind = want_H ? 2 : want_g ? 1 : 0;  // the term's event: E:, G: or H:
  for (size_t t = 0; t < terms_.size(); ++t) {
    LogEventScope event(term_events_[t][kind]);
    EnergyTerm& term = *terms_[t];
    term.prepare(*this, ghost_u_);
    for (int k = 0; k < term.n_pieces(); ++k) {
      load_piece(k, term, s, nodes);
      double e = term.piece(k, s, want_g ? &g : nullptr, want_H ? &H : nullptr);
      idx.clear();
      for (int n : nodes)
        for (int i = 0; i < 3; ++i) idx.push_back(constrained_[3 * n + i] ? -1 : 3 * n + i);
      local += e;
      visit(t, k, idx, e, g, H);
    }
  }
  double total = 0.0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, comm_);
  if (std::isnan(total)) total = std::numeric_limits<double>::infinity();
  return total;
}

double Assembler::energy(Vec u) {
  static const PetscLogEvent event = log_event("AsmEnergy");
  LogEventScope scope(event);
  return sweep(u, false, false, [](auto&&...) {});
}

std::vector<double> Assembler::term_energies(Vec u) {
  std::vector<double> local(terms_.size(), 0.0), total(terms_.size(), 0.0);
  sweep(u, false, false, [&](size_t t, int, const auto&, double e, const auto&, const auto&) { local[t] += e; });
  MPI_Allreduce(local.data(), total.data(), static_cast<int>(local.size()), MPI_DOUBLE, MPI_SUM, comm_);
  return total;
}

double Assembler::gradient(Vec u, Vec gvec) {
  static const PetscLogEvent event = log_event("AsmGradient");
  LogEventScope scope(event);
  PETSC_CHECK(VecSet(gvec, 0.0));
  // Constrained dofs carry index -1; PETSc vectors skip them only with this option.
  PETSC_CHECK(VecSetOption(gvec, VEC_IGNORE_NEGATIVE_INDICES, PETSC_TRUE));
  double e =
      sweep(u, true, false,
            [&](size_t t, int, const std::vector<PetscInt>& idx, double energy, const Eigen::VectorXd& g,
                const Eigen::MatrixXd&) {
              if (!std::isfinite(energy)) return;                     // outside the domain: no meaningful gradient
              if (!block_first_[t].empty() && g.isZero(0.0)) return;  // a sparse term's inactive piece
              PETSC_CHECK(VecSetValues(gvec, static_cast<PetscInt>(idx.size()), idx.data(), g.data(), ADD_VALUES));
            });
  PETSC_CHECK(VecAssemblyBegin(gvec));
  PETSC_CHECK(VecAssemblyEnd(gvec));
  return e;
}

void Assembler::hessian(Vec u, Mat Hmat) {
  static const PetscLogEvent event = log_event("AsmHessian");
  LogEventScope scope(event);
  // Values go into the coordinate list built by setup() and reach PETSc in one
  // MatSetValuesCOO: measured on the voxel robot (3,060 dofs, P1), per-piece
  // MatSetValues took ~40 % of the run, most of it searching for columns.
  for (const auto& [begin, end] : block_values_)  // the shared blocks sum their pieces
    std::fill(coo_v_.begin() + static_cast<long>(begin), coo_v_.begin() + static_cast<long>(end), 0.0);
  sweep(u, false, true,
        [&](size_t t, int k, const std::vector<PetscInt>& idx, double energy, const Eigen::VectorXd&,
            const Eigen::MatrixXd& H) {
          if (!block_first_[t].empty()) {
            add_to_shared_blocks(t, k, idx.size() / 3, energy, H);
            return;
          }
          if (static_cast<std::size_t>(k) >= coo_offset_[t].size())
            throw std::logic_error("Assembler::hessian: a term gained pieces without setup()");
          const std::size_t n = idx.size(), begin = coo_offset_[t][k];
          if (begin + n * n > coo_diagonal_ ||
              (k + 1 < static_cast<int>(coo_offset_[t].size()) && coo_offset_[t][k + 1] != begin + n * n))
            throw std::logic_error("Assembler::hessian: a piece changed its nodes without setup()");
          if (std::isfinite(energy))
            std::copy(H.data(), H.data() + n * n, coo_v_.begin() + static_cast<long>(begin));
          else
            std::fill_n(coo_v_.begin() + static_cast<long>(begin), n * n, 0.0);
        });
  for (PetscInt d = owned_dof_begin(); d < owned_dof_end(); ++d)
    coo_v_[coo_diagonal_ + static_cast<std::size_t>(d - owned_dof_begin())] = constrained_[d] ? 1.0 : 0.0;
  PETSC_CHECK(MatSetValuesCOO(Hmat, coo_v_.data(), INSERT_VALUES));
}

void Assembler::add_to_shared_blocks(std::size_t t, int k, std::size_t n, double energy, const Eigen::MatrixXd& H) {
  const auto& first = block_first_[t];
  if (static_cast<std::size_t>(k) + 1 >= first.size() || first[k + 1] - first[k] != n * n)
    throw std::logic_error("Assembler::hessian: a piece changed its nodes without setup()");
  if (!std::isfinite(energy) || H.size() == 0 || H.isZero(0.0)) return;  // the common case: no contribution
  const std::size_t* offset = block_offset_[t].data() + first[k];
  for (std::size_t b = 0; b < n; ++b)
    for (std::size_t a = 0; a < n; ++a) {
      double* v = coo_v_.data() + offset[b * n + a];
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) v[3 * j + i] += H(3 * a + i, 3 * b + j);
    }
}

RowMatrixXd Assembler::gather_all(Vec u) const {
  VecScatter to_all;
  Vec all;
  PETSC_CHECK(VecScatterCreateToAll(u, &to_all, &all));
  PETSC_CHECK(VecScatterBegin(to_all, u, all, INSERT_VALUES, SCATTER_FORWARD));
  PETSC_CHECK(VecScatterEnd(to_all, u, all, INSERT_VALUES, SCATTER_FORWARD));
  RowMatrixXd field(mesh_.n_nodes(), 3);
  const PetscScalar* a;
  PETSC_CHECK(VecGetArrayRead(all, &a));
  std::copy(a, a + field.size(), field.data());
  PETSC_CHECK(VecRestoreArrayRead(all, &a));
  PETSC_CHECK(VecScatterDestroy(&to_all));
  PETSC_CHECK(VecDestroy(&all));
  return field;
}

void Assembler::scatter_all(const RowMatrixXd& field, Vec u) const {
  PetscScalar* a;
  PETSC_CHECK(VecGetArray(u, &a));
  for (PetscInt d = owned_dof_begin(); d < owned_dof_end(); ++d) a[d - owned_dof_begin()] = field(d / 3, d % 3);
  PETSC_CHECK(VecRestoreArray(u, &a));
}

}  // namespace morphfem
