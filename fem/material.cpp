// Material registry (the one place where laws are registered by name), the shared
// parameter helpers, and the silicone presets.
#include "fem/material.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/strings.h"

namespace morphfem {

double positive_parameter(const ParamSet& params, const std::string& key, double hi, const std::string& what) {
  const double v = params.number(key);
  if (!(v > 0.0) || v > hi) {
    std::ostringstream s;
    s << key << " (" << what << ") = " << v << " must be > 0 and <= " << hi;
    throw InputError(params.where(key), s.str());
  }
  return v;
}

double bulk_modulus_from_params(const ParamSet& params, double mu0) {
  const bool has_kappa = params.has("kappa"), has_nu = params.has("nu");
  if (has_kappa && has_nu)
    throw InputError(params.where("nu"), "give the bulk modulus either as kappa [Pa] or as nu, not both");
  if (has_kappa) return positive_parameter(params, "kappa", 1e15, "bulk modulus [Pa]");
  if (!has_nu)
    throw InputError(params.context(),
                     "missing bulk modulus: give kappa [Pa] or nu (Poisson's ratio, e.g. 0.49 for silicone)");
  const double nu = params.number("nu");
  if (!(nu >= -0.99 && nu <= 0.49999)) {
    std::ostringstream s;
    s << "Poisson's ratio nu = " << nu
      << " must be in [-0.99, 0.49999] (nu = 0.5, incompressible, is not representable by the "
         "penalty U(J); use 0.49 to 0.4999 for silicone)";
    throw InputError(params.where("nu"), s.str());
  }
  return 2.0 * mu0 * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu));
}

namespace {

// Silicone presets: hyperelastic fits to the uniaxial tensile curves in
// shared/data/materials/ (Marechal et al., Soft Robotics 2021; strain from the
// crosshead) over engineering strain 0 .. 200 % (stretch 1.045 .. 3.0, 87 points per
// curve), incompressible uniaxial closed forms, unweighted least squares on the
// nominal stress. Reproduce with (fem/material_fit.cpp):
//   morphfem fit-materials --max-strain 2.0          (or --json for full precision)
// Coefficients in Pa. They agree with the published fits quoted in
// shared/VERIFICATION.md (DS10 Yeoh 0.022 / 3.0e-3 / -1.1e-4 MPa, mu 0.08 MPa;
// DS30 0.092 / 9.0e-3 / -3.6e-4 MPa, mu 0.29 MPa) to within 2 %.
// The neo-Hookean fit is a compromise over the whole range (RMS 25 / 69 kPa, i.e.
// 7-9 % of the stress at 200 %): its mu is 1.6-1.8x the Yeoh small-strain shear
// modulus 2 c1 because the curves stiffen; prefer the Yeoh law (RMS 0.84 / 3.1 kPa).
// The negative c3 softens the Yeoh law beyond the fitted range: dW/dIbar1 stays
// positive up to Ibar1 - 3 = 21.2 (DS10) / 21.0 (DS30), uniaxial stretch ~ 4.9.
struct SiliconeFit {
  double yeoh_c1, yeoh_c2, yeoh_c3;  // Yeoh [Pa]
  double neo_mu;                     // neo-Hookean shear modulus [Pa]
};
// Dragon Skin 10 Medium: Yeoh RMS 0.842 kPa, neo-Hookean RMS 24.58 kPa.
constexpr SiliconeFit kDragonSkin10{21589.78136, 3044.251204, -111.6003155, 78634.87476};
// Dragon Skin 30: Yeoh RMS 3.107 kPa, neo-Hookean RMS 69.30 kPa.
constexpr SiliconeFit kDragonSkin30{92174.84632, 9028.396943, -356.94068, 286574.4859};

// Preset keys: law (yeoh | neo_hookean, default yeoh), kappa [Pa] or nu (default
// nu = 0.49: nearly incompressible silicone, kappa ~ 50 mu).
std::unique_ptr<Material> make_silicone_preset(const ParamSet& params, const SiliconeFit& fit) {
  params.allow_only({"model", "law", "kappa", "nu"});
  const std::string law = params.string("law", "yeoh");
  const double mu0 = law == "neo_hookean" ? fit.neo_mu : 2.0 * fit.yeoh_c1;
  const double kappa = params.has("kappa") || params.has("nu") ? bulk_modulus_from_params(params, mu0)
                                                               : 2.0 * mu0 * (1.0 + 0.49) / (3.0 * (1.0 - 2.0 * 0.49));
  ParamSet law_params(params.context());
  law_params.set("kappa", kappa);
  if (law == "yeoh") {
    law_params.set("c1", fit.yeoh_c1);
    law_params.set("c2", fit.yeoh_c2);
    law_params.set("c3", fit.yeoh_c3);
    return make_yeoh(law_params);
  }
  if (law == "neo_hookean") {
    law_params.set("mu", fit.neo_mu);
    return make_neo_hookean(law_params);
  }
  throw InputError(params.where("law"), "unknown preset law '" + law + "' (allowed: yeoh, neo_hookean)");
}

}  // namespace

// One line per law: its name, factory and example parameters [Pa].
const std::map<std::string, MaterialLaw>& material_registry() {
  static const std::map<std::string, MaterialLaw> registry = {
      {"neo_hookean", {make_neo_hookean, {{"mu", {80e3}}, {"kappa", {2e6}}}}},
      {"mooney_rivlin", {make_mooney_rivlin, {{"c10", {30e3}}, {"c01", {8e3}}, {"nu", {0.45}}}}},
      {"yeoh", {make_yeoh, {{"c1", {21.6e3}}, {"c2", {3.0e3}}, {"c3", {-110.0}}, {"kappa", {1e6}}}}},
      {"ogden", {make_ogden, {{"mu", {27e3}}, {"alpha", {3.13}}, {"kappa", {1e6}}}}},
      {"fabric",
       {make_fabric,
        {{"mu", {1e5}}, {"nu", {0.3}}, {"fibre_modulus", {1e8}}, {"fibres", {1, 0, 0, 0, 1, 0, 1, 1, 0}}}}},
      {"dragon_skin_10", {[](const ParamSet& p) { return make_silicone_preset(p, kDragonSkin10); }, {}}},
      {"dragon_skin_30", {[](const ParamSet& p) { return make_silicone_preset(p, kDragonSkin30); }, {}}},
  };
  return registry;
}

ParamSet example_parameters(const std::string& name) {
  const MaterialLaw& law = material_registry().at(name);
  ParamSet p("material registry: " + name);
  p.set_string("model", name);
  for (const auto& [key, values] : law.example) p.set(key, values);
  for (const auto& [key, text] : law.example_strings) p.set_string(key, text);
  return p;
}

std::unique_ptr<Material> make_material(const ParamSet& params) {
  const std::string model = params.string("model");
  const auto& registry = material_registry();
  auto it = registry.find(model);
  if (it == registry.end()) {
    throw InputError(params.where("model"),
                     "unknown material model '" + model + "' (known: " + join_keys(registry, ", ") + ")");
  }
  return it->second.make(params);
}

}  // namespace morphfem
