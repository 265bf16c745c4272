// Assembly of energy terms into PETSc objects: the one loop over pieces.
//
// Degrees of freedom: displacement u, 3 per node, dof = 3*node + component; PETSc
// block size 3. Every rank holds the whole mesh (renumbered by partition_mesh so
// that rank r owns nodes [node_begin[r], node_begin[r+1])), assembles the pieces
// its terms hand it, and reads the displacement of the nodes it needs through a
// PETSc scatter (ghost values).
//
// Constrained (Dirichlet) dofs keep the value set in the solution vector: their
// gradient rows are zero and their Hessian rows/columns are the identity, so a
// Newton step never changes them.
#pragma once
#include <petscmat.h>
#include <petscvec.h>

#include <array>
#include <memory>
#include <utility>
#include <vector>

#include "fem/energy.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

class Assembler {
 public:
  Assembler(const Mesh& mesh, const Partition& partition, MPI_Comm comm);
  ~Assembler();
  Assembler(const Assembler&) = delete;
  Assembler& operator=(const Assembler&) = delete;

  void add_term(std::shared_ptr<EnergyTerm> term);
  const std::vector<std::shared_ptr<EnergyTerm>>& terms() const { return terms_; }
  // Marks dofs as constrained (global dof ids; the same list on every rank).
  void set_constrained(const std::vector<int>& dofs);
  const std::vector<char>& constrained() const { return constrained_; }
  // Builds the ghost scatter and the Hessian's coordinate list; call after the last
  // add_term / set_constrained and again if the terms' pieces change.
  void setup();

  // Vectors and matrices with this layout (caller destroys them).
  Vec create_vector() const;
  Mat create_matrix() const;

  // Total energy [J] (collective; +inf if any piece is outside its domain).
  double energy(Vec u);
  // Gradient [N] into g (zero on constrained dofs). Returns the energy.
  double gradient(Vec u, Vec g);
  // Hessian [N/m] into H (identity on constrained rows/columns).
  void hessian(Vec u, Mat H);
  // Energy of each term separately (collective), in the order of terms().
  std::vector<double> term_energies(Vec u);

  // Ghost access: displacement of this rank's needed nodes, gathered from u.
  // node_slot(n) is the position of global node n in that array (-1 if absent).
  const std::vector<double>& gather(Vec u);
  int node_slot(int node) const { return slot_[node]; }

  const Mesh& mesh() const { return mesh_; }
  const Partition& partition() const { return partition_; }
  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  PetscInt owned_dof_begin() const { return 3 * partition_.node_begin[rank_]; }
  PetscInt owned_dof_end() const { return 3 * partition_.node_begin[rank_ + 1]; }
  PetscInt n_dofs() const { return 3 * static_cast<PetscInt>(mesh_.n_nodes()); }

  // Whole displacement field on every rank (n_nodes x 3), e.g. for output.
  RowMatrixXd gather_all(Vec u) const;
  // Sets the owned entries of u from a full field (n_nodes x 3).
  void scatter_all(const RowMatrixXd& field, Vec u) const;

 private:
  template <class Visit>
  double sweep(Vec u, bool want_g, bool want_H, Visit&& visit);
  void load_piece(int k, const EnergyTerm& term, PieceState& s, std::vector<int>& nodes) const;
  void setup_shared_blocks(std::size_t t);  // coordinate list of a term with sparse_pieces()
  void add_to_shared_blocks(std::size_t t, int k, std::size_t n, double energy, const Eigen::MatrixXd& H);

  const Mesh& mesh_;
  const Partition& partition_;
  MPI_Comm comm_;
  int rank_ = 0;
  std::vector<std::shared_ptr<EnergyTerm>> terms_;
  // Log events of each term's sweeps (core/log_event.h): energy "E:NAME", gradient
  // "G:NAME", Hessian "H:NAME"; the whole sweeps are AsmEnergy, AsmGradient, AsmHessian.
  std::vector<std::array<PetscLogEvent, 3>> term_events_;
  std::vector<char> constrained_;  // per global dof
  std::vector<int> slot_;          // global node -> slot in ghost array (-1)
  std::vector<int> ghost_nodes_;   // nodes needed on this rank, sorted
  std::vector<double> ghost_u_;    // 3 per ghost node
  Vec ghost_vec_ = nullptr;
  VecScatter scatter_ = nullptr;
  // Hessian assembly in coordinate form (MatSetPreallocationCOO / MatSetValuesCOO):
  // every piece's n x n block at a fixed offset, column-major like Eigen, then the
  // constrained diagonals. PETSc sums repeated entries; index -1 entries are ignored.
  std::vector<PetscInt> coo_i_, coo_j_;
  std::vector<PetscScalar> coo_v_;
  std::vector<std::vector<std::size_t>> coo_offset_;  // [term][piece] -> first value
  // Terms with sparse_pieces(): [term][piece] -> first entry in block_offset_[term],
  // which lists, for the piece's n x n node pairs (column-major), the first value
  // of the pair's shared 3 x 3 block (column-major).
  std::vector<std::vector<std::size_t>> block_first_;
  std::vector<std::vector<std::size_t>> block_offset_;
  std::vector<std::pair<std::size_t, std::size_t>> block_values_;  // each such term's [first, end) values
  std::size_t coo_diagonal_ = 0;                                   // first constrained-diagonal value
};

}  // namespace morphfem
