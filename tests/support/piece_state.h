// The state of one energy piece (its nodes' reference coordinates and displacements)
// taken from a whole-mesh displacement field u (n_nodes x 3), for kernel tests.
#pragma once
#include <vector>

#include "fem/energy.h"
#include "mesh/mesh.h"

namespace morphfem::testing {

inline PieceState piece_state(const Mesh& mesh, const std::vector<int>& nodes, const RowMatrixXd& u) {
  PieceState s;
  s.X.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  s.u.resize(static_cast<Eigen::Index>(nodes.size()), 3);
  for (size_t a = 0; a < nodes.size(); ++a) {
    s.X.row(static_cast<Eigen::Index>(a)) = mesh.X.row(nodes[a]);
    s.u.row(static_cast<Eigen::Index>(a)) = u.row(nodes[a]);
  }
  return s;
}

}  // namespace morphfem::testing
