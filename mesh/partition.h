// Partitioning for MPI runs: METIS splits the cells into one part per rank, and
// nodes are renumbered so that each rank owns one contiguous block of nodes (and so
// of PETSc rows, block size 3). Every rank holds the whole (small) mesh; each
// assembles only its own cells.
#pragma once
#include <vector>

#include "mesh/mesh.h"

namespace morphfem {

struct Partition {
  int n_parts = 1;
  std::vector<int> cell_part;   // part of each cell
  std::vector<int> node_begin;  // nodes [node_begin[p], node_begin[p+1]) belong to part p
};

// Splits `mesh` into `n_parts` with METIS (dual graph of cells sharing a face) and
// renumbers its nodes in place so that each part's nodes are contiguous (a node
// belongs to the lowest-numbered part among the cells that use it). With one part
// the nodes are reordered by METIS nested dissection to keep fill low.
// Deterministic: same mesh and n_parts give the same result on every rank.
Partition partition_mesh(Mesh& mesh, int n_parts);

}  // namespace morphfem
