// Woven fabric: a soft compressible neo-Hookean matrix plus fibre families that
// carry tension only (a fabric buckles, it does not push):
//   W = W_nh(F) + sum_a E_f / 8 <I4_a - 1>_+^2,   I4_a = a . C a,  C = F^T F  [Pa]
// with a the unit fibre directions in the reference configuration (default the warp
// along x and the weft along y) and <x>_+ = max(x, 0). At small strain a fibre adds
// E_f eps_aa^2 / 2 (its Young's modulus E_f along a). Stress and tangent of a fibre
// (Fa = F a):
//   P_iJ   = E_f / 2 <I4 - 1>_+ (Fa)_i a_J
//   A_iJkL = E_f / 2 <I4 - 1>_+ d_ik a_J a_L + E_f [I4 > 1] (Fa)_i a_J (Fa)_k a_L.
// W and P are continuous where a fibre goes slack (I4 = 1); A jumps there.
// Keys: mu [Pa], kappa [Pa] or nu (the matrix), fibre_modulus [Pa] (E_f > 0),
// fibres (optional): a list of 3 numbers per family, normalised here
// (default [1, 0, 0, 0, 1, 0]).
// The split of material.h: the fibre term goes into the isochoric part, evaluated on
// F itself (the fabric is not nearly incompressible), so W = W_iso + U(J) still holds.
#include <cmath>
#include <memory>
#include <vector>

#include "core/errors.h"
#include "fem/kinematics.h"

namespace morphfem {
namespace {

class Fabric final : public Material {
 public:
  Fabric(std::unique_ptr<Material> matrix, double modulus, std::vector<Eigen::Vector3d> fibres)
      : matrix_(std::move(matrix)), modulus_(modulus), fibres_(std::move(fibres)) {}
  std::string name() const override { return "fabric"; }
  double shear_modulus() const override { return matrix_->shear_modulus(); }
  double bulk_modulus() const override { return matrix_->bulk_modulus(); }
  bool isotropic() const override { return false; }
  // A fibre's energy E_f/8 (I4 - 1)^2 for I4 > 1 has a kink in its second derivative at
  // I4 = 1; I4 moves by at most 2 |F a| h + 3 h^2 when F moves by h per component.
  bool smooth_near(const Mat3& F, double h) const override {
    for (const auto& a : fibres_) {
      const double reach = 2.0 * (F * a).norm() * 3.0 * h + 9.0 * h * h;
      if (std::abs((F * a).squaredNorm() - 1.0) <= reach) return false;
    }
    return true;
  }

  double energy(const Mat3& F) const override {
    double W = matrix_->energy(F);
    if (std::isfinite(W)) add_fibres(F, W, nullptr, nullptr);
    return W;
  }
  void evaluate(const Mat3& F, double& W, Mat3& P, Tangent* A) const override {
    matrix_->evaluate(F, W, P, A);
    add_fibres(F, W, &P, A);
  }
  void evaluate_isochoric(const Mat3& F, double& W, Mat3& P, Tangent* A) const override {
    matrix_->evaluate_isochoric(F, W, P, A);
    add_fibres(F, W, &P, A);
  }
  void volumetric_energy(double J, double& U, double& dU, double& d2U) const override {
    matrix_->volumetric_energy(J, U, dU, d2U);
  }

 private:
  // Adds the taut fibres' W and, where asked for (P, A not null), their P and A.
  void add_fibres(const Mat3& F, double& W, Mat3* P, Tangent* A) const {
    for (const auto& a : fibres_) {
      const Eigen::Vector3d Fa = F * a;
      const double stretch = Fa.squaredNorm() - 1.0;  // I4 - 1
      if (!(stretch > 0)) continue;                   // slack fibre: no energy, stress or stiffness
      W += 0.125 * modulus_ * stretch * stretch;
      if (P == nullptr) continue;
      const Mat3 dI4 = Fa * a.transpose();  // half of d I4 / dF
      *P += 0.5 * modulus_ * stretch * dI4;
      if (A == nullptr) continue;
      const Vec9 g = flatten(dI4);
      *A += modulus_ * g * g.transpose();
      for (int i = 0; i < 3; ++i)
        for (int J = 0; J < 3; ++J)
          for (int L = 0; L < 3; ++L) (*A)(3 * i + J, 3 * i + L) += 0.5 * modulus_ * stretch * a(J) * a(L);
    }
  }

  std::unique_ptr<Material> matrix_;
  double modulus_;                       // E_f: fibre modulus [Pa]
  std::vector<Eigen::Vector3d> fibres_;  // unit directions in the reference configuration
};

}  // namespace

std::vector<Eigen::Vector3d> fibre_directions(const ParamSet& params) {
  const std::vector<double> list = params.list("fibres", {1, 0, 0, 0, 1, 0});
  if (list.empty() || list.size() % 3 != 0)
    throw InputError(params.where("fibres"), "fibres: expected 3 numbers per fibre family (x, y, z of its direction)");
  std::vector<Eigen::Vector3d> fibres;
  for (size_t k = 0; k < list.size(); k += 3) {
    const Eigen::Vector3d a(list[k], list[k + 1], list[k + 2]);
    if (!(a.norm() > 1e-12) || !a.allFinite())
      throw InputError(params.where("fibres"),
                       "fibres: family " + std::to_string(k / 3 + 1) + " has no direction (a zero vector)");
    fibres.push_back(a.normalized());
  }
  return fibres;
}

std::unique_ptr<Material> make_fabric(const ParamSet& params) {
  params.allow_only({"model", "mu", "kappa", "nu", "fibre_modulus", "fibres"});
  const double modulus = positive_parameter(params, "fibre_modulus", 1e13, "fibre modulus E_f [Pa]");
  return std::make_unique<Fabric>(make_neo_hookean(params.without("fibre_modulus").without("fibres")), modulus,
                                  fibre_directions(params));
}

}  // namespace morphfem
