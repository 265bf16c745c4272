#include "contact/self_contact.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>

#include "contact/barrier.h"
#include "contact/box_grid.h"
#include "contact/ground.h"
#include "core/errors.h"

namespace morphfem {

namespace {

// Second-order forward-mode number over the 12 coordinates of a point-triangle
// pair: value, gradient and Hessian carried together (exact derivatives of the
// distance formulas below, no hand-expanded expressions).
struct Dual {
  double v = 0;
  Eigen::Matrix<double, 12, 1> g = Eigen::Matrix<double, 12, 1>::Zero();
  Eigen::Matrix<double, 12, 12> H = Eigen::Matrix<double, 12, 12>::Zero();
};
Dual variable(double v, int i) {
  Dual d;
  d.v = v;
  d.g[i] = 1.0;
  return d;
}
Dual operator+(const Dual& a, const Dual& b) {
  Dual r;
  r.v = a.v + b.v;
  r.g = a.g + b.g;
  r.H = a.H + b.H;
  return r;
}
Dual operator-(const Dual& a, const Dual& b) {
  Dual r;
  r.v = a.v - b.v;
  r.g = a.g - b.g;
  r.H = a.H - b.H;
  return r;
}
Dual operator*(const Dual& a, const Dual& b) {
  Dual r;
  r.v = a.v * b.v;
  r.g = a.v * b.g + b.v * a.g;
  r.H = a.v * b.H + b.v * a.H + a.g * b.g.transpose() + b.g * a.g.transpose();
  return r;
}
// f(a) with f' = df, f'' = d2f at a.v.
Dual chain(const Dual& a, double f, double df, double d2f) {
  Dual r;
  r.v = f;
  r.g = df * a.g;
  r.H = df * a.H + d2f * a.g * a.g.transpose();
  return r;
}
Dual inverse(const Dual& a) { return chain(a, 1.0 / a.v, -1.0 / (a.v * a.v), 2.0 / (a.v * a.v * a.v)); }

using DualVec = std::array<Dual, 3>;
DualVec sub(const DualVec& a, const DualVec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Dual dot(const DualVec& a, const DualVec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
DualVec cross(const DualVec& a, const DualVec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// Closest feature of triangle (a, b, c) to p: the face (type 3), an edge (type 2,
// vertices i, j) or a vertex (type 1, vertex i); vertex indices 1..3 = a, b, c.
struct Feature {
  int type = 3;
  int i = 1, j = 2;
};

Feature closest_feature(const Eigen::Matrix<double, 4, 3>& x) {
  const Eigen::Vector3d p = x.row(0), a = x.row(1), b = x.row(2), c = x.row(3);
  const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double denom = d00 * d11 - d01 * d01;
  if (denom > 1e-14 * d00 * d11) {
    const double beta = (d11 * d20 - d01 * d21) / denom, gamma = (d00 * d21 - d01 * d20) / denom;
    if (beta >= 0 && gamma >= 0 && beta + gamma <= 1) return Feature{3, 1, 2};
  }
  Feature best{1, 1, 1};
  double best_d2 = std::numeric_limits<double>::infinity();
  const int edges[3][2] = {{1, 2}, {2, 3}, {3, 1}};
  for (const auto& e : edges) {
    const Eigen::Vector3d xi = x.row(e[0]), xj = x.row(e[1]);
    const double len2 = (xj - xi).squaredNorm();
    const double t = len2 > 0 ? std::clamp((p - xi).dot(xj - xi) / len2, 0.0, 1.0) : 0.0;
    const double d2 = (p - (xi + t * (xj - xi))).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      if (t <= 0)
        best = Feature{1, e[0], e[0]};
      else if (t >= 1)
        best = Feature{1, e[1], e[1]};
      else
        best = Feature{2, e[0], e[1]};
    }
  }
  return best;
}

// Squared distances between features, with derivatives.
Dual point_point_d2(const DualVec& p, const DualVec& q) {  // |p - q|^2
  const DualVec r = sub(p, q);
  return dot(r, r);
}
Dual point_line_d2(const DualVec& p, const DualVec& a, const DualVec& b) {  // |(p - a) x (b - a)|^2 / |b - a|^2
  const DualVec e = sub(b, a);
  const DualVec c = cross(sub(p, a), e);
  return dot(c, c) * inverse(dot(e, e));
}
// ((p - a) . n)^2 / |n|^2, n = (b - a) x (c - a)
Dual point_plane_d2(const DualVec& p, const DualVec& a, const DualVec& b, const DualVec& c) {
  const DualVec n = cross(sub(b, a), sub(c, a));
  const Dual h = dot(sub(p, a), n);
  return h * h * inverse(dot(n, n));
}

// ((b0 - a0) . n)^2 / |n|^2, n = (a1 - a0) x (b1 - b0): the distance of two lines
Dual line_line_d2(const DualVec& a0, const DualVec& a1, const DualVec& b0, const DualVec& b1) {
  const DualVec n = cross(sub(a1, a0), sub(b1, b0));
  const Dual h = dot(sub(b0, a0), n);
  return h * h * inverse(dot(n, n));
}

std::array<DualVec, 4> dual_positions(const Eigen::Matrix<double, 4, 3>& x) {
  std::array<DualVec, 4> v;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) v[a][i] = variable(x(a, i), 3 * a + i);
  return v;
}

// Squared distance to the closest feature, with derivatives.
Dual squared_distance(const Eigen::Matrix<double, 4, 3>& x, const Feature& f) {
  const std::array<DualVec, 4> v = dual_positions(x);
  if (f.type == 1) return point_point_d2(v[0], v[f.i]);
  if (f.type == 2) return point_line_d2(v[0], v[f.i], v[f.j]);
  return point_plane_d2(v[0], v[1], v[2], v[3]);
}

double plain_distance(const Eigen::Matrix<double, 4, 3>& x) {
  const Feature f = closest_feature(x);
  const Eigen::Vector3d p = x.row(0);
  if (f.type == 1) return (p - x.row(f.i).transpose()).norm();
  if (f.type == 2) {
    const Eigen::Vector3d xi = x.row(f.i), e = x.row(f.j).transpose() - xi;
    return (p - xi).cross(e).norm() / e.norm();
  }
  const Eigen::Vector3d a = x.row(1), n = (x.row(2).transpose() - a).cross(x.row(3).transpose() - a);
  return std::abs((p - a).dot(n)) / n.norm();
}

// Closest features of segments (x0, x1) and (x2, x3): line-line (type 3, the
// closest points interior to both), point-line (type 2: point p, line i-j) or
// point-point (type 1: p, i); rows 0..3 of x.
struct EdgeFeature {
  int type = 3;
  int p = 0, i = 2, j = 3;
};

EdgeFeature closest_edge_feature(const Eigen::Matrix<double, 4, 3>& x) {
  const Eigen::Vector3d u = x.row(1) - x.row(0), v = x.row(3) - x.row(2), w = x.row(0) - x.row(2);
  const double a = u.dot(u), b = u.dot(v), c = v.dot(v), d = u.dot(w), e = v.dot(w);
  const double D = a * c - b * b;  // |u x v|^2
  if (D > 1e-12 * a * c) {
    // Unconstrained minimiser of |x0 + s u - x2 - t v|^2; inside the unit square it is the minimum.
    const double s = (b * e - c * d) / D, t = (a * e - b * d) / D;
    if (s > 0 && s < 1 && t > 0 && t < 1) return EdgeFeature{3, 0, 2, 3};
  }
  // Otherwise on the square's boundary: the nearest of the four end-point-to-segment distances.
  EdgeFeature best{1, 0, 2, 2};
  double best_d2 = std::numeric_limits<double>::infinity();
  const int cases[4][3] = {{0, 2, 3}, {1, 2, 3}, {2, 0, 1}, {3, 0, 1}};
  for (const auto& cs : cases) {
    const Eigen::Vector3d p = x.row(cs[0]), xi = x.row(cs[1]), xj = x.row(cs[2]);
    const double len2 = (xj - xi).squaredNorm();
    const double t = len2 > 0 ? std::clamp((p - xi).dot(xj - xi) / len2, 0.0, 1.0) : 0.0;
    const double d2 = (p - (xi + t * (xj - xi))).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      if (t <= 0)
        best = EdgeFeature{1, cs[0], cs[1], cs[1]};
      else if (t >= 1)
        best = EdgeFeature{1, cs[0], cs[2], cs[2]};
      else
        best = EdgeFeature{2, cs[0], cs[1], cs[2]};
    }
  }
  return best;
}

double plain_edge_distance(const Eigen::Matrix<double, 4, 3>& x) {
  const EdgeFeature f = closest_edge_feature(x);
  const Eigen::Vector3d p = x.row(f.p);
  if (f.type == 1) return (p - x.row(f.i).transpose()).norm();
  if (f.type == 2) {
    const Eigen::Vector3d xi = x.row(f.i), e = x.row(f.j).transpose() - xi;
    return (p - xi).cross(e).norm() / e.norm();
  }
  const Eigen::Vector3d u = x.row(1) - x.row(0), v = x.row(3) - x.row(2), n = u.cross(v);
  return std::abs((x.row(2) - x.row(0)).dot(n.transpose())) / n.norm();
}

Dual squared_edge_distance(const Eigen::Matrix<double, 4, 3>& x, const EdgeFeature& f) {
  const std::array<DualVec, 4> v = dual_positions(x);
  if (f.type == 1) return point_point_d2(v[f.p], v[f.i]);
  if (f.type == 2) return point_line_d2(v[f.p], v[f.i], v[f.j]);
  return line_line_d2(v[0], v[1], v[2], v[3]);
}

// The triangles of a surface: P1 faces, or each P2 face split at its mid-nodes
// (VTK order: 3 = (0,1), 4 = (1,2), 5 = (0,2)).
void surface_triangles(const Mesh& mesh, const std::vector<int>& faces, std::vector<std::array<int, 3>>& triangles,
                       std::vector<int>& parent) {
  for (int f : faces) {
    const auto F = [&](int a) { return mesh.faces(f, a); };
    if (mesh.order == 1) {
      triangles.push_back({F(0), F(1), F(2)});
      parent.push_back(f);
    } else {
      for (const auto& t : {std::array<int, 3>{F(0), F(3), F(5)}, std::array<int, 3>{F(3), F(1), F(4)},
                            std::array<int, 3>{F(5), F(4), F(2)}, std::array<int, 3>{F(3), F(4), F(5)}}) {
        triangles.push_back(t);
        parent.push_back(f);
      }
    }
  }
}

}  // namespace

double point_triangle_distance(const Eigen::Matrix<double, 4, 3>& x) { return plain_distance(x); }

// E = A kappa dhat phi(d/dhat), d = sqrt(d2) [J], with its gradient and Hessian
// carried by the chain rule from the exact Dual derivatives of d2.
static Dual barrier_of_squared_distance(const Dual& d2, double area, double kappa, double dhat) {
  const double d = std::sqrt(d2.v);
  const Dual dist = chain(d2, d, 0.5 / d, -0.25 / (d * d * d));
  double phi, dphi, d2phi;
  log_barrier(d / dhat, phi, &dphi, &d2phi);
  const double scale = area * kappa;
  return chain(dist, scale * dhat * phi, scale * dphi, scale * d2phi / dhat);
}

// Point-triangle: the barrier of the squared distance to the closest feature.
double point_triangle_barrier(const Eigen::Matrix<double, 4, 3>& x, double area, double kappa, double dhat,
                              Eigen::VectorXd* g, Eigen::MatrixXd* H) {
  if (g) g->setZero(12);
  if (H) H->setZero(12, 12);
  const double d_plain = plain_distance(x);
  if (!(d_plain > 0)) return std::numeric_limits<double>::infinity();
  if (d_plain >= dhat) return 0.0;
  const Dual d2 = squared_distance(x, closest_feature(x));
  if (!(d2.v > 0)) return std::numeric_limits<double>::infinity();
  const Dual e = barrier_of_squared_distance(d2, area, kappa, dhat);
  if (g) *g = e.g;
  if (H) *H = e.H;
  return e.v;
}

double edge_edge_distance(const Eigen::Matrix<double, 4, 3>& x) { return plain_edge_distance(x); }

double edge_edge_mollifier_threshold(const Eigen::Matrix<double, 4, 3>& x_reference) {
  return 1e-3 * (x_reference.row(1) - x_reference.row(0)).squaredNorm() *
         (x_reference.row(3) - x_reference.row(2)).squaredNorm();
}

// E = A m(c) kappa dhat phi(d/dhat), c = |e_a x e_b|^2, m(c) = (2 - c/eps) c/eps
// below eps (1 above): product rule on the exact Dual derivatives of c and d.
double edge_edge_barrier(const Eigen::Matrix<double, 4, 3>& x, double area, double kappa, double dhat, double eps,
                         Eigen::VectorXd* g, Eigen::MatrixXd* H) {
  if (g) g->setZero(12);
  if (H) H->setZero(12, 12);
  const double d_plain = plain_edge_distance(x);
  if (!(d_plain > 0)) return std::numeric_limits<double>::infinity();
  if (d_plain >= dhat) return 0.0;
  const Dual d2 = squared_edge_distance(x, closest_edge_feature(x));
  if (!(d2.v > 0)) return std::numeric_limits<double>::infinity();
  const Dual barrier = barrier_of_squared_distance(d2, area, kappa, dhat);
  const std::array<DualVec, 4> v = dual_positions(x);
  const DualVec n = cross(sub(v[1], v[0]), sub(v[3], v[2]));
  const Dual c = dot(n, n);
  Dual e = barrier;
  if (c.v < eps) {  // m(c) = 2 c/eps - c^2/eps^2, m' = 2/eps - 2 c/eps^2, m'' = -2/eps^2
    const Dual m = chain(c, (2.0 - c.v / eps) * c.v / eps, 2.0 / eps - 2.0 * c.v / (eps * eps), -2.0 / (eps * eps));
    e = m * barrier;
  }
  if (g) *g = e.g;
  if (H) *H = e.H;
  return e.v;
}

namespace {

// The unique edges of a side's triangles with their parent faces and area weights
// A_e = sum over the triangles next to e of area/3 (reference configuration).
void collect_edges(const RowMatrixXd& X, const std::vector<std::array<int, 3>>& triangles,
                   const std::vector<int>& triangle_face, std::vector<std::array<int, 2>>& edges,
                   std::vector<std::vector<int>>& edge_faces, std::vector<double>& edge_weight) {
  std::map<std::array<int, 2>, int> index;
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    const Eigen::Vector3d a = X.row(tri[0]), b = X.row(tri[1]), c = X.row(tri[2]);
    const double area = 0.5 * (b - a).cross(c - a).norm();
    for (int i = 0; i < 3; ++i) {
      const std::array<int, 2> e{std::min(tri[i], tri[(i + 1) % 3]), std::max(tri[i], tri[(i + 1) % 3])};
      auto [it, inserted] = index.emplace(e, static_cast<int>(edges.size()));
      if (inserted) {
        edges.push_back(e);
        edge_faces.emplace_back();
        edge_weight.push_back(0.0);
      }
      auto& faces = edge_faces[it->second];
      if (std::find(faces.begin(), faces.end(), triangle_face[t]) == faces.end()) faces.push_back(triangle_face[t]);
      edge_weight[it->second] += area / 3.0;
    }
  }
}

// The node sets of the surface pairs, merged where pairs share a node: the groups
// whose candidates a rigid motion of the group's nodes leaves unchanged.
template <class Sides>
std::vector<std::vector<int>> rigid_groups(const Sides& sides) {
  std::vector<std::set<int>> groups;
  for (const auto& [a, b] : sides) {
    std::set<int> nodes(a.points.begin(), a.points.end());
    nodes.insert(b.points.begin(), b.points.end());
    for (auto it = groups.begin(); it != groups.end();) {
      const bool shares = std::any_of(it->begin(), it->end(), [&](int n) { return nodes.count(n) > 0; });
      if (shares) {
        nodes.insert(it->begin(), it->end());
        it = groups.erase(it);
      } else {
        ++it;
      }
    }
    groups.push_back(std::move(nodes));
  }
  std::vector<std::vector<int>> out;
  for (const auto& g : groups) out.emplace_back(g.begin(), g.end());
  return out;
}

}  // namespace

