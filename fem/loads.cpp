#include "fem/loads.h"

namespace morphfem {

std::vector<int> owned_faces(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& faces) {
  std::vector<int> out;
  const int begin = partition.node_begin[rank], end = partition.node_begin[rank + 1];
  for (int f : faces) {
    const int n0 = mesh.faces(f, 0);
    if (n0 >= begin && n0 < end) out.push_back(f);
  }
  return out;
}

BodyForceTerm::BodyForceTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& cells,
                             VectorField body_force, int quadrature_degree)
    : mesh_(mesh), force_(std::move(body_force)) {
  for (int c : cells)
    if (partition.cell_part[c] == rank) cells_.push_back(c);
  table_ = make_tet_table(mesh.order, quadrature_degree);
}

void BodyForceTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int c = cells_[k];
  nodes.assign(mesh_.cells.row(c).data(), mesh_.cells.row(c).data() + mesh_.nodes_per_cell());
}

double BodyForceTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n = static_cast<int>(s.X.rows());
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  double energy = 0.0;
  for (size_t q = 0; q < table_.points.size(); ++q) {
    const Eigen::VectorXd& N = table_.N[q];
    const Eigen::Matrix3d J0 = s.X.transpose() * table_.dN[q];
    const double dV = table_.points[q].weight * J0.determinant();
    const Eigen::Vector3d X = s.X.transpose() * N, u = s.u.transpose() * N;
    const Eigen::Vector3d b = force_(X, time_);
    energy -= dV * b.dot(u);
    if (g)
      for (int a = 0; a < n; ++a) g->segment<3>(3 * a) -= dV * N[a] * b;
  }
  return energy;
}

SurfaceLoadTerm::SurfaceLoadTerm(const Mesh& mesh, const Partition& partition, int rank,
                                 const std::vector<int>& faces, VectorField traction)
    : mesh_(mesh), faces_(owned_faces(mesh, partition, rank, faces)), traction_(std::move(traction)) {
  table_ = make_triangle_table(mesh.order, 2 * mesh.order);
}

void SurfaceLoadTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int f = faces_[k];
  nodes.assign(mesh_.faces.row(f).data(), mesh_.faces.row(f).data() + mesh_.nodes_per_face());
}

double SurfaceLoadTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n = static_cast<int>(s.X.rows());
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  double energy = 0.0;
  for (size_t q = 0; q < table_.points.size(); ++q) {
    const Eigen::VectorXd& N = table_.N[q];
    const Eigen::MatrixXd& dN = table_.dN[q];
    const Eigen::Vector3d a = s.X.transpose() * dN.col(0), b = s.X.transpose() * dN.col(1);
    const double dA = table_.points[q].weight * a.cross(b).norm();  // reference area element
    const Eigen::Vector3d X = s.X.transpose() * N, u = s.u.transpose() * N;
    const Eigen::Vector3d t = traction_(X, time_);
    energy -= dA * t.dot(u);
    if (g)
      for (int c = 0; c < n; ++c) g->segment<3>(3 * c) -= dA * N[c] * t;
  }
  return energy;
}

}  // namespace morphfem
