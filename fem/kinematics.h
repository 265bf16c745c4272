// Kinematics shared by every hyperelastic law: J = det F, C = F^T F, the invariants
// of the isochoric split (Fbar = J^(-1/3) F, Cbar = J^(-2/3) C,
// Ibar1 = J^(-2/3) I1, Ibar2 = J^(-4/3) I2), their first and second derivatives with
// respect to F, and the chain rule that turns derivatives of W(Ibar1, Ibar2, J) into
// the first Piola-Kirchhoff stress P = dW/dF and the tangent A = dP/dF.
//
// Flattening as in material.h: a = 3*i + J for F_iJ (row-major), so a 9-vector
// gradient g(a) = d(.)/dF_iJ and a Hessian H(a, b) = d^2(.)/dF_iJ dF_kL.
// Everything here is fixed-size (no heap allocation): it runs at every quadrature
// point of every Newton iteration.
#pragma once
#include <Eigen/Dense>

#include "fem/material.h"

namespace morphfem {

using Vec9 = Eigen::Matrix<double, 9, 1>;

// Row-major flattening F_iJ -> v(3*i + J) and back.
inline Vec9 flatten(const Mat3& M) {
  Vec9 v;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) v(3 * i + j) = M(i, j);
  return v;
}
inline Mat3 unflatten(const Vec9& v) {
  Mat3 M;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M(i, j) = v(3 * i + j);
  return M;
}

// Invariants of F needed by the invariant-based laws.
struct Invariants {
  double J = 1;      // det F
  double I1 = 3;     // tr C
  double I2 = 3;     // (I1^2 - tr C^2) / 2
  double Ibar1 = 3;  // J^(-2/3) I1 = tr Cbar
  double Ibar2 = 3;  // J^(-4/3) I2
  Mat3 C;            // F^T F
};
// Requires det F > 0 (not checked; callers check J first).
Invariants invariants(const Mat3& F);

// Volumetric energy U(J) = kappa/4 (J^2 - 1 - 2 ln J) [Pa] and its derivatives
// U' = kappa/2 (J - 1/J), U'' = kappa/2 (1 + 1/J^2). U(1) = U'(1) = 0, U''(1) = kappa.
struct Volumetric {
  double U, dU, ddU;
};
Volumetric volumetric(double kappa, double J);

// dJ/dF = J F^-T (9-vector) and, if HJ != nullptr,
// d^2J/dF_iJ dF_kL = J (F^-T_iJ F^-T_kL - F^-1_Jk F^-1_Li).
void det_derivatives(const Mat3& F, double J, Vec9& gJ, Tangent* HJ);

// Isochoric energy of an invariant-based law and its derivatives with respect to
// (Ibar1, Ibar2): W1 = dW/dIbar1, W12 = d^2W/dIbar1 dIbar2, ...
struct IsochoricDerivatives {
  double W = 0;
  double W1 = 0, W2 = 0;
  double W11 = 0, W12 = 0, W22 = 0;
};

// Chain rule for W(F) = Wiso(Ibar1, Ibar2) + U(J):
//   P = W^_I1 dI1/dF + W^_I2 dI2/dF + W^_J dJ/dF,
//   A = sum_a W^_a d^2 y_a/dF^2 + G W^_yy G^T,  y = (I1, I2, J), G = [dy_a/dF],
// where W^(I1, I2, J) = Wiso(J^(-2/3) I1, J^(-4/3) I2) + U(J). With uses_I2 = false the
// I2 terms are skipped (W2 = W12 = W22 must then be zero).
void invariant_stress_tangent(const Mat3& F, const Invariants& inv, const IsochoricDerivatives& iso,
                              const Volumetric& vol, bool uses_I2, Mat3& P, Tangent* A);

// Base class of the laws W = Wiso(Ibar1, Ibar2) + U(J) (neo-Hookean, Mooney-Rivlin,
// Yeoh): a law only supplies Wiso and its derivatives.
class InvariantMaterial : public Material {
 public:
  double energy(const Mat3& F) const override;
  void evaluate(const Mat3& F, double& W, Mat3& P, Tangent* A) const override;
  void evaluate_isochoric(const Mat3& F, double& W, Mat3& P, Tangent* A) const override;
  void volumetric_energy(double J, double& U, double& dU, double& d2U) const override;
  double bulk_modulus() const override { return kappa_; }

 protected:
  InvariantMaterial(double kappa, bool uses_I2) : kappa_(kappa), uses_I2_(uses_I2) {}
  // Wiso and (if second) its second derivatives at (Ibar1, Ibar2).
  virtual IsochoricDerivatives isochoric(double Ibar1, double Ibar2, bool second) const = 0;

 private:
  double kappa_;
  bool uses_I2_;
};

}  // namespace morphfem