SelfContactTerm::SelfContactTerm(const Mesh& mesh, const Partition& partition, int rank, SelfContactSpec spec)
    : mesh_(mesh), spec_(std::move(spec)) {
  const std::string where = "self_contact." + spec_.name;
  if (spec_.pairs.empty()) throw InputError(where, "no surface pairs given");
  if (spec_.dhat <= 0) spec_.dhat = 1e-3 * (mesh.X.colwise().maxCoeff() - mesh.X.colwise().minCoeff()).norm();
  if (spec_.kappa <= 0) spec_.kappa = spec_.young_modulus;
  if (!(spec_.kappa > 0))
    throw InputError(where, "the barrier stiffness kappa [Pa] is not set (give kappa or the Young's modulus)");
  if (spec_.inflation <= 0) spec_.inflation = 20 * spec_.dhat;
  spec_.max_trust_radius = std::max(spec_.max_trust_radius, 0.5 * spec_.inflation);
  if (!(spec_.max_step_fraction > 0 && spec_.max_step_fraction < 1))
    throw InputError(where, "max_step_fraction must lie in (0, 1)");
  rank_begin_ = partition.node_begin[rank];
  rank_end_ = partition.node_begin[rank + 1];

  std::vector<int> all_faces;
  std::set<int> surface_nodes;
  for (const auto& [first, second] : spec_.pairs) {
    std::pair<Side, Side> sides;
    for (auto [name, side] : {std::pair{first, &sides.first}, std::pair{second, &sides.second}}) {
      const std::vector<int> faces = mesh.faces_of(name);
      all_faces.insert(all_faces.end(), faces.begin(), faces.end());
      side->points = mesh.nodes_of_surface(name);
      surface_triangles(mesh, faces, side->triangles, side->triangle_face);
      collect_edges(mesh.X, side->triangles, side->triangle_face, side->edges, side->edge_faces, side->edge_weight);
      surface_nodes.insert(side->points.begin(), side->points.end());
    }
    sides_.push_back(std::move(sides));
  }
  std::sort(all_faces.begin(), all_faces.end());
  all_faces.erase(std::unique(all_faces.begin(), all_faces.end()), all_faces.end());
  weight_ = nodal_area_weights(mesh, all_faces);
  surface_nodes_.assign(surface_nodes.begin(), surface_nodes.end());
  rigid_groups_ = rigid_groups(sides_);
  for (int a : surface_nodes_)
    if (a >= rank_begin_ && a < rank_end_) trust_nodes_.push_back(a);
  anchor_.assign(mesh.n_nodes(), Eigen::Vector3d::Zero());
  searched_ = anchor_;
  build_candidates(mesh.X);
  const RowMatrixXd zero = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  for (const Pair& pr : pairs_)
    if (!(plain_distance(positions({pr.point, pr.triangle[0], pr.triangle[1], pr.triangle[2]}, zero)) > 0))
      throw InputError(where, "surfaces touch at the start (node " + std::to_string(pr.point) + ")");
  for (const EdgePair& ep : edge_pairs_)
    if (!(plain_edge_distance(positions(ep.nodes, zero)) > 0))
      throw InputError(where, "surfaces touch at the start (edges " + std::to_string(ep.nodes[0]) + "-" +
                                  std::to_string(ep.nodes[1]) + " and " + std::to_string(ep.nodes[2]) + "-" +
                                  std::to_string(ep.nodes[3]) + ")");
  if (spec_.start > -std::numeric_limits<double>::infinity()) {  // off until start (refresh_pieces)
    active_ = false;
    pairs_.clear();
    edge_pairs_.clear();
  }
}

