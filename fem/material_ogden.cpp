// Compressible Ogden law (isochoric/volumetric split), N terms:
//   W = sum_p mu_p/alpha_p (lbar1^alpha_p + lbar2^alpha_p + lbar3^alpha_p - 3)
//       + kappa/4 (J^2 - 1 - 2 ln J)                                          [Pa]
// with lbar_a = J^(-1/3) lambda_a the isochoric principal stretches.
// Keys: mu [Pa] and alpha [-], lists of equal length N >= 1, each mu_p alpha_p > 0;
// kappa [Pa] or nu. Small-strain shear modulus sum_p mu_p alpha_p / 2.
//
// Formulation without principal-direction singularities: with c_a the eigenvalues
// and n_a the eigenvectors of C = F^T F,
//   sum_a lbar_a^alpha = J^(-alpha/3) phi(C),  phi(C) = tr C^(alpha/2) = sum_a g(c_a),
//   g(c) = c^(alpha/2).
// phi is a spectral function of C: dphi/dC = g'(C) = sum_a g'(c_a) n_a n_a^T, and the
// derivative of the matrix function g'(C) is (Daleckii-Krein)
//   d g'(C)[dC] = sum_ab g'[c_a, c_b] (n_a . dC n_b) n_a n_b^T,
// with the divided difference g'[x, y] = (g'(x) - g'(y)) / (x - y), g''(x) if x = y.
// For g'(c) = alpha/2 c^q, q = alpha/2 - 1, the divided difference is evaluated as
//   (x^q - y^q) / (x - y) = y^(q-1) expm1(q L) / expm1(L),  L = ln(x/y),
// which is accurate to rounding for every x, y > 0, including x = y (limit q y^(q-1)),
// so the tangent is exact at repeated principal stretches (F = I, uniaxial states).
// In F: dphi/dF = 2 F G (G = g'(C)),
//   d^2phi/dF_iJ dF_kL = 2 d_ik G_JL + 2 sum_ab g'[c_a,c_b] u_ab,iJ (u_ab + u_ba)_kL,
// u_ab = (F n_a) (x) n_b. The factor J^(-alpha/3) is applied by the product rule.
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <vector>

#include "core/errors.h"
#include "fem/kinematics.h"

namespace morphfem {
namespace {

constexpr int kMaxTerms = 8;

// (x^q - y^q) / (x - y) for x, y > 0, and its limit q x^(q-1) at x = y.
double power_divided_difference(double x, double y, double q) {
  const double L = std::log(x / y);
  if (L == 0.0) return q * std::pow(y, q - 1.0);
  return std::pow(y, q - 1.0) * std::expm1(q * L) / std::expm1(L);
}

class Ogden final : public Material {
 public:
  Ogden(std::vector<double> mu, std::vector<double> alpha, double kappa)
      : n_(static_cast<int>(mu.size())), kappa_(kappa) {
    for (int p = 0; p < n_; ++p) {
      mu_[p] = mu[p];
      alpha_[p] = alpha[p];
    }
  }
  std::string name() const override { return "ogden"; }
  double shear_modulus() const override {
    double s = 0;
    for (int p = 0; p < n_; ++p) s += 0.5 * mu_[p] * alpha_[p];
    return s;
  }
  double bulk_modulus() const override { return kappa_; }

