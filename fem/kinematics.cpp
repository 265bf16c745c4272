// Kinematics of the isochoric/volumetric split and the invariant chain rule
// (see kinematics.h for the formulas).
#include "fem/kinematics.h"

#include <cmath>
#include <limits>

namespace morphfem {

Invariants invariants(const Mat3& F) {
  Invariants k;
  k.J = F.determinant();
  k.C = F.transpose() * F;
  k.I1 = k.C.trace();
  k.I2 = 0.5 * (k.I1 * k.I1 - k.C.squaredNorm());    // C symmetric: tr C^2 = |C|^2
  const double Jm23 = std::cbrt(1.0 / (k.J * k.J));  // J^(-2/3)
  k.Ibar1 = Jm23 * k.I1;
  k.Ibar2 = Jm23 * Jm23 * k.I2;
  return k;
}

Volumetric volumetric(double kappa, double J) {
  return {0.25 * kappa * (J * J - 1.0 - 2.0 * std::log(J)), 0.5 * kappa * (J - 1.0 / J),
          0.5 * kappa * (1.0 + 1.0 / (J * J))};
}

void det_derivatives(const Mat3& F, double J, Vec9& gJ, Tangent* HJ) {
  const Mat3 Finv = F.inverse();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) gJ(3 * i + j) = J * Finv(j, i);
  if (!HJ) return;
  // d^2J/dF_iJ dF_kL = J (Finv_Ji Finv_Lk - Finv_Jk Finv_Li)
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 3; ++l)
          (*HJ)(3 * i + j, 3 * k + l) = J * (Finv(j, i) * Finv(l, k) - Finv(j, k) * Finv(l, i));
}

void invariant_stress_tangent(const Mat3& F, const Invariants& inv, const IsochoricDerivatives& iso,
                              const Volumetric& vol, bool uses_I2, Mat3& P, Tangent* A) {
  const double J = inv.J;
  const double a1 = inv.Ibar1 / inv.I1;  // J^(-2/3)
  const double a2 = a1 * a1;             // J^(-4/3)

  // First derivatives of W^(I1, I2, J) = Wiso(a1 I1, a2 I2) + U(J).
  const double w_I1 = a1 * iso.W1;
  const double w_I2 = a2 * iso.W2;
  const double w_J = (-2.0 / 3.0 * inv.Ibar1 * iso.W1 - 4.0 / 3.0 * inv.Ibar2 * iso.W2) / J + vol.dU;

  // Gradients of y = (I1, I2, J) with respect to F.
  const Mat3 g_I1 = 2.0 * F;                         // dI1/dF = 2 F
  const Mat3 g_I2 = 2.0 * (inv.I1 * F - F * inv.C);  // dI2/dF = 2 (I1 F - F C)
  Vec9 g_J;
  det_derivatives(F, J, g_J, A);  // writes d^2J/dF^2 into A when requested

  P = w_I1 * g_I1 + w_J * unflatten(g_J);
  if (uses_I2) P += w_I2 * g_I2;
  if (!A) return;

  // A currently holds d^2J/dF^2: scale it, then add the other terms.
  *A *= w_J;
  // d^2I1/dF^2 = 2 I (9x9 identity).
  A->diagonal().array() += 2.0 * w_I1;
  if (uses_I2 && w_I2 != 0.0) {
    // d^2I2/dF_iJ dF_kL = 4 F_iJ F_kL + 2 I1 d_ik d_JL - 2 (d_ik C_LJ + F_iL F_kJ + b_ik d_JL)
    const Mat3 b = F * F.transpose();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) {
            double h = 4.0 * F(i, j) * F(k, l) - 2.0 * F(i, l) * F(k, j);
            if (i == k) h -= 2.0 * inv.C(l, j);
            if (j == l) h += 2.0 * (i == k ? inv.I1 : 0.0) - 2.0 * b(i, k);
            (*A)(3 * i + j, 3 * k + l) += w_I2 * h;
          }
  }

  // Second derivatives of W^ in y = (I1, I2, J): with x = (Ibar1, Ibar2, J) = x(y),
  // W^_yy = D^T W_xx D + W1 d^2x1/dy^2 + W2 d^2x2/dy^2, D = dx/dy.
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero();
  D(0, 0) = a1;
  D(0, 2) = -2.0 / 3.0 * inv.Ibar1 / J;
  D(1, 1) = a2;
  D(1, 2) = -4.0 / 3.0 * inv.Ibar2 / J;
  D(2, 2) = 1.0;
  Eigen::Matrix3d Wxx;
  Wxx << iso.W11, iso.W12, 0.0, iso.W12, iso.W22, 0.0, 0.0, 0.0, vol.ddU;
  Eigen::Matrix3d Wyy = D.transpose() * Wxx * D;
  // d^2 Ibar1/dI1 dJ = -2/3 a1/J, d^2 Ibar1/dJ^2 = 10/9 Ibar1/J^2
  Wyy(0, 2) += iso.W1 * (-2.0 / 3.0 * a1 / J);
  Wyy(2, 0) += iso.W1 * (-2.0 / 3.0 * a1 / J);
  Wyy(2, 2) += iso.W1 * (10.0 / 9.0 * inv.Ibar1 / (J * J));
  // d^2 Ibar2/dI2 dJ = -4/3 a2/J, d^2 Ibar2/dJ^2 = 28/9 Ibar2/J^2
  Wyy(1, 2) += iso.W2 * (-4.0 / 3.0 * a2 / J);
  Wyy(2, 1) += iso.W2 * (-4.0 / 3.0 * a2 / J);
  Wyy(2, 2) += iso.W2 * (28.0 / 9.0 * inv.Ibar2 / (J * J));

  Eigen::Matrix<double, 9, 3> G;
  G.col(0) = flatten(g_I1);
  G.col(1) = uses_I2 ? flatten(g_I2) : Vec9::Zero();
  G.col(2) = g_J;
  A->noalias() += G * Wyy * G.transpose();
}

double InvariantMaterial::energy(const Mat3& F) const {
  const double J = F.determinant();
  if (!(J > 0.0)) return std::numeric_limits<double>::infinity();
  const Invariants inv = invariants(F);
  return isochoric(inv.Ibar1, inv.Ibar2, false).W + volumetric(kappa_, J).U;
}

void InvariantMaterial::evaluate(const Mat3& F, double& W, Mat3& P, Tangent* A) const {
  const Invariants inv = invariants(F);
  const IsochoricDerivatives iso = isochoric(inv.Ibar1, inv.Ibar2, A != nullptr);
  const Volumetric vol = volumetric(kappa_, inv.J);
  W = iso.W + vol.U;
  invariant_stress_tangent(F, inv, iso, vol, uses_I2_, P, A);
}

// Isochoric part: the same chain rule with U = U' = U'' = 0.
void InvariantMaterial::evaluate_isochoric(const Mat3& F, double& W, Mat3& P, Tangent* A) const {
  const Invariants inv = invariants(F);
  const IsochoricDerivatives iso = isochoric(inv.Ibar1, inv.Ibar2, A != nullptr);
  W = iso.W;
  invariant_stress_tangent(F, inv, iso, Volumetric{0.0, 0.0, 0.0}, uses_I2_, P, A);
}

void InvariantMaterial::volumetric_energy(double J, double& U, double& dU, double& d2U) const {
  const Volumetric vol = volumetric(kappa_, J);
  U = vol.U;
  dU = vol.dU;
  d2U = vol.ddU;
}

}  // namespace morphfem
