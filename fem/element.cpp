#include "fem/element.h"

#include <gmsh.h>

#include <map>
#include <mutex>
#include <stdexcept>
#include <string>

#include "mesh/geometry.h"

namespace morphfem {

namespace {

// gmsh element types: 2 = 3-node triangle, 4 = 4-node tetrahedron.
// gmsh's degree-3 (both) and degree-4 (tet) rules have negative weights; use the
// next positive rule instead.
std::vector<QuadraturePoint> gmsh_rule(int gmsh_type, int degree) {
  if (degree < 1 || degree > 6) throw std::invalid_argument("quadrature degree must be 1..6");
  int use = degree;
  if (degree == 3) use = 4;
  if (gmsh_type == 4 && use == 4) use = 5;
  initialize_gmsh();
  std::vector<double> local, weights;
  gmsh::model::mesh::getIntegrationPoints(gmsh_type, "Gauss" + std::to_string(use), local, weights);
  std::vector<QuadraturePoint> rule(weights.size());
  for (size_t q = 0; q < weights.size(); ++q) {
    rule[q].xi = Eigen::Vector3d(local[3 * q], local[3 * q + 1], local[3 * q + 2]);
    rule[q].weight = weights[q];
    if (weights[q] <= 0) throw std::logic_error("quadrature rule with a non-positive weight");
  }
  return rule;
}

const std::vector<QuadraturePoint>& cached_rule(int gmsh_type, int degree) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::vector<QuadraturePoint>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto key = std::make_pair(gmsh_type, degree);
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, gmsh_rule(gmsh_type, degree)).first;
  return it->second;
}

}  // namespace

const std::vector<QuadraturePoint>& tet_quadrature(int degree) { return cached_rule(4, degree); }
const std::vector<QuadraturePoint>& triangle_quadrature(int degree) { return cached_rule(2, degree); }

void tet_shape(int order, const Eigen::Vector3d& xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN) {
  const double L[4] = {1.0 - xi[0] - xi[1] - xi[2], xi[0], xi[1], xi[2]};
  // dL_i / dxi_k
  const double dL[4][3] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  if (order == 1) {
    N.resize(4);
    dN.resize(4, 3);
    for (int i = 0; i < 4; ++i) {
      N[i] = L[i];
      for (int k = 0; k < 3; ++k) dN(i, k) = dL[i][k];
    }
    return;
  }
  if (order != 2) throw std::invalid_argument("tetrahedron order must be 1 or 2");
  N.resize(10);
  dN.resize(10, 3);
  for (int i = 0; i < 4; ++i) {
    N[i] = L[i] * (2 * L[i] - 1);
    for (int k = 0; k < 3; ++k) dN(i, k) = (4 * L[i] - 1) * dL[i][k];
  }
  static const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (int e = 0; e < 6; ++e) {
    const int a = edge[e][0], b = edge[e][1];
    N[4 + e] = 4 * L[a] * L[b];
    for (int k = 0; k < 3; ++k) dN(4 + e, k) = 4 * (dL[a][k] * L[b] + L[a] * dL[b][k]);
  }
}

void triangle_shape(int order, const Eigen::Vector3d& xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN) {
  const double L[3] = {1.0 - xi[0] - xi[1], xi[0], xi[1]};
  const double dL[3][2] = {{-1, -1}, {1, 0}, {0, 1}};
  if (order == 1) {
    N.resize(3);
    dN.resize(3, 2);
    for (int i = 0; i < 3; ++i) {
      N[i] = L[i];
      for (int k = 0; k < 2; ++k) dN(i, k) = dL[i][k];
    }
    return;
  }
  if (order != 2) throw std::invalid_argument("triangle order must be 1 or 2");
  N.resize(6);
  dN.resize(6, 2);
  for (int i = 0; i < 3; ++i) {
    N[i] = L[i] * (2 * L[i] - 1);
    for (int k = 0; k < 2; ++k) dN(i, k) = (4 * L[i] - 1) * dL[i][k];
  }
  static const int edge[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  for (int e = 0; e < 3; ++e) {
    const int a = edge[e][0], b = edge[e][1];
    N[3 + e] = 4 * L[a] * L[b];
    for (int k = 0; k < 2; ++k) dN(3 + e, k) = 4 * (dL[a][k] * L[b] + L[a] * dL[b][k]);
  }
}

namespace {
template <class ShapeFn>
ShapeTable make_table(int order, const std::vector<QuadraturePoint>& rule, ShapeFn shape) {
  ShapeTable t;
  t.order = order;
  t.points = rule;
  for (const auto& q : rule) {
    Eigen::VectorXd N;
    Eigen::MatrixXd dN;
    shape(order, q.xi, N, dN);
    t.N.push_back(N);
    t.dN.push_back(dN);
  }
  return t;
}
}  // namespace

ShapeTable make_tet_table(int order, int degree) { return make_table(order, tet_quadrature(degree), tet_shape); }
ShapeTable make_triangle_table(int order, int degree) {
  return make_table(order, triangle_quadrature(degree), triangle_shape);
}

double physical_gradients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& dN_dxi, Eigen::MatrixXd& dN_dX) {
  const Eigen::Matrix3d J0 = X.transpose() * dN_dxi;  // J0(i,k) = sum_a X_ai dN_a/dxi_k
  dN_dX = dN_dxi * J0.inverse();
  return J0.determinant();
}

void deformation_gradient_map(const Eigen::MatrixXd& dN_dX, Eigen::MatrixXd& B) {
  const int n = static_cast<int>(dN_dX.rows());
  B.setZero(9, 3 * n);
  for (int b = 0; b < n; ++b)
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 3; ++J) B(3 * i + J, 3 * b + i) = dN_dX(b, J);
}

}  // namespace morphfem
