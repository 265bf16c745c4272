#include "contact/lattice_floor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "contact/barrier.h"
#include "contact/friction.h"
#include "core/errors.h"
#include "fem/element.h"
#include "fem/term_state.h"

namespace morphfem {

namespace {

const char* const kWhere = "contact.lattice_floor";

// Of the cells scored so far, the one whose smallest barycentric coordinate at X is
// largest (the first one on ties), with that coordinate and X's local coordinates.
struct Located {
  int cell = -1;
  double smallest = -std::numeric_limits<double>::infinity();
  Eigen::Vector3d xi = Eigen::Vector3d::Zero();
};

void score(const Mesh& mesh, int e, const Eigen::Vector3d& X, Located& best) {
  // X = x0 + [x1 - x0, x2 - x0, x3 - x0] xi (the vertices' affine map).
  const Eigen::Vector3d x0 = mesh.X.row(mesh.cells(e, 0)).transpose();
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) J.col(i) = mesh.X.row(mesh.cells(e, i + 1)).transpose() - x0;
  const Eigen::Vector3d xi = J.inverse() * (X - x0);
  const double smallest = std::min(1.0 - xi.sum(), xi.minCoeff());  // smallest barycentric coordinate
  if (smallest > best.smallest) best = Located{e, smallest, xi};
}

int fill(const Mesh& mesh, const Located& best, std::vector<int>& nodes, std::vector<double>& weights) {
  Eigen::VectorXd N;
  Eigen::MatrixXd dN;
  tet_shape(mesh.order, best.xi, N, dN);
  nodes.resize(N.size());
  weights.resize(N.size());
  for (int a = 0; a < N.size(); ++a) {
    nodes[a] = mesh.cells(best.cell, a);
    weights[a] = N[a];
  }
  return best.cell;
}

}  // namespace

int interpolation_weights(const Mesh& mesh, const std::vector<int>& cells, const Eigen::Vector3d& X,
                          std::vector<int>& nodes, std::vector<double>& weights) {
  if (cells.empty()) throw InputError(kWhere, "a lattice voxel without cells");
  Located best;
  for (int e : cells) score(mesh, e, X, best);
  return fill(mesh, best, nodes, weights);
}

namespace {

// Bounding box [lo, hi] of cell e's vertices (its straight shape) [m].
void vertex_box(const Mesh& mesh, int e, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = hi = mesh.X.row(mesh.cells(e, 0)).transpose();
  for (int a = 1; a < 4; ++a) {
    lo = lo.cwiseMin(mesh.X.row(mesh.cells(e, a)).transpose());
    hi = hi.cwiseMax(mesh.X.row(mesh.cells(e, a)).transpose());
  }
}

// Mean largest extent [m] of the cells' vertex boxes (the grid spacing).
double mean_cell_size(const Mesh& mesh, const std::vector<int>& cells) {
  if (cells.empty()) throw InputError(kWhere, "a lattice voxel without cells");
  double sum = 0.0;
  Eigen::Vector3d lo, hi;
  for (int e : cells) {
    vertex_box(mesh, e, lo, hi);
    sum += (hi - lo).maxCoeff();
  }
  return sum / static_cast<double>(cells.size());
}

}  // namespace

CellLocator::CellLocator(const Mesh& mesh, std::vector<int> cells)
    : mesh_(mesh), cells_(std::move(cells)), grid_(mean_cell_size(mesh, cells_)) {
  for (size_t i = 0; i < cells_.size(); ++i) {
    Eigen::Vector3d lo, hi;
    vertex_box(mesh, cells_[i], lo, hi);
    // Widened by a rounding margin, so a point that a cell contains up to the
    // barycentric round-off is still listed with it.
    const Eigen::Vector3d margin = Eigen::Vector3d::Constant(1e-9 * (hi - lo).maxCoeff());
    grid_.insert(static_cast<int>(i), lo - margin, hi + margin);
  }
}

int CellLocator::weights(const Eigen::Vector3d& X, std::vector<int>& nodes, std::vector<double>& weights) const {
  Located best;
  if (const std::vector<int>* listed = grid_.at(X))
    for (int i : *listed) score(mesh_, cells_[i], X, best);  // listed in cells_ order
  if (!(best.smallest >= 0.0)) {                             // no listed cell contains X: the nearest of all
    best = Located{};
    for (int e : cells_) score(mesh_, e, X, best);
  }
  return fill(mesh_, best, nodes, weights);
}