Eigen::Matrix<double, 4, 3> SelfContactTerm::positions(const std::array<int, 4>& nodes, const RowMatrixXd& u) const {
  Eigen::Matrix<double, 4, 3> x;
  for (int a = 0; a < 4; ++a) x.row(a) = mesh_.X.row(nodes[a]) + u.row(nodes[a]);
  return x;
}

// Uniform grids of bounding boxes inflated by reach = dhat + r. A (point,
// triangle) pair is a candidate if the point is not a node of the triangle's face
// and their distance is below reach (only points this rank owns); an edge pair if
// the edges share no node and no parent face and their distance is below reach
// (only pairs whose smallest node this rank owns). With far nodes (R > r/2) the
// grids reach dhat + 2R and every rank measures every pair out to there, so the trust
// radii are the same on every rank.
namespace {

// Axis-aligned bounding box [lo, hi] of the positions x of `nodes` [m].
template <class Nodes>
void bounding_box(const RowMatrixXd& x, const Nodes& nodes, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  lo = x.row(nodes[0]);
  hi = lo;
  for (size_t i = 1; i < nodes.size(); ++i) {
    lo = lo.cwiseMin(x.row(nodes[i]).transpose());
    hi = hi.cwiseMax(x.row(nodes[i]).transpose());
  }
}

}  // namespace

