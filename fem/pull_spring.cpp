// Pull spring of a test machine (formulas in pull_spring.h).
#include "fem/pull_spring.h"

#include <algorithm>
#include <map>

#include "core/errors.h"

namespace morphfem {

PullSpringTerm::PullSpringTerm(const Mesh& mesh, int rank, PullSpringSpec spec)
    : mesh_(mesh), rank_(rank), spec_(std::move(spec)) {
  const std::string where = spec_.where.empty() ? "loads.pulls" : spec_.where;
  if (!mesh.has_region(spec_.surface, 2)) throw InputError(where, "no surface region '" + spec_.surface + "'");
  if (!(spec_.stiffness > 0.0)) throw InputError(where, "pull stiffness must be > 0 [N/m]");
  const double speed = spec_.velocity.norm();
  if (!(speed > 0.0)) throw InputError(where, "pull velocity must be a non-zero vector [m/s]");
  direction_ = spec_.velocity / speed;
  // Nodal area weights: a third of each face's area to its corner nodes.
  std::map<int, double> area;
  double total = 0.0;
  for (int f : mesh.faces_of(spec_.surface)) {
    const Eigen::Vector3d p0 = mesh.X.row(mesh.faces(f, 0)).transpose();
    const Eigen::Vector3d p1 = mesh.X.row(mesh.faces(f, 1)).transpose();
    const Eigen::Vector3d p2 = mesh.X.row(mesh.faces(f, 2)).transpose();
    const double A = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    for (int c = 0; c < 3; ++c) area[mesh.faces(f, c)] += A / 3.0;
    total += A;
  }
  if (!(total > 0.0)) throw InputError(where, "surface '" + spec_.surface + "' has no area");
  for (const auto& [node, A] : area) {
    nodes_.push_back(node);
    weights_.push_back(A / total);
  }
  for (size_t a = 0; a < nodes_.size(); ++a) x0_ += weights_[a] * direction_.dot(mesh.X.row(nodes_[a]).transpose());
}

double PullSpringTerm::crosshead(double t) const {
  return x0_ + spec_.velocity.norm() * std::max(0.0, t - spec_.start);
}

double PullSpringTerm::mean_position(const RowMatrixXd& u) const {
  double x = 0.0;
  for (size_t a = 0; a < nodes_.size(); ++a)
    x += weights_[a] * direction_.dot((mesh_.X.row(nodes_[a]) + u.row(nodes_[a])).transpose());
  return x;
}

double PullSpringTerm::piece(int, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n = static_cast<int>(nodes_.size());
  double xbar = 0.0;
  for (int a = 0; a < n; ++a) xbar += weights_[a] * direction_.dot((s.X.row(a) + s.u.row(a)).transpose());
  const double stretch = crosshead(time_) - xbar;  // [m]
  const double k = spec_.stiffness;
  if (g) {
    g->resize(3 * n);
    for (int a = 0; a < n; ++a) g->segment<3>(3 * a) = -k * stretch * weights_[a] * direction_;
  }
  if (H) {
    Eigen::VectorXd b(3 * n);  // d(d . xbar)/du
    for (int a = 0; a < n; ++a) b.segment<3>(3 * a) = weights_[a] * direction_;
    *H = k * b * b.transpose();
  }
  return 0.5 * k * stretch * stretch;
}

}  // namespace morphfem
