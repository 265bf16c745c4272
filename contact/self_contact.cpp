#include "contact/self_contact.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>

#include "contact/barrier.h"
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

// Squared distance to the closest feature, with derivatives.
Dual squared_distance(const Eigen::Matrix<double, 4, 3>& x, const Feature& f) {
  std::array<DualVec, 4> v;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) v[a][i] = variable(x(a, i), 3 * a + i);
  const DualVec& p = v[0];
  if (f.type == 1) {  // |p - x_i|^2
    const DualVec r = sub(p, v[f.i]);
    return dot(r, r);
  }
  if (f.type == 2) {  // |(p - x_i) x (x_j - x_i)|^2 / |x_j - x_i|^2
    const DualVec e = sub(v[f.j], v[f.i]);
    const DualVec c = cross(sub(p, v[f.i]), e);
    return dot(c, c) * inverse(dot(e, e));
  }
  // ((p - a) . n)^2 / |n|^2, n = (b - a) x (c - a)
  const DualVec n = cross(sub(v[2], v[1]), sub(v[3], v[1]));
  const Dual h = dot(sub(p, v[1]), n);
  return h * h * inverse(dot(n, n));
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

// E = A kappa dhat phi(d/dhat), d = sqrt(d2): derivatives by the chain rule on
// the exact Dual derivatives of d2 for the closest feature.
double point_triangle_barrier(const Eigen::Matrix<double, 4, 3>& x, double area, double kappa, double dhat,
                              Eigen::VectorXd* g, Eigen::MatrixXd* H) {
  if (g) g->setZero(12);
  if (H) H->setZero(12, 12);
  const double d_plain = plain_distance(x);
  if (!(d_plain > 0)) return std::numeric_limits<double>::infinity();
  if (d_plain >= dhat) return 0.0;
  const Dual d2 = squared_distance(x, closest_feature(x));
  if (!(d2.v > 0)) return std::numeric_limits<double>::infinity();
  const double d = std::sqrt(d2.v);
  const Dual dist = chain(d2, d, 0.5 / d, -0.25 / (d * d * d));
  double phi, dphi, d2phi;
  log_barrier(d / dhat, phi, &dphi, &d2phi);
  const double scale = area * kappa;
  const Dual e = chain(dist, scale * dhat * phi, scale * dphi, scale * d2phi / dhat);
  if (g) *g = e.g;
  if (H) *H = e.H;
  return e.v;
}

SelfContactTerm::SelfContactTerm(const Mesh& mesh, const Partition& partition, int rank, SelfContactSpec spec)
    : mesh_(mesh), spec_(std::move(spec)) {
  const std::string where = "self_contact." + spec_.name;
  if (spec_.pairs.empty()) throw InputError(where, "no surface pairs given");
  if (spec_.dhat <= 0) spec_.dhat = 1e-3 * (mesh.X.colwise().maxCoeff() - mesh.X.colwise().minCoeff()).norm();
  if (spec_.kappa <= 0) spec_.kappa = spec_.young_modulus;
  if (!(spec_.kappa > 0))
    throw InputError(where, "the barrier stiffness kappa [Pa] is not set (give kappa or the Young's modulus)");
  if (spec_.inflation <= 0) spec_.inflation = 20 * spec_.dhat;
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
      surface_nodes.insert(side->points.begin(), side->points.end());
    }
    sides_.push_back(std::move(sides));
  }
  std::sort(all_faces.begin(), all_faces.end());
  all_faces.erase(std::unique(all_faces.begin(), all_faces.end()), all_faces.end());
  weight_ = nodal_area_weights(mesh, all_faces);
  for (int a : surface_nodes)
    if (a >= rank_begin_ && a < rank_end_) trust_nodes_.push_back(a);
  anchor_.assign(mesh.n_nodes(), Eigen::Vector3d::Zero());
  build_candidates(mesh.X);
  for (const Pair& pr : pairs_) {
    Eigen::Matrix<double, 4, 3> x;
    x.row(0) = mesh.X.row(pr.point);
    for (int i = 0; i < 3; ++i) x.row(i + 1) = mesh.X.row(pr.triangle[i]);
    if (!(plain_distance(x) > 0))
      throw InputError(where, "surfaces touch at the start (node " + std::to_string(pr.point) + ")");
  }
}