// One candidate search: pairs closer than reach = dhat + inflation are candidates;
// pairs closer than search = dhat + 2 R_max but not candidates bound the trust radii
// through the nearest non-candidate distance per node.
struct SelfContactTerm::CandidateSearch {
  double reach = 0, search = 0;  // [m]
  bool far = false;              // search > reach: pairs of other ranks bound the radii too
  std::vector<double> nearest;   // per mesh node: nearest non-candidate distance [m]
  std::set<std::tuple<int, int, int, int>> seen;
  std::set<std::array<int, 4>> seen_edges;

  template <class... Nodes>
  void note(double d, Nodes... nodes) {
    ((nearest[nodes] = std::min(nearest[nodes], d)), ...);
  }
};

// Points of `points` against triangles of `tris`: triangles in every cell their box
// inflated by `search` touches; each point looks in its own cell (cells at least as
// large as any triangle edge).
void SelfContactTerm::point_triangle_candidates(const Side& points, const Side& tris, const RowMatrixXd& x,
                                                CandidateSearch& s) {
  double size = s.search;
  for (const auto& t : tris.triangles)
    for (int i = 0; i < 3; ++i) size = std::max(size, (x.row(t[i]) - x.row(t[(i + 1) % 3])).cwiseAbs().maxCoeff());
  BoxGrid grid(size);
  for (size_t t = 0; t < tris.triangles.size(); ++t) {
    Eigen::Vector3d lo, hi;
    bounding_box(x, tris.triangles[t], lo, hi);
    grid.insert(static_cast<int>(t), (lo.array() - s.search).matrix(), (hi.array() + s.search).matrix());
  }
  for (int p : points.points) {
    const bool owned = p >= rank_begin_ && p < rank_end_;
    if (!owned && !s.far) continue;
    const std::vector<int>* listed = grid.at(x.row(p).transpose());
    if (listed == nullptr) continue;
    for (int t : *listed) {
      const auto& tri = tris.triangles[t];
      const int face = tris.triangle_face[t];
      bool own = false;
      for (int a = 0; a < mesh_.nodes_per_face(); ++a) own = own || mesh_.faces(face, a) == p;
      if (own) continue;
      Eigen::Matrix<double, 4, 3> xs;
      xs.row(0) = x.row(p);
      for (int i = 0; i < 3; ++i) xs.row(i + 1) = x.row(tri[i]);
      const double d = plain_distance(xs);
      if (d >= s.search) continue;
      if (d >= s.reach) {
        s.note(d, p, tri[0], tri[1], tri[2]);
      } else if (owned && s.seen.insert({p, tri[0], tri[1], tri[2]}).second) {
        pairs_.push_back(Pair{p, tri});
      }
    }
  }
}

