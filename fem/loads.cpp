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
  set_time(0.0);
}

void BodyForceTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int c = cells_[k];
  nodes.assign(mesh_.cells.row(c).data(), mesh_.cells.row(c).data() + mesh_.nodes_per_cell());
}

// Nodal forces f_a = int_V N_a b(X, t) dV [N] of every owned cell.
void BodyForceTerm::set_time(double t) {
  if (t == time_ && nodal_force_.size() == cells_.size()) return;
  time_ = t;
  nodal_force_.resize(cells_.size());
  const int n = mesh_.nodes_per_cell();
  Eigen::MatrixXd X(n, 3);
  for (size_t k = 0; k < cells_.size(); ++k) {
    for (int a = 0; a < n; ++a) X.row(a) = mesh_.X.row(mesh_.cells(cells_[k], a));
    Eigen::VectorXd& f = nodal_force_[k];
    f.setZero(3 * n);
    for (size_t q = 0; q < table_.points.size(); ++q) {
      const Eigen::VectorXd& N = table_.N[q];
      const Eigen::Matrix3d J0 = X.transpose() * table_.dN[q];
      const double dV = table_.points[q].weight * J0.determinant();
      const Eigen::Vector3d b = force_(X.transpose() * N, t);
      for (int a = 0; a < n; ++a) f.segment<3>(3 * a) += dV * N[a] * b;
    }
  }
}

double BodyForceTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n = static_cast<int>(s.X.rows());
  const Eigen::VectorXd& f = nodal_force_.at(k);
  if (g) *g = -f;
  if (H) H->setZero(3 * n, 3 * n);
  return -f.dot(Eigen::Map<const Eigen::VectorXd>(Eigen::MatrixXd(s.u.transpose()).data(), 3 * n));
}

SurfaceLoadTerm::SurfaceLoadTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& faces,
                                 VectorField traction)
    : mesh_(mesh), faces_(owned_faces(mesh, partition, rank, faces)), traction_(std::move(traction)) {
  table_ = make_triangle_table(mesh.order, 2 * mesh.order);
  set_time(0.0);
}

void SurfaceLoadTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int f = faces_[k];
  nodes.assign(mesh_.faces.row(f).data(), mesh_.faces.row(f).data() + mesh_.nodes_per_face());
}

// Nodal forces f_a = int_S N_a t(X, t) dA [N] (reference area) of every owned face.
void SurfaceLoadTerm::set_time(double t) {
  if (t == time_ && nodal_force_.size() == faces_.size()) return;
  time_ = t;
  nodal_force_.resize(faces_.size());
  const int n = mesh_.nodes_per_face();
  Eigen::MatrixXd X(n, 3);
  for (size_t k = 0; k < faces_.size(); ++k) {
    for (int a = 0; a < n; ++a) X.row(a) = mesh_.X.row(mesh_.faces(faces_[k], a));
    Eigen::VectorXd& f = nodal_force_[k];
    f.setZero(3 * n);
    for (size_t q = 0; q < table_.points.size(); ++q) {
      const Eigen::VectorXd& N = table_.N[q];
      const Eigen::MatrixXd& dN = table_.dN[q];
      const Eigen::Vector3d a = X.transpose() * dN.col(0), b = X.transpose() * dN.col(1);
      const double dA = table_.points[q].weight * a.cross(b).norm();
      const Eigen::Vector3d traction = traction_(X.transpose() * N, t);
      for (int c = 0; c < n; ++c) f.segment<3>(3 * c) += dA * N[c] * traction;
    }
  }
}

double SurfaceLoadTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n = static_cast<int>(s.X.rows());
  const Eigen::VectorXd& f = nodal_force_.at(k);
  if (g) *g = -f;
  if (H) H->setZero(3 * n, 3 * n);
  return -f.dot(Eigen::Map<const Eigen::VectorXd>(Eigen::MatrixXd(s.u.transpose()).data(), 3 * n));
}

}  // namespace morphfem
