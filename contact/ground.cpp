#include "contact/ground.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "contact/barrier.h"
#include "core/errors.h"
#include "fem/element.h"

namespace morphfem {

namespace {

// Reference area [m^2] of face f: exact for flat P1 faces, quadrature of |a x b|
// (a, b the tangent vectors) for possibly curved P2 faces.
double face_area(const Mesh& mesh, int f, const ShapeTable& table) {
  if (mesh.order == 1) {
    const Eigen::Vector3d x0 = mesh.X.row(mesh.faces(f, 0)), x1 = mesh.X.row(mesh.faces(f, 1)),
                          x2 = mesh.X.row(mesh.faces(f, 2));
    return 0.5 * (x1 - x0).cross(x2 - x0).norm();
  }
  const int n = mesh.nodes_per_face();
  Eigen::MatrixXd X(n, 3);
  for (int a = 0; a < n; ++a) X.row(a) = mesh.X.row(mesh.faces(f, a));
  double area = 0.0;
  for (size_t q = 0; q < table.points.size(); ++q) {
    const Eigen::Vector3d a = X.transpose() * table.dN[q].col(0), b = X.transpose() * table.dN[q].col(1);
    area += table.points[q].weight * a.cross(b).norm();
  }
  return area;
}

}  // namespace

std::vector<double> nodal_area_weights(const Mesh& mesh, const std::vector<int>& faces) {
  std::vector<double> weight(mesh.n_nodes(), 0.0);
  ShapeTable table;
  if (mesh.order == 2) table = make_triangle_table(2, 4);
  for (int f : faces) {
    const double area = face_area(mesh, f, table);
    if (mesh.order == 1) {
      for (int a = 0; a < 3; ++a) weight[mesh.faces(f, a)] += area / 3.0;
    } else {
      // Four sub-triangles split at the mid-nodes, a third of each to its corners.
      for (int a = 0; a < 3; ++a) weight[mesh.faces(f, a)] += area / 12.0;
      for (int a = 3; a < 6; ++a) weight[mesh.faces(f, a)] += area / 4.0;
    }
  }
  return weight;
}

GroundContactTerm::GroundContactTerm(const Mesh& mesh, const Partition& partition, int rank, GroundContactSpec spec)
    : mesh_(mesh), spec_(std::move(spec)) {
  const std::string where = "contact." + spec_.name;
  if (!(spec_.normal.norm() > 0)) throw InputError(where, "the ground normal is zero");
  spec_.normal.normalize();
  if (spec_.surfaces.empty()) throw InputError(where, "no contact surfaces given");
  if (!(spec_.max_step_fraction > 0 && spec_.max_step_fraction < 1))
    throw InputError(where, "max_step_fraction must lie in (0, 1)");
  if (spec_.dhat <= 0) spec_.dhat = 1e-3 * (mesh.X.colwise().maxCoeff() - mesh.X.colwise().minCoeff()).norm();
  if (spec_.kappa <= 0) spec_.kappa = spec_.young_modulus;
  if (!(spec_.kappa > 0))
    throw InputError(where, "the barrier stiffness kappa [Pa] is not set (give kappa or the Young's modulus)");

  std::vector<int> faces;
  for (const auto& s : spec_.surfaces) {
    const auto fs = mesh.faces_of(s);  // throws InputError naming the known regions
    faces.insert(faces.end(), fs.begin(), fs.end());
  }
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  weight_ = nodal_area_weights(mesh, faces);
  const int begin = partition.node_begin[rank], end = partition.node_begin[rank + 1];
  for (int a = 0; a < mesh.n_nodes(); ++a) {
    if (weight_[a] <= 0) continue;
    all_nodes_.push_back(a);
    if (a >= begin && a < end) owned_nodes_.push_back(a);
    const double d = gap(mesh.X.row(a).transpose());
    if (!(d > 0)) {
      std::ostringstream msg;
      msg << "node " << a << " at (" << mesh.X(a, 0) << ", " << mesh.X(a, 1) << ", " << mesh.X(a, 2)
          << ") starts at gap " << d
          << " m <= 0 from the plane: place the body above it (a gap of about dhat/2 = " << 0.5 * spec_.dhat
          << " m rests in contact)";
      throw InputError(where, msg.str());
    }
  }
}

double GroundContactTerm::normal_force(double area_weight, double d) const {
  if (!(d > 0)) return std::numeric_limits<double>::infinity();
  return area_weight * spec_.kappa * -barrier_dphi(d / spec_.dhat);
}

double GroundContactTerm::resting_gap(double pressure) const {
  if (pressure <= 0) return spec_.dhat;
  double lo = 0.0, hi = 1.0;  // in units of dhat; -phi' decreases from +inf to 0 on (0, 1)
  for (int it = 0; it < 200 && hi - lo > 1e-15; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (spec_.kappa * -barrier_dphi(mid) > pressure)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi) * spec_.dhat;
}

// E = A kappa dhat phi(s), s = d/dhat, d = n.(X + u - p0):
// dE/du = A kappa phi'(s) n,  d2E/du2 = (A kappa / dhat) phi''(s) n n^T.
double GroundContactTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int node = owned_nodes_[k];
  const Eigen::Vector3d x = s.X.row(0).transpose() + s.u.row(0).transpose();
  const double d = gap(x);
  if (g) g->setZero(3);
  if (H) H->setZero(3, 3);
  if (!(d > 0)) return std::numeric_limits<double>::infinity();
  const double sr = d / spec_.dhat;
  if (sr >= 1.0) return 0.0;
  double phi, dphi, d2phi;
  log_barrier(sr, phi, &dphi, &d2phi);
  const double scale = weight_[node] * spec_.kappa;
  if (g) *g = scale * dphi * spec_.normal;
  if (H) *H = (scale * d2phi / spec_.dhat) * spec_.normal * spec_.normal.transpose();
  return scale * spec_.dhat * phi;
}