// Edge pairs: edges of B in every cell their inflated box touches; each edge of A
// looks in the cells of its own box (cells at least as large as any edge). Edges
// sharing a node or a face are skipped; A_ee' = (A_e + A_e') / 2.
void SelfContactTerm::edge_edge_candidates(const Side& side_a, const Side& side_b, const RowMatrixXd& x,
                                           CandidateSearch& s) {
  double size = s.search;
  for (const auto& e : side_b.edges) size = std::max(size, (x.row(e[0]) - x.row(e[1])).cwiseAbs().maxCoeff());
  for (const auto& e : side_a.edges) size = std::max(size, (x.row(e[0]) - x.row(e[1])).cwiseAbs().maxCoeff());
  BoxGrid grid(size);
  for (size_t k = 0; k < side_b.edges.size(); ++k) {
    Eigen::Vector3d lo, hi;
    bounding_box(x, side_b.edges[k], lo, hi);
    grid.insert(static_cast<int>(k), (lo.array() - s.search).matrix(), (hi.array() + s.search).matrix());
  }
  std::set<int> near;
  for (size_t ka = 0; ka < side_a.edges.size(); ++ka) {
    const auto& ea = side_a.edges[ka];
    Eigen::Vector3d lo, hi;
    bounding_box(x, ea, lo, hi);
    near.clear();
    grid.near(lo, hi, near);
    for (int kb : near) {
      const auto& eb = side_b.edges[kb];
      if (ea[0] == eb[0] || ea[0] == eb[1] || ea[1] == eb[0] || ea[1] == eb[1]) continue;
      const int smallest = std::min(std::min(ea[0], ea[1]), std::min(eb[0], eb[1]));
      const bool owned = smallest >= rank_begin_ && smallest < rank_end_;
      if (!owned && !s.far) continue;
      bool shared_face = false;
      for (int f : side_a.edge_faces[ka])
        for (int g : side_b.edge_faces[kb]) shared_face = shared_face || f == g;
      if (shared_face) continue;
      // One orientation per unordered pair (the same surface on both sides).
      const std::array<int, 4> key =
          ea < eb ? std::array<int, 4>{ea[0], ea[1], eb[0], eb[1]} : std::array<int, 4>{eb[0], eb[1], ea[0], ea[1]};
      Eigen::Matrix<double, 4, 3> xs;
      for (int i = 0; i < 4; ++i) xs.row(i) = x.row(key[i]);
      const double d = plain_edge_distance(xs);
      if (d >= s.search) continue;
      if (d >= s.reach) {
        s.note(d, key[0], key[1], key[2], key[3]);
        continue;
      }
      if (!owned || !s.seen_edges.insert(key).second) continue;
      Eigen::Matrix<double, 4, 3> xref;
      for (int i = 0; i < 4; ++i) xref.row(i) = mesh_.X.row(key[i]);
      edge_pairs_.push_back(
          EdgePair{key, 0.5 * (side_a.edge_weight[ka] + side_b.edge_weight[kb]), edge_edge_mollifier_threshold(xref)});
    }
  }
}

