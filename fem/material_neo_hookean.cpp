// Compressible neo-Hookean law (isochoric/volumetric split):
//   W = mu/2 (Ibar1 - 3) + kappa/4 (J^2 - 1 - 2 ln J)      [Pa]
// Keys: mu [Pa] (> 0), kappa [Pa] or nu. Small-strain shear modulus mu.
#include <memory>

#include "fem/kinematics.h"

namespace morphfem {
namespace {

class NeoHookean final : public InvariantMaterial {
 public:
  NeoHookean(double mu, double kappa) : InvariantMaterial(kappa, false), mu_(mu) {}
  std::string name() const override { return "neo_hookean"; }
  double shear_modulus() const override { return mu_; }

 protected:
  IsochoricDerivatives isochoric(double Ibar1, double, bool) const override {
    IsochoricDerivatives d;
    d.W = 0.5 * mu_ * (Ibar1 - 3.0);
    d.W1 = 0.5 * mu_;
    return d;
  }

 private:
  double mu_;  // shear modulus [Pa]
};

}  // namespace

std::unique_ptr<Material> make_neo_hookean(const ParamSet& params) {
  params.allow_only({"model", "mu", "kappa", "nu"});
  const double mu = positive_parameter(params, "mu", 1e12, "shear modulus [Pa]");
  return std::make_unique<NeoHookean>(mu, bulk_modulus_from_params(params, mu));
}

}  // namespace morphfem
