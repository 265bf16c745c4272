// Compressible Mooney-Rivlin law (isochoric/volumetric split):
//   W = c10 (Ibar1 - 3) + c01 (Ibar2 - 3) + kappa/4 (J^2 - 1 - 2 ln J)      [Pa]
// Keys: c10, c01 [Pa] (both >= 0, c10 + c01 > 0), kappa [Pa] or nu.
// Small-strain shear modulus 2 (c10 + c01).
// A negative c10 or c01 (what least-squares fits of silicone tensile curves tend to
// give) makes the law lose ellipticity at finite strain (the material becomes
// unstable: localisation, no Newton convergence), so it is rejected.
#include <memory>
#include <sstream>

#include "core/errors.h"
#include "fem/kinematics.h"

namespace morphfem {
namespace {

class MooneyRivlin final : public InvariantMaterial {
 public:
  MooneyRivlin(double c10, double c01, double kappa) : InvariantMaterial(kappa, true), c10_(c10), c01_(c01) {}
  std::string name() const override { return "mooney_rivlin"; }
  double shear_modulus() const override { return 2.0 * (c10_ + c01_); }

 protected:
  IsochoricDerivatives isochoric(double Ibar1, double Ibar2, bool) const override {
    IsochoricDerivatives d;
    d.W = c10_ * (Ibar1 - 3.0) + c01_ * (Ibar2 - 3.0);
    d.W1 = c10_;
    d.W2 = c01_;
    return d;
  }

 private:
  double c10_, c01_;  // [Pa]
};

}  // namespace

std::unique_ptr<Material> make_mooney_rivlin(const ParamSet& params) {
  params.allow_only({"model", "c10", "c01", "kappa", "nu"});
  const double c10 = params.number_in("c10", -1e12, 1e12);
  const double c01 = params.number_in("c01", -1e12, 1e12);
  for (const auto& [key, value] : {std::pair{"c10", c10}, std::pair{"c01", c01}}) {
    if (value < 0.0) {
      std::ostringstream s;
      s << key << " = " << value
        << " is negative: a Mooney-Rivlin law with c10 < 0 or c01 < 0 is not stable at finite "
           "strain (it loses ellipticity), so it is rejected. Use c10, c01 >= 0 or a Yeoh/Ogden "
           "law fitted to the data";
      throw InputError(params.where(key), s.str());
    }
  }
  if (!(c10 + c01 > 0.0)) throw InputError(params.where("c10"), "c10 + c01 must be > 0 (shear modulus 2 (c10 + c01))");
  return std::make_unique<MooneyRivlin>(c10, c01, bulk_modulus_from_params(params, 2.0 * (c10 + c01)));
}

}  // namespace morphfem