void SelfContactTerm::build_candidates(const RowMatrixXd& x) {
  pairs_.clear();
  edge_pairs_.clear();
  CandidateSearch s;
  s.reach = spec_.dhat + spec_.inflation;              // candidates
  s.search = spec_.dhat + 2 * spec_.max_trust_radius;  // trust radii (>= reach)
  s.far = s.search > s.reach;
  s.nearest.assign(mesh_.n_nodes(), std::numeric_limits<double>::infinity());
  for (const auto& [side_a, side_b] : sides_) {
    point_triangle_candidates(side_a, side_b, x, s);
    point_triangle_candidates(side_b, side_a, x, s);
    if (spec_.edge_edge) edge_edge_candidates(side_a, side_b, x, s);
  }
  // rho = min((d - dhat)/2, R) with d the nearest non-candidate distance.
  trust_radius_.assign(mesh_.n_nodes(), 0.0);
  for (int a : surface_nodes_) trust_radius_[a] = std::min(0.5 * (s.nearest[a] - spec_.dhat), spec_.max_trust_radius);
}

void SelfContactTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int n_pairs = static_cast<int>(pairs_.size()), n_edge = static_cast<int>(edge_pairs_.size());
  if (k < n_pairs) {
    const Pair& p = pairs_[k];
    nodes = {p.point, p.triangle[0], p.triangle[1], p.triangle[2]};
  } else if (k < n_pairs + n_edge) {
    const auto& e = edge_pairs_[k - n_pairs].nodes;
    nodes.assign(e.begin(), e.end());
  } else {
    nodes.assign(1, trust_nodes_[k - n_pairs - n_edge]);
  }
}

double SelfContactTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n_pairs = static_cast<int>(pairs_.size()), n_edge = static_cast<int>(edge_pairs_.size());
  if (k >= n_pairs + n_edge) {  // trust region: |u - u_c| <= rho
    if (g) g->setZero(3);
    if (H) H->setZero(3, 3);
    const int node = trust_nodes_[k - n_pairs - n_edge];
    const double moved = (s.u.row(0).transpose() - anchor_[node]).norm();
    return moved <= trust_radius_[node] ? 0.0 : std::numeric_limits<double>::infinity();
  }
  const Eigen::Matrix<double, 4, 3> x = s.X + s.u;
  double e;
  if (k < n_pairs) {
    e = point_triangle_barrier(x, weight_[pairs_[k].point], spec_.kappa, spec_.dhat, g, H);
  } else {
    const EdgePair& ep = edge_pairs_[k - n_pairs];
    e = edge_edge_barrier(x, ep.weight, spec_.kappa, spec_.dhat, ep.eps, g, H);
  }
  if (H && spec_.project_hessian && !exact_hessian_ && std::isfinite(e) && e > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(*H);
    const Eigen::VectorXd lambda = es.eigenvalues().cwiseMax(0.0);
    *H = es.eigenvectors() * lambda.asDiagonal() * es.eigenvectors().transpose();
  }
  return e;
}

