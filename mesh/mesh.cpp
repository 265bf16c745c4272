// Mesh queries (regions, volume, edge lengths) and consistency checks.
#include "mesh/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/errors.h"

namespace morphfem {

namespace {

std::string dim_word(int dim) {
  return dim == 3 ? "volume" : dim == 2 ? "surface" : "dimension-" + std::to_string(dim);
}

Eigen::Vector3d node_position(const Mesh& mesh, int node) { return mesh.X.row(node).transpose(); }

// Signed volume of the straight tetrahedron on the first four nodes of `cell` [m^3]:
// V = det[x1 - x0, x2 - x0, x3 - x0] / 6.
double vertex_tet_volume(const Mesh& mesh, int cell) {
  const Eigen::Vector3d x0 = node_position(mesh, mesh.cells(cell, 0));
  const Eigen::Vector3d e1 = node_position(mesh, mesh.cells(cell, 1)) - x0;
  const Eigen::Vector3d e2 = node_position(mesh, mesh.cells(cell, 2)) - x0;
  const Eigen::Vector3d e3 = node_position(mesh, mesh.cells(cell, 3)) - x0;
  return e1.dot(e2.cross(e3)) / 6.0;
}

// Gradients d N_a / d xi (xi in the unit tetrahedron, barycentrics L0 = 1 - xi - eta - zeta,
// L1 = xi, L2 = eta, L3 = zeta) of the 10 quadratic shape functions in VTK order:
// vertices N_i = L_i (2 L_i - 1), mid-nodes N_ij = 4 L_i L_j.
Eigen::Matrix<double, 10, 3> p2_shape_gradients(const Eigen::Vector3d& xi) {
  const std::array<double, 4> L = {1.0 - xi.sum(), xi(0), xi(1), xi(2)};
  // d L_i / d xi_k
  const std::array<Eigen::Vector3d, 4> dL = {Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 0, 0),
                                             Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)};
  static constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  Eigen::Matrix<double, 10, 3> dN;
  for (int i = 0; i < 4; ++i) dN.row(i) = ((4.0 * L[i] - 1.0) * dL[i]).transpose();
  for (int e = 0; e < 6; ++e) {
    const int i = kEdges[e][0], j = kEdges[e][1];
    dN.row(4 + e) = (4.0 * (L[i] * dL[j] + L[j] * dL[i])).transpose();
  }
  return dN;
}

// det(dx/dxi) of the quadratic map of a P2 cell at reference point xi.
double p2_jacobian_det(const Mesh& mesh, int cell, const Eigen::Vector3d& xi) {
  const Eigen::Matrix<double, 10, 3> dN = p2_shape_gradients(xi);
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();  // J_ck = sum_a x_a,c dN_a/dxi_k
  for (int a = 0; a < 10; ++a) J += node_position(mesh, mesh.cells(cell, a)) * dN.row(a);
  return J.determinant();
}

// Volume of a P2 cell, V = int det J dxi over the unit tetrahedron. det J is a cubic
// polynomial, integrated exactly by the degree-3 rule: weight -2/15 at the centroid
// and 3/40 at the four points with barycentrics (1/2, 1/6, 1/6, 1/6).
double p2_tet_volume(const Mesh& mesh, int cell) {
  double volume = -2.0 / 15.0 * p2_jacobian_det(mesh, cell, Eigen::Vector3d::Constant(0.25));
  const double a = 1.0 / 2.0, b = 1.0 / 6.0;
  const std::array<Eigen::Vector3d, 4> points = {Eigen::Vector3d(b, b, b), Eigen::Vector3d(a, b, b),
                                                 Eigen::Vector3d(b, a, b), Eigen::Vector3d(b, b, a)};
  for (const auto& xi : points) volume += 3.0 / 40.0 * p2_jacobian_det(mesh, cell, xi);
  return volume;
}

double cell_volume(const Mesh& mesh, int cell) {
  return mesh.order == 1 ? vertex_tet_volume(mesh, cell) : p2_tet_volume(mesh, cell);
}

}  // namespace

const Region& Mesh::region(const std::string& name, int dim) const {
  for (const Region& r : regions)
    if (r.name == name && r.dim == dim) return r;
  std::ostringstream known;
  for (const std::string& n : region_names(dim)) known << (known.tellp() > 0 ? ", " : "") << n;
  throw InputError("mesh", "no " + dim_word(dim) + " region named '" + name +
                               "' (known: " + (known.str().empty() ? "none" : known.str()) + ")");
}

bool Mesh::has_region(const std::string& name, int dim) const {
  return std::any_of(regions.begin(), regions.end(), [&](const Region& r) { return r.name == name && r.dim == dim; });
}

std::vector<std::string> Mesh::region_names(int dim) const {
  std::vector<std::string> names;
  for (const Region& r : regions)
    if (r.dim == dim) names.push_back(r.name);
  return names;
}

std::vector<int> Mesh::faces_of(const std::string& surface) const {
  const int id = region(surface, 2).id;
  std::vector<int> out;
  for (int f = 0; f < n_faces(); ++f)
    if (face_region[f] == id) out.push_back(f);
  return out;
}