double GroundContactTerm::max_step(Assembler& assembler, Vec u, Vec du) {
  const std::vector<double> u_local = assembler.gather(u);  // copy: gather reuses its buffer
  const std::vector<double>& du_local = assembler.gather(du);
  double alpha = 1.0;
  for (int node : owned_nodes_) {
    const int slot = assembler.node_slot(node);
    const Eigen::Vector3d x = mesh_.X.row(node).transpose() + Eigen::Vector3d::Map(&u_local[3 * slot]);
    const double approach = -spec_.normal.dot(Eigen::Vector3d::Map(&du_local[3 * slot]));  // closing speed
    if (approach <= 0) continue;
    const double d = gap(x);
    alpha = std::min(alpha, std::max(0.0, spec_.max_step_fraction * d / approach));
  }
  double global = alpha;
  MPI_Allreduce(&alpha, &global, 1, MPI_DOUBLE, MPI_MIN, assembler.comm());
  return global;
}

GroundContactTerm::NodalContact GroundContactTerm::nodal_contact(Assembler& assembler, Vec u) const {
  const int n = mesh_.n_nodes();
  const std::vector<double>& u_local = assembler.gather(u);
  // Owned values, summed over ranks (each node is owned once).
  std::vector<double> buffer(5 * static_cast<size_t>(n), 0.0);  // force (3), gap, status
  for (int node : owned_nodes_) {
    const int slot = assembler.node_slot(node);
    const Eigen::Vector3d x = mesh_.X.row(node).transpose() + Eigen::Vector3d::Map(&u_local[3 * slot]);
    const double d = gap(x);
    const double f = d < spec_.dhat ? normal_force(weight_[node], d) : 0.0;
    for (int i = 0; i < 3; ++i) buffer[5 * node + i] = f * spec_.normal[i];
    buffer[5 * node + 3] = d;
    buffer[5 * node + 4] = d < spec_.dhat ? 1.0 : 0.0;
  }
  std::vector<double> sum(buffer.size(), 0.0);
  MPI_Allreduce(buffer.data(), sum.data(), static_cast<int>(sum.size()), MPI_DOUBLE, MPI_SUM, assembler.comm());
  NodalContact out;
  out.force.setZero(n, 3);
  out.gap.assign(n, std::numeric_limits<double>::quiet_NaN());
  out.status.assign(n, 0);
  for (int node : all_nodes_) {
    for (int i = 0; i < 3; ++i) out.force(node, i) = sum[5 * node + i];
    out.gap[node] = sum[5 * node + 3];
    out.status[node] = sum[5 * node + 4] > 0.5 ? 1 : 0;
  }
  return out;
}

Eigen::Vector3d GroundContactTerm::total_force(Assembler& assembler, Vec u) const {
  const NodalContact c = nodal_contact(assembler, u);
  return c.force.colwise().sum().transpose();
}

double GroundContactTerm::min_gap(Assembler& assembler, Vec u) const {
  const std::vector<double>& u_local = assembler.gather(u);
  double local = std::numeric_limits<double>::infinity();
  for (int node : owned_nodes_) {
    const int slot = assembler.node_slot(node);
    local = std::min(local, gap(mesh_.X.row(node).transpose() + Eigen::Vector3d::Map(&u_local[3 * slot])));
  }
  double global = local;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MIN, assembler.comm());
  return global;
}

}  // namespace morphfem