double SelfContactTerm::max_step(Assembler& assembler, Vec u, Vec du) {
  if (!active_) return 1.0;  // the same on every rank
  const std::vector<double> u_local = assembler.gather(u);
  const std::vector<double>& du_local = assembler.gather(du);
  const auto U = [&](int n) { return Eigen::Vector3d::Map(&u_local[3 * assembler.node_slot(n)]); };
  const auto dU = [&](int n) { return Eigen::Vector3d::Map(&du_local[3 * assembler.node_slot(n)]); };
  const auto current = [&](const std::array<int, 4>& nodes) {
    Eigen::Matrix<double, 4, 3> x;
    for (int a = 0; a < 4; ++a) x.row(a) = mesh_.X.row(nodes[a]) + U(nodes[a]).transpose();
    return x;
  };
  double alpha = 1.0;
  for (const Pair& pr : pairs_) {
    double L = 0.0;
    for (int i = 0; i < 3; ++i) L = std::max(L, (dU(pr.triangle[i]) - dU(pr.point)).norm());
    if (L <= 0) continue;
    const double d = plain_distance(current({pr.point, pr.triangle[0], pr.triangle[1], pr.triangle[2]}));
    alpha = std::min(alpha, spec_.max_step_fraction * d / L);
  }
  for (const EdgePair& ep : edge_pairs_) {
    const auto& n = ep.nodes;
    const Eigen::Vector3d origin = dU(n[0]);
    const double La = (dU(n[1]) - origin).norm();
    const double Lb = std::max((dU(n[2]) - origin).norm(), (dU(n[3]) - origin).norm());
    const double L = La + Lb;
    if (L <= 0) continue;
    alpha = std::min(alpha, spec_.max_step_fraction * plain_edge_distance(current(n)) / L);
  }
  // Trust region: largest alpha with |a + alpha b| <= rho, a = u - u_c, b = du.
  for (int n : trust_nodes_) {
    const double R = trust_radius_[n];
    const Eigen::Vector3d a = U(n) - anchor_[n], b = dU(n);
    const double bb = b.squaredNorm();
    if (bb <= 0) continue;
    const double ab = a.dot(b), rest = std::max(0.0, R * R - a.squaredNorm());
    alpha = std::min(alpha, 0.999 * (-ab + std::sqrt(ab * ab + bb * rest)) / bb);
  }
  alpha = std::max(alpha, 0.0);
  double global = alpha;
  MPI_Allreduce(&alpha, &global, 1, MPI_DOUBLE, MPI_MIN, assembler.comm());
  return global;
}

bool SelfContactTerm::refresh_pieces(Assembler& assembler, Vec u0) {
  if (!active_ && !(time_ >= spec_.start)) return false;  // the same time on every rank
  return refresh_pieces(assembler.gather_all(u0));        // the same field on every rank: the same decision
}

bool SelfContactTerm::refresh_pieces(const RowMatrixXd& U) {
  if (!active_ && !(time_ >= spec_.start)) return false;
  if (!active_) {
    active_ = true;
    refresh(U);
    return true;
  }
  // Rigid re-anchoring. A pair's distance is invariant under a rigid motion of its
  // nodes, so the candidates of the surface pairs of a group (pairs that share no node
  // with other groups, e.g. one chamber's walls) found at anchor positions y are
  // exactly those at Q y, and the group's trust region may be centred there. Q is the
  // least-squares fit (Umeyama, no scaling) of y to the current positions x over the
  // group's nodes; the candidates are kept while |x - Q y| <= rho/2 at every node.
  // A body that rolls, falls or curls without deforming its contact surfaces then
  // rebuilds them (and the assembly pattern) only when they deform.
  const auto within = [&](const std::vector<int>& group, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xd& y) {
    for (Eigen::Index i = 0; i < x.cols(); ++i)
      if ((x.col(i) - y.col(i)).norm() > 0.5 * trust_radius_[group[i]]) return false;
    return true;
  };
  std::vector<Eigen::Matrix3Xd> fitted;
  bool moved = false;
  for (const std::vector<int>& group : rigid_groups_) {
    const auto n = static_cast<Eigen::Index>(group.size());
    Eigen::Matrix3Xd y(3, n), x(3, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const int a = group[i];
      y.col(i) = mesh_.X.row(a).transpose() + anchor_[a];
      x.col(i) = mesh_.X.row(a).transpose() + U.row(a).transpose();
    }
    if (within(group, x, y)) {
      fitted.push_back(std::move(y));  // Q = I
      continue;
    }
    moved = true;
    const Eigen::Matrix4d Q = Eigen::umeyama(y, x, false);
    fitted.emplace_back((Q.topLeftCorner<3, 3>() * y).colwise() + Q.topRightCorner<3, 1>());
    if (!within(group, x, fitted.back())) {
      refresh(U);
      return true;
    }
  }
  if (moved) {
    for (size_t g = 0; g < rigid_groups_.size(); ++g)
      for (size_t i = 0; i < rigid_groups_[g].size(); ++i) {
        const int a = rigid_groups_[g][i];
        anchor_[a] = fitted[g].col(static_cast<Eigen::Index>(i)) - mesh_.X.row(a).transpose();
      }
    ++n_reanchors_;
  }
  return false;
}