LatticeFloorTerm::LatticeFloorTerm(const Mesh& mesh, const Partition& partition, int rank, LatticeFloorSpec spec,
                                   std::vector<LatticePoint> points)
    : mesh_(mesh), spec_(std::move(spec)) {
  if (!(spec_.normal.norm() > 0)) throw InputError(kWhere, "the floor normal is zero");
  spec_.normal.normalize();
  if (!(spec_.dhat > 0)) throw InputError(kWhere, "dhat [m] must be > 0");
  if (!(spec_.kappa > 0)) throw InputError(kWhere, "kappa [Pa] must be > 0");
  if (!(spec_.eps_v > 0)) throw InputError(kWhere, "eps_v [m/s] must be > 0");
  if (!(spec_.catch_up > 0 && spec_.catch_up < 1)) throw InputError(kWhere, "catch_up must lie in (0, 1)");
  tangent_projector_ = Eigen::Matrix3d::Identity() - spec_.normal * spec_.normal.transpose();
  for (size_t k = 0; k < points.size(); ++k) {
    LatticePoint& p = points[k];
    if (p.nodes.empty() || p.nodes.size() != p.weights.size())
      throw InputError(kWhere, "lattice point " + std::to_string(k) + " has no nodes or mismatched weights");
    double sum = 0.0;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (size_t a = 0; a < p.nodes.size(); ++a) {
      sum += p.weights[a];
      c += p.weights[a] * mesh.X.row(p.nodes[a]).transpose();
    }
    if (std::abs(sum - 1.0) > 1e-9) throw InputError(kWhere, "the weights of a lattice point must sum to 1");
    const double d = spec_.normal.dot(c - spec_.point) - p.radius(0.0);
    if (!(d > 0)) {
      std::ostringstream msg;
      msg << "the sphere of lattice point " << k << " (centre (" << c.transpose() << "), radius " << p.radius(0.0)
          << " m) starts " << -d << " m inside the floor: move the floor's point at least that far down";
      throw InputError(kWhere, msg.str());
    }
    if (partition.cell_part[p.owner_cell] == rank) points_.push_back(std::move(p));
  }
  const size_t n = points_.size();
  mu_.assign(n, 0.0);
  radius_.resize(n);
  for (size_t k = 0; k < n; ++k) radius_[k] = points_[k].radius(0.0);
  lambda_.assign(n, 0.0);
  c0_.assign(n, Eigen::Vector3d::Zero());
  set_time(0.0);
}

void LatticeFloorTerm::set_time(double t) {
  for (size_t k = 0; k < points_.size(); ++k) mu_[k] = points_[k].mu(t);
}

Eigen::Vector3d LatticeFloorTerm::centre(int k, const PieceState& s) const {
  const LatticePoint& p = points_[k];
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (size_t a = 0; a < p.nodes.size(); ++a) c += p.weights[a] * (s.X.row(a) + s.u.row(a)).transpose();
  return c;
}

Eigen::Vector3d LatticeFloorTerm::centre_at(int k, const std::vector<double>& u_local,
                                            const Assembler& assembler) const {
  const LatticePoint& p = points_[k];
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (size_t a = 0; a < p.nodes.size(); ++a) {
    const int node = p.nodes[a];
    c += p.weights[a] * (mesh_.X.row(node).transpose() +
                         Eigen::Vector3d::Map(&u_local[3 * static_cast<size_t>(assembler.node_slot(node))]));
  }
  return c;
}

double LatticeFloorTerm::normal_force(int k, double gap) const {
  if (!(gap > 0)) return std::numeric_limits<double>::infinity();
  return points_[k].area * spec_.kappa * -barrier_dphi(gap / spec_.dhat);
}

void LatticeFloorTerm::begin_step(Assembler& assembler, Vec u0, double t0, double t1) {
  h_ = std::max(t1 - t0, std::numeric_limits<double>::min());
  const std::vector<double>& u_local = assembler.gather(u0);
  for (size_t k = 0; k < points_.size(); ++k) {
    const int kk = static_cast<int>(k);
    c0_[k] = centre_at(kk, u_local, assembler);
    const double height = spec_.normal.dot(c0_[k] - spec_.point);  // centre above the floor [m]
    // Grows until catch_up dhat from the floor, never below the last (feasible) radius.
    radius_[k] = std::min(points_[k].radius(t1), std::max(radius_[k], height - spec_.catch_up * spec_.dhat));
    const double d = height - radius_[k];
    lambda_[k] = d < spec_.dhat ? normal_force(kk, d) : 0.0;
  }
}

