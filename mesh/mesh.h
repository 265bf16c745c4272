// The finite-element mesh: tetrahedra (P1: 4 nodes, P2: 10 nodes) with named
// regions. Volumes carry materials; boundary surfaces carry clamps, loads,
// cavities, feet and contact surfaces. Lengths are in metres.
//
// Node ordering follows VTK/XDMF so meshes write to ParaView unchanged:
//   tet:      vertices 0-3, then edge mid-nodes (0,1) (1,2) (0,2) (0,3) (1,3) (2,3)
//   triangle: vertices 0-2, then edge mid-nodes (0,1) (1,2) (0,2)
// Boundary triangles are oriented so (x1 - x0) x (x2 - x0) points out of the solid.
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

namespace morphfem {

using RowMatrixXd = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXi = Eigen::Matrix<int, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct Region {
  std::string name;  // physical-group name, e.g. "skin", "inner", "foot_a"
  int dim = 3;       // 3: volume (cells), 2: surface (faces)
  int id = 0;        // index stored in cell_region / face_region
};

struct Mesh {
  int order = 1;                 // polynomial order of the tetrahedra: 1 or 2
  RowMatrixXd X;                 // reference coordinates, n_nodes x 3 [m]
  RowMatrixXi cells;             // n_cells x (4 | 10), VTK ordering
  std::vector<int> cell_region;  // region id per cell (dim 3)
  RowMatrixXi faces;             // boundary triangles n_faces x (3 | 6), outward from the solid
  std::vector<int> face_region;  // region id per face (dim 2)
  std::vector<Region> regions;

  int n_nodes() const { return static_cast<int>(X.rows()); }
  int n_cells() const { return static_cast<int>(cells.rows()); }
  int n_faces() const { return static_cast<int>(faces.rows()); }
  int nodes_per_cell() const { return order == 1 ? 4 : 10; }
  int nodes_per_face() const { return order == 1 ? 3 : 6; }

  // Region lookup; throws InputError listing the known names if absent.
  const Region& region(const std::string& name, int dim) const;
  bool has_region(const std::string& name, int dim) const;
  std::vector<std::string> region_names(int dim) const;

  // Faces of a surface region (indices into `faces`), and their sorted unique nodes.
  std::vector<int> faces_of(const std::string& surface) const;
  std::vector<int> nodes_of_surface(const std::string& surface) const;
  // Cells of a volume region, and the nodes they use.
  std::vector<int> cells_of(const std::string& volume) const;

  // Total reference volume [m^3] (exact for straight-sided cells, quadrature for P2).
  double volume() const;
  // Reference volume of one cell [m^3] (P2: of the curved cell).
  double cell_volume(int cell) const;
  // Smallest and largest edge length over vertex-to-vertex edges [m].
  std::pair<double, double> edge_length_range() const;
};

// Consistency checks (index ranges, positive reference volume of every cell,
// region ids known). Throws InputError naming `source` on the first problem.
void validate_mesh(const Mesh& mesh, const std::string& source);

}  // namespace morphfem
