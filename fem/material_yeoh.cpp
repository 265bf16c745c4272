// Compressible Yeoh law (isochoric/volumetric split):
//   W = c1 (Ibar1 - 3) + c2 (Ibar1 - 3)^2 + c3 (Ibar1 - 3)^3 + kappa/4 (J^2 - 1 - 2 ln J)  [Pa]
// Keys: c1 [Pa] (> 0), c2, c3 [Pa] (optional, default 0; may be negative),
// kappa [Pa] or nu. Small-strain shear modulus 2 c1.
// A negative c3 (typical of silicone fits) softens the law beyond the fitted strain
// range; dW/dIbar1 = c1 + 2 c2 x + 3 c3 x^2 (x = Ibar1 - 3) turns negative (unstable)
// for large x: the factory rejects parameters for which this happens before
// x = 7 (uniaxial stretch ~ 3, i.e. 200 % strain, the range the silicone fits cover).
// E.g. the published Dragon Skin 10 fit (c1 0.022, c2 3.0e-3, c3 -1.1e-4 MPa) stays
// stable up to x ~ 21 (uniaxial stretch ~ 4.9).
// Beyond the fitted range the cubic is not data, and with c3 < 0 it runs to -inf (a
// Newton iterate that overstretches one element then finds ever lower energy and
// diverges). So for c3 < 0 the law is continued linearly in x beyond the inflection
// x_c = max(0, -c2 / (3 c3)), where dW/dx peaks and d2W/dx2 = 0: the continuation
// W(x_c) + W1(x_c) (x - x_c) is C2 there, neo-Hookean-like (W1 = its maximum > 0) and
// bounded below. x_c = 9.1 (DS10) and 8.4 (DS30), past the fits' x < 7.
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/errors.h"
#include "fem/kinematics.h"

namespace morphfem {
namespace {

class Yeoh final : public InvariantMaterial {
 public:
  Yeoh(double c1, double c2, double c3, double kappa)
      : InvariantMaterial(kappa, false),
        c1_(c1),
        c2_(c2),
        c3_(c3),
        x_linear_(c3 < 0.0 ? std::max(0.0, -c2 / (3.0 * c3)) : INFINITY) {}
  std::string name() const override { return "yeoh"; }
  double shear_modulus() const override { return 2.0 * c1_; }

 protected:
  IsochoricDerivatives isochoric(double Ibar1, double, bool) const override {
    const double x = Ibar1 - 3.0;
    const double xc = std::min(x, x_linear_);  // the cubic up to x_linear_, then its tangent line
    IsochoricDerivatives d;
    d.W1 = c1_ + xc * (2.0 * c2_ + 3.0 * xc * c3_);
    d.W = xc * (c1_ + xc * (c2_ + xc * c3_)) + d.W1 * (x - xc);
    d.W11 = x < x_linear_ ? 2.0 * c2_ + 6.0 * c3_ * x : 0.0;
    return d;
  }

 private:
  double c1_, c2_, c3_;  // [Pa]
  double x_linear_;      // x beyond which W is linear in x (c3 < 0), else +inf
};

}  // namespace

// Smallest x = Ibar1 - 3 >= 0 where dW/dIbar1 = c1 + 2 c2 x + 3 c3 x^2 vanishes
// (+infinity if never).
static double yeoh_loss_of_stability(double c1, double c2, double c3) {
  double best = INFINITY;
  if (c3 == 0.0) {
    if (c2 < 0.0) best = -c1 / (2.0 * c2);
    return best;
  }
  const double disc = 4.0 * c2 * c2 - 12.0 * c3 * c1;
  if (disc < 0.0) return best;
  for (double sign : {-1.0, 1.0}) {
    const double x = (-2.0 * c2 + sign * std::sqrt(disc)) / (6.0 * c3);
    if (x >= 0.0 && x < best) best = x;
  }
  return best;
}

std::unique_ptr<Material> make_yeoh(const ParamSet& params) {
  params.allow_only({"model", "c1", "c2", "c3", "kappa", "nu"});
  const double c1 = positive_parameter(params, "c1", 1e12, "Yeoh c1 = half the shear modulus [Pa]");
  const double c2 = params.number_in("c2", -1e12, 1e12, 0.0);
  const double c3 = params.number_in("c3", -1e12, 1e12, 0.0);
  const double x_max = yeoh_loss_of_stability(c1, c2, c3);
  if (x_max < 7.0) {
    std::ostringstream s;
    s << "c1 = " << c1 << ", c2 = " << c2 << ", c3 = " << c3
      << ": dW/dIbar1 = c1 + 2 c2 x + 3 c3 x^2 becomes negative at x = Ibar1 - 3 = " << x_max
      << " (uniaxial stretch about " << std::sqrt(x_max + 3.0)
      << "); the law would be unstable within 200 % strain (Ibar1 - 3 < 7)";
    throw InputError(params.where(params.has("c3") ? "c3" : "c2"), s.str());
  }
  return std::make_unique<Yeoh>(c1, c2, c3, bulk_modulus_from_params(params, 2.0 * c1));
}

}  // namespace morphfem