void SelfContactTerm::refresh(Assembler& assembler, Vec u) { refresh(assembler.gather_all(u)); }

void SelfContactTerm::save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) {
  state.integers[prefix + ".active"] = active_;
  state.integers[prefix + ".refreshes"] = n_refreshes_;
  state.integers[prefix + ".reanchors"] = n_reanchors_;
  if (assembler.rank() != 0) return;
  for (const auto& [key, field] : {std::pair{".anchor", &anchor_}, std::pair{".searched", &searched_}}) {
    std::vector<double> flat(3 * field->size());
    for (size_t a = 0; a < field->size(); ++a)
      for (int i = 0; i < 3; ++i) flat[3 * a + i] = (*field)[a][i];
    state.arrays[prefix + key] = std::move(flat);
  }
}

void SelfContactTerm::load_state(Assembler&, const std::string& prefix, const StateRecord& state) {
  const std::string where = "checkpoint: " + prefix;
  active_ = state.integer(prefix + ".active", where) != 0;
  const auto field = [&](const char* key) {
    const auto& flat = state.array(prefix + key, where, 3L * mesh_.n_nodes());
    RowMatrixXd U(mesh_.n_nodes(), 3);
    for (int a = 0; a < mesh_.n_nodes(); ++a)
      for (int i = 0; i < 3; ++i) U(a, i) = flat[3 * a + i];
    return U;
  };
  const RowMatrixXd anchor = field(".anchor"), searched = field(".searched");
  if (active_) {
    refresh(searched);  // the candidates of the last search, from the same positions
  } else {
    pairs_.clear();
    edge_pairs_.clear();
  }
  for (int a = 0; a < mesh_.n_nodes(); ++a) anchor_[a] = anchor.row(a).transpose();  // moved rigidly since
  n_refreshes_ = static_cast<int>(state.integer(prefix + ".refreshes", where));
  n_reanchors_ = static_cast<int>(state.integer(prefix + ".reanchors", where));
}

void SelfContactTerm::refresh(const RowMatrixXd& u) {
  for (int a = 0; a < mesh_.n_nodes(); ++a) anchor_[a] = searched_[a] = u.row(a).transpose();
  build_candidates(mesh_.X + u);
  ++n_refreshes_;
}

double SelfContactTerm::min_distance(Assembler& assembler, Vec u) const {
  const RowMatrixXd U = assembler.gather_all(u);
  double local = std::numeric_limits<double>::infinity();
  for (const Pair& pr : pairs_)
    local = std::min(local, plain_distance(positions({pr.point, pr.triangle[0], pr.triangle[1], pr.triangle[2]}, U)));
  for (const EdgePair& ep : edge_pairs_) local = std::min(local, plain_edge_distance(positions(ep.nodes, U)));
  double global = local;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MIN, assembler.comm());
  return global;
}

SelfContactNodal SelfContactTerm::nodal_contact(const RowMatrixXd& u) const {
  SelfContactNodal out;
  out.force = RowMatrixXd::Zero(mesh_.n_nodes(), 3);
  out.gap.assign(mesh_.n_nodes(), std::numeric_limits<double>::infinity());
  Eigen::VectorXd g;
  const auto add = [&](const std::array<int, 4>& nodes, double d, double e) {
    for (int a = 0; a < 4; ++a) {
      out.gap[nodes[a]] = std::min(out.gap[nodes[a]], d);
      if (std::isfinite(e)) out.force.row(nodes[a]) -= g.segment<3>(3 * a).transpose();
    }
  };
  for (const Pair& pr : pairs_) {
    const std::array<int, 4> nodes{pr.point, pr.triangle[0], pr.triangle[1], pr.triangle[2]};
    const Eigen::Matrix<double, 4, 3> x = positions(nodes, u);
    const double e = point_triangle_barrier(x, weight_[pr.point], spec_.kappa, spec_.dhat, &g, nullptr);
    add(nodes, plain_distance(x), e);
  }
  for (const EdgePair& ep : edge_pairs_) {
    const Eigen::Matrix<double, 4, 3> x = positions(ep.nodes, u);
    const double e = edge_edge_barrier(x, ep.weight, spec_.kappa, spec_.dhat, ep.eps, &g, nullptr);
    add(ep.nodes, plain_edge_distance(x), e);
  }
  return out;
}

SelfContactNodal SelfContactTerm::nodal_contact(Assembler& assembler, Vec u) const {
  SelfContactNodal local = nodal_contact(assembler.gather_all(u)), out;
  out.force = RowMatrixXd::Zero(mesh_.n_nodes(), 3);
  out.gap.assign(mesh_.n_nodes(), 0.0);
  MPI_Allreduce(local.force.data(), out.force.data(), static_cast<int>(local.force.size()), MPI_DOUBLE, MPI_SUM,
                assembler.comm());
  MPI_Allreduce(local.gap.data(), out.gap.data(), static_cast<int>(local.gap.size()), MPI_DOUBLE, MPI_MIN,
                assembler.comm());
  return out;
}

}  // namespace morphfem