std::vector<int> Mesh::nodes_of_surface(const std::string& surface) const {
  std::vector<int> nodes;
  for (int f : faces_of(surface))
    for (int k = 0; k < faces.cols(); ++k) nodes.push_back(faces(f, k));
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

std::vector<int> Mesh::cells_of(const std::string& volume) const {
  const int id = region(volume, 3).id;
  std::vector<int> out;
  for (int c = 0; c < n_cells(); ++c)
    if (cell_region[c] == id) out.push_back(c);
  return out;
}

double Mesh::cell_volume(int cell) const { return morphfem::cell_volume(*this, cell); }

double Mesh::volume() const {
  double total = 0.0;
  for (int c = 0; c < n_cells(); ++c) total += cell_volume(c);
  return total;
}

std::pair<double, double> Mesh::edge_length_range() const {
  static constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  double shortest = std::numeric_limits<double>::infinity(), longest = 0.0;
  for (int c = 0; c < n_cells(); ++c)
    for (const auto& e : kEdges) {
      const double length = (X.row(cells(c, e[0])) - X.row(cells(c, e[1]))).norm();
      shortest = std::min(shortest, length);
      longest = std::max(longest, length);
    }
  if (n_cells() == 0) shortest = 0.0;
  return {shortest, longest};
}

namespace {

void check_shapes(const Mesh& mesh, const std::string& source) {
  if (mesh.order != 1 && mesh.order != 2)
    throw InputError(source, "mesh order must be 1 or 2, got " + std::to_string(mesh.order));
  if (mesh.X.cols() != 3) throw InputError(source, "node coordinates must have 3 columns");
  if (mesh.n_cells() == 0) throw InputError(source, "mesh has no tetrahedra");
  if (mesh.cells.cols() != mesh.nodes_per_cell())
    throw InputError(source, "cells have " + std::to_string(mesh.cells.cols()) + " nodes, expected " +
                                 std::to_string(mesh.nodes_per_cell()));
  if (mesh.n_faces() > 0 && mesh.faces.cols() != mesh.nodes_per_face())
    throw InputError(source, "faces have " + std::to_string(mesh.faces.cols()) + " nodes, expected " +
                                 std::to_string(mesh.nodes_per_face()));
  if (static_cast<int>(mesh.cell_region.size()) != mesh.n_cells())
    throw InputError(source, "cell_region size differs from the number of cells");
  if (static_cast<int>(mesh.face_region.size()) != mesh.n_faces())
    throw InputError(source, "face_region size differs from the number of faces");
  if (!mesh.X.allFinite()) throw InputError(source, "node coordinates are not all finite");
}

void check_node_indices(const RowMatrixXi& connectivity, int n_nodes, const std::string& what,
                        const std::string& source) {
  if (connectivity.size() == 0) return;
  if (connectivity.minCoeff() < 0 || connectivity.maxCoeff() >= n_nodes)
    throw InputError(source, what + " reference node indices outside [0, " + std::to_string(n_nodes) + ")");
}

void check_regions(const Mesh& mesh, const std::string& source) {
  for (size_t i = 0; i < mesh.regions.size(); ++i)
    if (mesh.regions[i].id != static_cast<int>(i))
      throw InputError(source, "region '" + mesh.regions[i].name + "' has id " + std::to_string(mesh.regions[i].id) +
                                   ", expected its index " + std::to_string(i));
  auto check_ids = [&](const std::vector<int>& ids, int dim, const std::string& what) {
    for (size_t k = 0; k < ids.size(); ++k) {
      const int id = ids[k];
      if (id < 0 || id >= static_cast<int>(mesh.regions.size()) || mesh.regions[id].dim != dim)
        throw InputError(source, what + " " + std::to_string(k) + " has region id " + std::to_string(id) +
                                     ", which is not a " + dim_word(dim) + " region");
    }
  };
  check_ids(mesh.cell_region, 3, "cell");
  check_ids(mesh.face_region, 2, "face");
}

// Every cell must have positive volume: the vertex tetrahedron, and for P2 also
// det J > 0 at the vertices and the centroid of the curved cell.
void check_positive_cells(const Mesh& mesh, const std::string& source) {
  const std::array<Eigen::Vector3d, 5> probes = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                                 Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1),
                                                 Eigen::Vector3d::Constant(0.25)};
  for (int c = 0; c < mesh.n_cells(); ++c) {
    bool positive = vertex_tet_volume(mesh, c) > 0.0;
    if (mesh.order == 2)
      for (const auto& xi : probes) positive = positive && p2_jacobian_det(mesh, c, xi) > 0.0;
    if (!positive) throw InputError(source, "cell " + std::to_string(c) + " has non-positive volume (inverted)");
  }
}

}  // namespace

void validate_mesh(const Mesh& mesh, const std::string& source) {
  check_shapes(mesh, source);
  check_node_indices(mesh.cells, mesh.n_nodes(), "cells", source);
  check_node_indices(mesh.faces, mesh.n_nodes(), "faces", source);
  check_regions(mesh, source);
  check_positive_cells(mesh, source);
}

}  // namespace morphfem