  double energy(const Mat3& F) const override {
    const double J = F.determinant();
    if (!(J > 0.0)) return std::numeric_limits<double>::infinity();
    Eigen::SelfAdjointEigenSolver<Mat3> eig(F.transpose() * F, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d c = eig.eigenvalues();
    double W = volumetric(kappa_, J).U;
    for (int p = 0; p < n_; ++p) {
      const double h = 0.5 * alpha_[p];
      const double phi = std::pow(c(0), h) + std::pow(c(1), h) + std::pow(c(2), h);
      W += mu_[p] / alpha_[p] * (std::pow(J, -alpha_[p] / 3.0) * phi - 3.0);
    }
    return W;
  }

  void evaluate(const Mat3& F, double& W, Mat3& P, Tangent* A) const override { evaluate_split(F, W, P, A, true); }
  void evaluate_isochoric(const Mat3& F, double& W, Mat3& P, Tangent* A) const override {
    evaluate_split(F, W, P, A, false);
  }
  void volumetric_energy(double J, double& U, double& dU, double& d2U) const override {
    const Volumetric vol = volumetric(kappa_, J);
    U = vol.U;
    dU = vol.dU;
    d2U = vol.ddU;
  }

 private:
  // W, P, A of the whole law (with_volumetric) or of its isochoric part alone.
  void evaluate_split(const Mat3& F, double& W, Mat3& P, Tangent* A, bool with_volumetric) const {
    const double J = F.determinant();
    const Eigen::SelfAdjointEigenSolver<Mat3> eig(F.transpose() * F);
    const Eigen::Vector3d c = eig.eigenvalues();
    const Mat3& N = eig.eigenvectors();  // columns n_a
    const Volumetric vol = with_volumetric ? volumetric(kappa_, J) : Volumetric{0.0, 0.0, 0.0};
    Vec9 gJ;
    Tangent HJ;
    det_derivatives(F, J, gJ, A ? &HJ : nullptr);

    // Sum over terms of coef_p = mu_p/alpha_p J^s_p (s_p = -alpha_p/3):
    //   psi_p = J^s phi_p, dpsi/dF = J^s (dphi/dF + s phi/J dJ/dF),
    //   d^2psi = J^s [d^2phi + s/J (dphi dJ^T + dJ dphi^T) + s(s-1) phi/J^2 dJ dJ^T + s phi/J d^2J].
    W = vol.U;
    Eigen::Vector3d G_eig = Eigen::Vector3d::Zero();  // eigenvalues of sum coef_p g'_p(C)
    Eigen::Matrix3d K = Eigen::Matrix3d::Zero();      // sum coef_p g'_p[c_a, c_b]
    double d_J = vol.dU;                              // coefficient of dJ/dF in P
    double dd_JJ = vol.ddU;                           // coefficient of dJ dJ^T in A
    Eigen::Vector3d v_eig = Eigen::Vector3d::Zero();  // eigenvalues of sum coef s/J g'_p(C)
    for (int p = 0; p < n_; ++p) {
      const double a = alpha_[p], s = -a / 3.0, q = 0.5 * a - 1.0;
      const double coef = mu_[p] / a * std::pow(J, s);
      Eigen::Vector3d dg;  // g'(c_a) = a/2 c_a^q
      double phi = 0;
      for (int k = 0; k < 3; ++k) {
        const double cq = std::pow(c(k), q);
        dg(k) = 0.5 * a * cq;
        phi += cq * c(k);
      }
      W += mu_[p] / a * (std::pow(J, s) * phi - 3.0);
      G_eig += coef * dg;
      d_J += coef * s * phi / J;
      if (A) {
        v_eig += coef * s / J * dg;
        dd_JJ += coef * s * (s - 1.0) * phi / (J * J);
        for (int x = 0; x < 3; ++x)
          for (int y = x; y < 3; ++y) {
            const double h = 0.5 * a * power_divided_difference(c(x), c(y), q);
            K(x, y) += coef * h;
          }
      }
    }
    const Mat3 G = N * G_eig.asDiagonal() * N.transpose();
    P = 2.0 * F * G + d_J * unflatten(gJ);
    if (!A) return;

    const Vec9 v = flatten(2.0 * F * (N * v_eig.asDiagonal() * N.transpose()));
    *A = d_J * HJ;
    A->noalias() += dd_JJ * gJ * gJ.transpose();
    A->noalias() += v * gJ.transpose();
    A->noalias() += gJ * v.transpose();
    // 2 d_ik G_JL
    for (int i = 0; i < 3; ++i) A->block<3, 3>(3 * i, 3 * i) += 2.0 * G;
    // 2 sum_ab K_ab u_ab (u_ab + u_ba)^T = sum_a 4 K_aa u_aa u_aa^T + sum_{a<b} 2 K_ab w w^T,
    // w = u_ab + u_ba, u_ab = (F n_a) (x) n_b.
    const Mat3 M = F * N;  // columns m_a = F n_a
    for (int x = 0; x < 3; ++x)
      for (int y = x; y < 3; ++y) {
        Mat3 w = M.col(x) * N.col(y).transpose();
        if (x == y) {
          const Vec9 u = flatten(w);
          A->noalias() += 4.0 * K(x, x) * u * u.transpose();
        } else {
          w += M.col(y) * N.col(x).transpose();
          const Vec9 u = flatten(w);
          A->noalias() += 2.0 * K(x, y) * u * u.transpose();
        }
      }
  }

  int n_;
  double mu_[kMaxTerms] = {}, alpha_[kMaxTerms] = {};
  double kappa_;
};

}  // namespace

std::unique_ptr<Material> make_ogden(const ParamSet& params) {
  params.allow_only({"model", "mu", "alpha", "kappa", "nu"});
  const std::vector<double> mu = params.list("mu"), alpha = params.list("alpha");
  if (mu.empty() || mu.size() > static_cast<size_t>(kMaxTerms))
    throw InputError(params.where("mu"),
                     "expected 1 to " + std::to_string(kMaxTerms) + " Ogden terms, got " + std::to_string(mu.size()));
  if (alpha.size() != mu.size())
    throw InputError(params.where("alpha"), "alpha has " + std::to_string(alpha.size()) + " entries but mu has " +
                                                std::to_string(mu.size()) + " (one alpha per mu)");
  double mu0 = 0;
  for (size_t p = 0; p < mu.size(); ++p) {
    std::ostringstream s;
    if (alpha[p] == 0.0 || std::abs(alpha[p]) > 100.0) {
      s << "alpha[" << p << "] = " << alpha[p] << " must be nonzero with |alpha| <= 100";
      throw InputError(params.where("alpha"), s.str());
    }
    if (!(mu[p] * alpha[p] > 0.0) || std::abs(mu[p]) > 1e12) {
      s << "term " << p << ": mu = " << mu[p] << ", alpha = " << alpha[p]
        << ": each term needs mu_p alpha_p > 0 (and |mu_p| <= 1e12 Pa); terms with mu_p alpha_p "
           "<= 0 can make the law unstable at finite strain";
      throw InputError(params.where("mu"), s.str());
    }
    mu0 += 0.5 * mu[p] * alpha[p];
  }
  return std::make_unique<Ogden>(mu, alpha, bulk_modulus_from_params(params, mu0));
}

}  // namespace morphfem
