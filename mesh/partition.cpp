// METIS cell partitioning and node renumbering (contiguous node block per part, or a
// fill-reducing nested-dissection order for a single part).
#include "mesh/partition.h"

#include <metis.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/errors.h"

namespace morphfem {

namespace {

constexpr idx_t kMetisSeed = 4242;  // fixed so every rank gets the same partition

void set_metis_options(idx_t* options) {
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  options[METIS_OPTION_SEED] = kMetisSeed;
}

void check_metis(int status, const std::string& call) {
  if (status != METIS_OK) throw std::runtime_error(call + " failed with METIS status " + std::to_string(status));
}

// Part of each cell from METIS on the dual graph (cells adjacent when they share a
// face, i.e. ncommon = 3 vertices).
std::vector<int> metis_cell_parts(const Mesh& mesh, int n_parts) {
  idx_t n_elements = mesh.n_cells(), n_nodes = mesh.n_nodes(), ncommon = 3, nparts = n_parts, objval = 0;
  std::vector<idx_t> eptr(n_elements + 1), eind(4 * static_cast<std::size_t>(n_elements));
  for (idx_t c = 0; c < n_elements; ++c) {
    eptr[c] = 4 * c;
    for (int k = 0; k < 4; ++k) eind[4 * c + k] = mesh.cells(c, k);
  }
  eptr[n_elements] = 4 * n_elements;
  idx_t options[METIS_NOPTIONS];
  set_metis_options(options);
  std::vector<idx_t> element_part(n_elements), node_part(n_nodes);
  check_metis(METIS_PartMeshDual(&n_elements, &n_nodes, eptr.data(), eind.data(), nullptr, nullptr, &ncommon, &nparts,
                                 nullptr, options, &objval, element_part.data(), node_part.data()),
              "METIS_PartMeshDual");
  return std::vector<int>(element_part.begin(), element_part.end());
}

// New node numbers: nodes sorted by owning part (lowest part among the cells using
// the node), ties kept in the old order. Fills node_begin.
std::vector<int> contiguous_part_numbering(const Mesh& mesh, const std::vector<int>& cell_part, int n_parts,
                                           std::vector<int>& node_begin) {
  std::vector<int> owner(mesh.n_nodes(), n_parts);  // unused nodes go to the last part
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (int k = 0; k < mesh.cells.cols(); ++k)
      owner[mesh.cells(c, k)] = std::min(owner[mesh.cells(c, k)], cell_part[c]);
  for (int& p : owner) p = std::min(p, n_parts - 1);

  std::vector<int> old_of_new(mesh.n_nodes());
  std::iota(old_of_new.begin(), old_of_new.end(), 0);
  std::stable_sort(old_of_new.begin(), old_of_new.end(), [&](int a, int b) { return owner[a] < owner[b]; });
  node_begin.assign(n_parts + 1, 0);
  for (int p : owner) ++node_begin[p + 1];
  std::partial_sum(node_begin.begin(), node_begin.end(), node_begin.begin());

  std::vector<int> new_of_old(mesh.n_nodes());
  for (int n = 0; n < mesh.n_nodes(); ++n) new_of_old[old_of_new[n]] = n;
  return new_of_old;
}

// Node adjacency graph (nodes sharing a cell, mid-nodes included) in CSR form.
void node_graph(const Mesh& mesh, std::vector<idx_t>& xadj, std::vector<idx_t>& adjncy) {
  std::vector<std::vector<idx_t>> neighbours(mesh.n_nodes());
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (int a = 0; a < mesh.cells.cols(); ++a)
      for (int b = 0; b < mesh.cells.cols(); ++b)
        if (a != b) neighbours[mesh.cells(c, a)].push_back(mesh.cells(c, b));
  xadj.assign(1, 0);
  adjncy.clear();
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    adjncy.insert(adjncy.end(), list.begin(), list.end());
    xadj.push_back(static_cast<idx_t>(adjncy.size()));
  }
}

// New node numbers from METIS nested dissection (fill-reducing order).
std::vector<int> nested_dissection_numbering(const Mesh& mesh) {
  std::vector<idx_t> xadj, adjncy;
  node_graph(mesh, xadj, adjncy);
  idx_t n_nodes = mesh.n_nodes();
  idx_t options[METIS_NOPTIONS];
  set_metis_options(options);
  std::vector<idx_t> perm(n_nodes), iperm(n_nodes);  // perm[new] = old, iperm[old] = new
  check_metis(METIS_NodeND(&n_nodes, xadj.data(), adjncy.data(), nullptr, options, perm.data(), iperm.data()),
              "METIS_NodeND");
  return std::vector<int>(iperm.begin(), iperm.end());
}

void renumber_nodes(Mesh& mesh, const std::vector<int>& new_of_old) {
  RowMatrixXd X(mesh.n_nodes(), 3);
  for (int n = 0; n < mesh.n_nodes(); ++n) X.row(new_of_old[n]) = mesh.X.row(n);
  mesh.X = std::move(X);
  for (Eigen::Index k = 0; k < mesh.cells.size(); ++k) mesh.cells.data()[k] = new_of_old[mesh.cells.data()[k]];
  for (Eigen::Index k = 0; k < mesh.faces.size(); ++k) mesh.faces.data()[k] = new_of_old[mesh.faces.data()[k]];
}

}  // namespace

Partition partition_mesh(Mesh& mesh, int n_parts) {
  if (n_parts < 1 || n_parts > mesh.n_cells())
    throw InputError("partition", "cannot split a mesh of " + std::to_string(mesh.n_cells()) + " cells into " +
                                      std::to_string(n_parts) + " parts");
  Partition partition;
  partition.n_parts = n_parts;
  std::vector<int> new_of_old;
  if (n_parts == 1) {
    partition.cell_part.assign(mesh.n_cells(), 0);
    partition.node_begin = {0, mesh.n_nodes()};
    new_of_old = nested_dissection_numbering(mesh);
  } else {
    partition.cell_part = metis_cell_parts(mesh, n_parts);
    new_of_old = contiguous_part_numbering(mesh, partition.cell_part, n_parts, partition.node_begin);
  }
  renumber_nodes(mesh, new_of_old);
  return partition;
}

}  // namespace morphfem
