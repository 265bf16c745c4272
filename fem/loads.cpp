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

namespace {

std::vector<int> owned_cells(const Partition& partition, int rank, const std::vector<int>& cells) {
  std::vector<int> out;
  for (int c : cells)
    if (partition.cell_part[c] == rank) out.push_back(c);
  return out;
}

}  // namespace

DeadLoadTerm::DeadLoadTerm(const Mesh& mesh, Entity kind, std::vector<int> entities, VectorField field,
                           ShapeTable table)
    : mesh_(mesh), kind_(kind), entities_(std::move(entities)), field_(std::move(field)), table_(std::move(table)) {
  set_time(0.0);
}

BodyForceTerm::BodyForceTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& cells,
                             VectorField body_force, int quadrature_degree)
    : DeadLoadTerm(mesh, Entity::cell, owned_cells(partition, rank, cells), std::move(body_force),
                   make_tet_table(mesh.order, quadrature_degree)) {}

SurfaceLoadTerm::SurfaceLoadTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& faces,
                                 VectorField traction)
    : DeadLoadTerm(mesh, Entity::face, owned_faces(mesh, partition, rank, faces), std::move(traction),
                   make_triangle_table(mesh.order, 2 * mesh.order)) {}

void DeadLoadTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const auto& rows = kind_ == Entity::cell ? mesh_.cells : mesh_.faces;
  const int e = entities_[k];
  nodes.assign(rows.row(e).data(), rows.row(e).data() + rows.cols());
}

// Nodal forces f_a = sum_q w_q N_a(q) v(X(q), t) dm(q) [N] of every owned entity, with
// dm = det(dX/dxi) for a cell and |dX/dxi_1 x dX/dxi_2| for a face (reference measures).
void DeadLoadTerm::set_time(double t) {
  if (t == time_ && nodal_force_.size() == entities_.size()) return;
  time_ = t;
  nodal_force_.resize(entities_.size());
  const auto& rows = kind_ == Entity::cell ? mesh_.cells : mesh_.faces;
  const int n = static_cast<int>(rows.cols());
  Eigen::MatrixXd X(n, 3);
  for (size_t k = 0; k < entities_.size(); ++k) {
    for (int a = 0; a < n; ++a) X.row(a) = mesh_.X.row(rows(entities_[k], a));
    Eigen::VectorXd& f = nodal_force_[k];
    f.setZero(3 * n);
    for (size_t q = 0; q < table_.points.size(); ++q) {
      const Eigen::VectorXd& N = table_.N[q];
      const Eigen::MatrixXd tangents = X.transpose() * table_.dN[q];  // 3 x dim
      const double measure = kind_ == Entity::cell
                                 ? Eigen::Matrix3d(tangents).determinant()
                                 : Eigen::Vector3d(tangents.col(0)).cross(Eigen::Vector3d(tangents.col(1))).norm();
      const Eigen::Vector3d v = field_(X.transpose() * N, t);
      for (int a = 0; a < n; ++a) f.segment<3>(3 * a) += table_.points[q].weight * measure * N[a] * v;
    }
  }
}

double DeadLoadTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n = static_cast<int>(s.X.rows());
  const Eigen::VectorXd& f = nodal_force_.at(k);
  if (g) *g = -f;
  if (H) H->setZero(3 * n, 3 * n);
  return -f.dot(Eigen::Map<const Eigen::VectorXd>(Eigen::MatrixXd(s.u.transpose()).data(), 3 * n));
}

}  // namespace morphfem