// E = A kappa dhat phi(d/dhat) + lambda F(|r|), d = n.(c - p0) - r, r = P (c - c0),
// c = sum w_a x_a: dc/du_a = w_a I, so
//   grad_a = w_a [A kappa phi'(s) n + lambda phi(y)/y r]
//   Hess_ab = w_a w_b [(A kappa / dhat) phi''(s) n n^T + lambda (phi/y P + (phi' - phi/y) rhat rhat^T)].
double LatticeFloorTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const LatticePoint& p = points_[k];
  const int n = static_cast<int>(p.nodes.size());
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  const Eigen::Vector3d c = centre(k, s);
  const double d = spec_.normal.dot(c - spec_.point) - radius_[k];
  if (!(d > 0)) return std::numeric_limits<double>::infinity();
  double energy = 0.0;
  Eigen::Vector3d force = Eigen::Vector3d::Zero();      // dE/dc [N]
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();  // d2E/dc2 [N/m]
  const double sr = d / spec_.dhat;
  if (sr < 1.0) {
    double phi, dphi, d2phi;
    log_barrier(sr, phi, &dphi, &d2phi);
    const double scale = p.area * spec_.kappa;
    energy += scale * spec_.dhat * phi;
    force += scale * dphi * spec_.normal;
    stiffness += (scale * d2phi / spec_.dhat) * spec_.normal * spec_.normal.transpose();
  }
  const double lambda = lambda_[k];
  if (lambda > 0) {
    Eigen::Vector3d friction_force;
    Eigen::Matrix3d friction_stiffness;
    energy += lagged_friction(FrictionLaw{mu_[k], mu_[k], spec_.eps_v * h_}, lambda, tangent_projector_, c - c0_[k],
                              spec_.project_hessian && !exact_hessian_, &friction_force, &friction_stiffness);
    force += friction_force;
    stiffness += friction_stiffness;
  }
  for (int a = 0; a < n; ++a) {
    if (g) g->segment<3>(3 * a) = p.weights[a] * force;
    if (H)
      for (int b = 0; b < n; ++b) H->block<3, 3>(3 * a, 3 * b) = p.weights[a] * p.weights[b] * stiffness;
  }
  return energy;
}

double LatticeFloorTerm::max_step(Assembler& assembler, Vec u, Vec du) {
  const std::vector<double> u_local = assembler.gather(u);  // copy: gather reuses its buffer
  const std::vector<double>& du_local = assembler.gather(du);
  double alpha = 1.0;
  for (size_t k = 0; k < points_.size(); ++k) {
    const int kk = static_cast<int>(k);
    const Eigen::Vector3d c = centre_at(kk, u_local, assembler);
    Eigen::Vector3d dc = Eigen::Vector3d::Zero();
    for (size_t a = 0; a < points_[k].nodes.size(); ++a)
      dc += points_[k].weights[a] *
            Eigen::Vector3d::Map(&du_local[3 * static_cast<size_t>(assembler.node_slot(points_[k].nodes[a]))]);
    const double approach = -spec_.normal.dot(dc);
    if (approach <= 0) continue;
    const double d = spec_.normal.dot(c - spec_.point) - radius_[k];
    alpha = std::min(alpha, std::max(0.0, spec_.max_step_fraction * d / approach));
  }
  double global = alpha;
  MPI_Allreduce(&alpha, &global, 1, MPI_DOUBLE, MPI_MIN, assembler.comm());
  return global;
}

double LatticeFloorTerm::total_normal_force(Assembler& assembler, Vec u) const {
  const std::vector<double>& u_local = assembler.gather(u);
  double local = 0.0;
  for (size_t k = 0; k < points_.size(); ++k) {
    const double d = spec_.normal.dot(centre_at(static_cast<int>(k), u_local, assembler) - spec_.point) - radius_[k];
    if (d < spec_.dhat) local += normal_force(static_cast<int>(k), d);
  }
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, assembler.comm());
  return global;
}

void LatticeFloorTerm::save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) {
  save_rank_data(assembler.comm(), radius_, prefix + ".radius", state);
}

void LatticeFloorTerm::load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) {
  std::vector<double> r = load_rank_data(assembler.comm(), state, prefix + ".radius", "checkpoint: " + prefix);
  if (r.size() != radius_.size())
    throw InputError("checkpoint: " + prefix, "holds " + std::to_string(r.size()) + " lattice radii for this rank, " +
                                                  "the scene has " + std::to_string(radius_.size()));
  radius_ = std::move(r);
}

}  // namespace morphfem
