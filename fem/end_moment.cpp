// Conservative end moment (formulas in end_moment.h).
#include "fem/end_moment.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "fem/assembly.h"

namespace morphfem {

namespace {
constexpr double kTwoPi = 6.28318530717958647692;
}  // namespace

EndMomentTerm::EndMomentTerm(const Mesh& mesh, const Partition& partition, int rank, std::vector<int> section_nodes,
                             int axis, int across, std::function<double(double)> moment)
    : mesh_(mesh), nodes_(std::move(section_nodes)), axis_(axis), across_(across), moment_(std::move(moment)) {
  if (nodes_.size() < 2) throw std::invalid_argument("end moment: the section needs at least two nodes");
  if (axis < 0 || axis > 2 || across < 0 || across > 2 || axis == across)
    throw std::invalid_argument("end moment: axis and across must be distinct components 0..2");
  // c_a = (Z_a - Zbar) / sum_b (Z_b - Zbar)^2, Z = reference coordinate `across` [m].
  const int n = static_cast<int>(nodes_.size());
  double mean = 0.0;
  for (int a = 0; a < n; ++a) mean += mesh.X(nodes_[a], across) / n;
  weights_.resize(n);
  double spread = 0.0;
  for (int a = 0; a < n; ++a) {
    weights_[a] = mesh.X(nodes_[a], across) - mean;
    spread += weights_[a] * weights_[a];
  }
  if (!(spread > 0.0)) throw std::invalid_argument("end moment: the section nodes have no extent across the beam");
  weights_ /= spread;
  Eigen::MatrixXd X(n, 3);
  for (int a = 0; a < n; ++a) X.row(a) = mesh.X.row(nodes_[a]);
  const Eigen::Vector3d d = X.transpose() * weights_;
  theta0_ = std::atan2(-d[axis_], d[across_]);
  const int first = nodes_[0];
  owner_ = first >= partition.node_begin[rank] && first < partition.node_begin[rank + 1];
}

void EndMomentTerm::piece_nodes(int, std::vector<int>& nodes) const { nodes = nodes_; }

double EndMomentTerm::angle_of_positions(const Eigen::MatrixXd& x) const {
  const Eigen::Vector3d d = x.transpose() * weights_;
  const double raw = std::atan2(-d[axis_], d[across_]) - theta0_;
  // The value within pi of the last converged angle.
  return branch_ + std::remainder(raw - branch_, kTwoPi);
}

double EndMomentTerm::angle(const RowMatrixXd& u) const {
  Eigen::MatrixXd x(nodes_.size(), 3);
  for (size_t a = 0; a < nodes_.size(); ++a) x.row(a) = mesh_.X.row(nodes_[a]) + u.row(nodes_[a]);
  return angle_of_positions(x);
}

double EndMomentTerm::piece(int, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const Eigen::MatrixXd x = s.X + s.u;
  const Eigen::Vector3d d = x.transpose() * weights_;
  const double p = d[axis_], q = d[across_], r2 = p * p + q * q;
  if (!(r2 > 0.0)) return std::numeric_limits<double>::infinity();  // collapsed section
  const double theta = angle_of_positions(x);
  const double M = moment_now_;
  const int n = static_cast<int>(nodes_.size());
  if (g) {
    // dtheta/dd: (-q, p) / r^2 in (axis, across)
    Eigen::Vector3d dtheta = Eigen::Vector3d::Zero();
    dtheta[axis_] = -q / r2;
    dtheta[across_] = p / r2;
    g->setZero(3 * n);
    for (int a = 0; a < n; ++a) g->segment<3>(3 * a) = -M * weights_[a] * dtheta;
  }
  if (H) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();  // d2theta/dd2
    const double r4 = r2 * r2;
    h(axis_, axis_) = 2.0 * p * q / r4;
    h(axis_, across_) = h(across_, axis_) = (q * q - p * p) / r4;
    h(across_, across_) = -2.0 * p * q / r4;
    H->setZero(3 * n, 3 * n);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) H->block<3, 3>(3 * a, 3 * b) = -M * weights_[a] * weights_[b] * h;
  }
  return -M * theta;
}

// Collective (every rank gathers the field and follows the same branch).
void EndMomentTerm::begin_step(Assembler& assembler, Vec u0, double, double) { follow(assembler.gather_all(u0)); }

void EndMomentTerm::end_step(Assembler& assembler, Vec u1, double) { follow(assembler.gather_all(u1)); }

}  // namespace morphfem
