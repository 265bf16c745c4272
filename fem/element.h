// Lagrange tetrahedra and triangles (P1, P2) on the reference simplex, and
// quadrature rules. Reference tetrahedron: vertices (0,0,0) (1,0,0) (0,1,0) (0,0,1);
// reference triangle: (0,0) (1,0) (0,1). Node ordering is VTK's (see mesh/mesh.h).
//
// With barycentric coordinates L0 = 1 - xi - eta - zeta, L1 = xi, L2 = eta, L3 = zeta:
//   P1:  N_i = L_i
//   P2:  vertex N_i = L_i (2 L_i - 1);  edge (i,j) N = 4 L_i L_j
#pragma once
#include <Eigen/Dense>
#include <vector>

namespace morphfem {

struct QuadraturePoint {
  Eigen::Vector3d xi;  // reference coordinates (third entry 0 on triangles)
  double weight;       // sums to the reference measure: 1/6 (tet) or 1/2 (triangle)
};

// Rules exact for polynomials of total degree <= `degree` (1..6), with positive
// weights (gmsh's tables; gmsh is initialised on first use).
const std::vector<QuadraturePoint>& tet_quadrature(int degree);
const std::vector<QuadraturePoint>& triangle_quadrature(int degree);

// Shape functions N (n) and reference gradients dN (n x 3 or n x 2) at xi.
// order 1 or 2; n = 4/10 (tet) or 3/6 (triangle).
void tet_shape(int order, const Eigen::Vector3d& xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN);
void triangle_shape(int order, const Eigen::Vector3d& xi, Eigen::VectorXd& N, Eigen::MatrixXd& dN);

// Tabulated shape functions at every point of a rule (computed once, reused by
// every element kernel).
struct ShapeTable {
  int order = 1;
  std::vector<QuadraturePoint> points;
  std::vector<Eigen::VectorXd> N;   // per point: n
  std::vector<Eigen::MatrixXd> dN;  // per point: n x dim (reference gradients)
};
ShapeTable make_tet_table(int order, int degree);

// Reference-to-physical gradients at one point of a cell with nodal reference
// coordinates X (n x 3): J0 = X^T dN/dxi (3x3), dN/dX = dN/dxi J0^-1 (n x 3).
// Returns det J0, the reference volume per unit reference-simplex volume (> 0 for
// a valid mesh).
double physical_gradients(const Eigen::MatrixXd& X, const Eigen::MatrixXd& dN_dxi, Eigen::MatrixXd& dN_dX);

// The linear map from nodal displacements to the deformation gradient:
// B(3i+J, 3b+k) = dF_iJ / du_bk = delta_ik dN_b/dX_J (9 x 3n, F flattened row-major).
void deformation_gradient_map(const Eigen::MatrixXd& dN_dX, Eigen::MatrixXd& B);
ShapeTable make_triangle_table(int order, int degree);

}  // namespace morphfem
