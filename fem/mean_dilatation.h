// Mean-dilatation (P2/P0, Simo-Taylor-Pister) element for nearly incompressible
// materials, registered as "mean_dilatation" in elastic_formulations().
//
// Per cell e, with the law split W(F) = W_iso(F) + U(J) (fem/material.h):
//   E_e = int_e W_iso(F) dV + V_e U(Theta_e),    Theta_e = v_e / V_e,
//   V_e = int_e dV (reference volume [m^3]), v_e = int_e J dV (current volume [m^3]).
// The volume change is constant per cell (a P0 pressure p_e = U'(Theta_e) [Pa],
// eliminated element by element), so no global pressure unknowns are needed and the
// one assembly loop is unchanged. With g_a = F^-T grad_X N_a (spatial gradient of
// shape function a) and dJ/du_ai = J g_ai:
//   dE/du_ai = int_e P_iso : dF/du_ai dV + U'(Theta) dv/du_ai,  dv/du_ai = int_e J g_ai dV
//   d2E      = int_e B^T A_iso B dV + U''(Theta)/V_e dv dv^T + U'(Theta) d2v,
//   d2v/du_ai du_bk = int_e J (g_ai g_bk - g_ak g_bi) dV.
// v_e is integrated with a rule of degree >= 3, exact for P2 cells (det dx/dxi is a
// cubic in xi), so Theta_e is the exact current-to-reference volume ratio.
//
// Stability and accuracy: P2 displacement / P0 pressure satisfies the inf-sup
// condition on tetrahedra, so the solution does not lock as kappa/mu -> infinity.
// The P0 pressure limits the order: displacement error O(h) in H1 and O(h^2) in L2
// (pressure O(h)), uniformly in kappa, instead of O(h^2)/O(h^3) for compressible P2.
// For moderate kappa both formulations converge to the same solution.
//
// P1 cells are rejected: J is already constant on a linear tetrahedron, so
// Theta_e = J and the formulation would be identical to (and lock like) the
// displacement element.
#pragma once
#include "fem/elastic.h"

namespace morphfem {

class MeanDilatationTerm : public ElasticTerm {
 public:
  // As ElasticTerm; quadrature_degree (0: 2) is the rule for W_iso, the volume
  // integral uses max(3, quadrature_degree). Throws InputError on P1 meshes.
  MeanDilatationTerm(const Mesh& mesh, const Partition& partition, int rank,
                     std::vector<std::shared_ptr<const Material>> materials, int quadrature_degree = 0);

  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  // Growth is not implemented for the mixed formulation: refused.
  void set_growth(int region, GrowthFunction growth) override;

  // Reference volume V_e [m^3] and volume ratio Theta_e = v_e / V_e of piece k.
  void dilatation(const PieceState& s, double& reference_volume, double& theta) const;

 private:
  ShapeTable volume_table_;
};

}  // namespace morphfem