// Uniform grid of triangle boxes inflated by dhat + r; a (point, triangle) pair is
// a candidate if the point is a node of neither the triangle's face and their
// distance is below dhat + r. Only points this rank owns.
void SelfContactTerm::build_candidates(const RowMatrixXd& x) {
  pairs_.clear();
  const double reach = spec_.dhat + spec_.inflation;
  std::set<std::tuple<int, int, int, int>> seen;
  for (const auto& [side_a, side_b] : sides_)
    for (const auto& [points, tris] : {std::pair{&side_a, &side_b}, std::pair{&side_b, &side_a}}) {
      double size = reach;
      for (const auto& t : tris->triangles)
        for (int i = 0; i < 3; ++i) size = std::max(size, (x.row(t[i]) - x.row(t[(i + 1) % 3])).cwiseAbs().maxCoeff());
      const auto cell = [&](const Eigen::Vector3d& y) {
        return std::make_tuple(static_cast<long>(std::floor(y[0] / size)), static_cast<long>(std::floor(y[1] / size)),
                               static_cast<long>(std::floor(y[2] / size)));
      };
      std::map<std::tuple<long, long, long>, std::vector<int>> grid;
      for (size_t t = 0; t < tris->triangles.size(); ++t) {
        Eigen::Vector3d lo = x.row(tris->triangles[t][0]), hi = lo;
        for (int i = 1; i < 3; ++i) {
          lo = lo.cwiseMin(x.row(tris->triangles[t][i]).transpose());
          hi = hi.cwiseMax(x.row(tris->triangles[t][i]).transpose());
        }
        const auto [x0, y0, z0] = cell((lo.array() - reach).matrix());
        const auto [x1, y1, z1] = cell((hi.array() + reach).matrix());
        for (long i = x0; i <= x1; ++i)
          for (long j = y0; j <= y1; ++j)
            for (long k = z0; k <= z1; ++k) grid[{i, j, k}].push_back(static_cast<int>(t));
      }
      for (int p : points->points) {
        if (p < rank_begin_ || p >= rank_end_) continue;
        const auto it = grid.find(cell(x.row(p).transpose()));
        if (it == grid.end()) continue;
        for (int t : it->second) {
          const auto& tri = tris->triangles[t];
          const int face = tris->triangle_face[t];
          bool own = false;
          for (int a = 0; a < mesh_.nodes_per_face(); ++a) own = own || mesh_.faces(face, a) == p;
          if (own) continue;
          Eigen::Matrix<double, 4, 3> xs;
          xs.row(0) = x.row(p);
          for (int i = 0; i < 3; ++i) xs.row(i + 1) = x.row(tri[i]);
          if (plain_distance(xs) >= reach) continue;
          if (seen.insert({p, tri[0], tri[1], tri[2]}).second) pairs_.push_back(Pair{p, tri});
        }
      }
    }
}

void SelfContactTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int n_pairs = static_cast<int>(pairs_.size());
  if (k < n_pairs) {
    const Pair& p = pairs_[k];
    nodes = {p.point, p.triangle[0], p.triangle[1], p.triangle[2]};
  } else {
    nodes.assign(1, trust_nodes_[k - n_pairs]);
  }
}

double SelfContactTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n_pairs = static_cast<int>(pairs_.size());
  if (k >= n_pairs) {  // trust region: |u - u_c| <= r/2
    if (g) g->setZero(3);
    if (H) H->setZero(3, 3);
    const int node = trust_nodes_[k - n_pairs];
    const double moved = (s.u.row(0).transpose() - anchor_[node]).norm();
    return moved <= 0.5 * spec_.inflation ? 0.0 : std::numeric_limits<double>::infinity();
  }
  Eigen::Matrix<double, 4, 3> x = s.X + s.u;
  const double e = point_triangle_barrier(x, weight_[pairs_[k].point], spec_.kappa, spec_.dhat, g, H);
  if (H && spec_.project_hessian && std::isfinite(e) && e > 0) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(*H);
    const Eigen::VectorXd lambda = es.eigenvalues().cwiseMax(0.0);
    *H = es.eigenvectors() * lambda.asDiagonal() * es.eigenvectors().transpose();
  }
  return e;
}

double SelfContactTerm::max_step(Assembler& assembler, Vec u, Vec du) {
  const std::vector<double> u_local = assembler.gather(u);
  const std::vector<double>& du_local = assembler.gather(du);
  const auto U = [&](int n) { return Eigen::Vector3d::Map(&u_local[3 * assembler.node_slot(n)]); };
  const auto dU = [&](int n) { return Eigen::Vector3d::Map(&du_local[3 * assembler.node_slot(n)]); };
  double alpha = 1.0;
  for (const Pair& pr : pairs_) {
    double L = 0.0;
    for (int i = 0; i < 3; ++i) L = std::max(L, (dU(pr.triangle[i]) - dU(pr.point)).norm());
    if (L <= 0) continue;
    Eigen::Matrix<double, 4, 3> x;
    x.row(0) = mesh_.X.row(pr.point) + U(pr.point).transpose();
    for (int i = 0; i < 3; ++i) x.row(i + 1) = mesh_.X.row(pr.triangle[i]) + U(pr.triangle[i]).transpose();
    alpha = std::min(alpha, spec_.max_step_fraction * plain_distance(x) / L);
  }
  // Trust region: largest alpha with |a + alpha b| <= R, a = u - u_c, b = du.
  const double R = 0.5 * spec_.inflation;
  for (int n : trust_nodes_) {
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

void SelfContactTerm::refresh(Assembler& assembler, Vec u) {
  const RowMatrixXd U = assembler.gather_all(u);
  for (int a = 0; a < mesh_.n_nodes(); ++a) anchor_[a] = U.row(a).transpose();
  build_candidates(mesh_.X + U);
}

double SelfContactTerm::min_distance(Assembler& assembler, Vec u) const {
  const std::vector<double>& u_local = assembler.gather(u);
  double local = std::numeric_limits<double>::infinity();
  for (const Pair& pr : pairs_) {
    Eigen::Matrix<double, 4, 3> x;
    const std::array<int, 4> nodes{pr.point, pr.triangle[0], pr.triangle[1], pr.triangle[2]};
    for (int a = 0; a < 4; ++a)
      x.row(a) = mesh_.X.row(nodes[a]) + Eigen::RowVector3d::Map(&u_local[3 * assembler.node_slot(nodes[a])]);
    local = std::min(local, plain_distance(x));
  }
  double global = local;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_MIN, assembler.comm());
  return global;
}

}  // namespace morphfem
