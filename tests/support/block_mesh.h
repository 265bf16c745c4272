// Meshes for kernel tests: the `block` geometry [0, lx] x [0, ly] x [0, lz] (surfaces
// xmin xmax ymin ymax zmin zmax, volume body), and the partition that puts every cell
// and node on rank 0.
#pragma once
#include <Eigen/Dense>

#include "core/params.h"
#include "mesh/geometry.h"
#include "mesh/partition.h"

namespace morphfem::testing {

inline Mesh block_mesh(const Eigen::Vector3d& lengths, double mesh_size, int order) {
  ParamSet p("test block");
  p.set_string("type", "block");
  p.set("lx", lengths.x());
  p.set("ly", lengths.y());
  p.set("lz", lengths.z());
  p.set("mesh_size", mesh_size);
  p.set("order", order);
  return build_geometry(p);
}

inline Partition one_rank(const Mesh& mesh) {
  Partition part;
  part.n_parts = 1;
  part.cell_part.assign(mesh.n_cells(), 0);
  part.node_begin = {0, mesh.n_nodes()};
  return part;
}

}  // namespace morphfem::testing
