// Hyperelastic material laws. A law is a parameter struct plus pure functions of
// the deformation gradient F returning the strain-energy density W [J/m^3 = Pa],
// the first Piola-Kirchhoff stress P = dW/dF [Pa] and the tangent
// A = dP/dF [Pa]. No PETSc objects in here.
//
// Index convention: F, P flattened row-major, a = 3*i + J for F_iJ, so
// A(3*i+J, 3*k+L) = d P_iJ / d F_kL.
//
// Every law is split into an isochoric part (function of Fbar = J^(-1/3) F) and a
// volumetric part U(J) = kappa/4 (J^2 - 1 - 2 ln J) (kappa: bulk modulus [Pa]),
// which is convex in J and infinite as J -> 0.
#pragma once
#include <Eigen/Dense>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/params.h"

namespace morphfem {

using Mat3 = Eigen::Matrix3d;
using Tangent = Eigen::Matrix<double, 9, 9>;

class Material {
 public:
  virtual ~Material() = default;
  virtual std::string name() const = 0;
  // Energy density W(F) [Pa]; +infinity if det F <= 0.
  virtual double energy(const Mat3& F) const = 0;
  // W, P and (if A != nullptr) A at F. Requires det F > 0.
  virtual void evaluate(const Mat3& F, double& W, Mat3& P, Tangent* A) const = 0;
  // The isochoric part alone, W_iso(F) = W(F) - U(J) [Pa] (a function of
  // Fbar = J^(-1/3) F), P_iso = dW_iso/dF [Pa] and (if A != nullptr)
  // A_iso = dP_iso/dF [Pa]. Requires det F > 0. Element formulations that
  // discretise the volume change separately (mean dilatation) combine it with
  // volumetric_energy() evaluated at their own dilatation.
  virtual void evaluate_isochoric(const Mat3& F, double& W, Mat3& P, Tangent* A) const = 0;
  // The volumetric part U(J) = kappa/4 (J^2 - 1 - 2 ln J) [Pa] and its derivatives
  // dU = U'(J) = kappa/2 (J - 1/J), d2U = U''(J) = kappa/2 (1 + 1/J^2) [Pa].
  // Requires J > 0. W(F) = W_iso(F) + U(det F) for every law.
  virtual void volumetric_energy(double J, double& U, double& dU, double& d2U) const = 0;
  // Small-strain shear and bulk moduli [Pa] (for reporting, time steps, penalties).
  virtual double shear_modulus() const = 0;
  virtual double bulk_modulus() const = 0;
  // Whether W is twice differentiable within h of F in every component of F. A law
  // with kinks (the fabric's fibres going slack) says where they are, so that a
  // finite-difference check of its tangent steps around them.
  virtual bool smooth_near(const Mat3& F, double h) const { return F.allFinite() && h >= 0; }
  // Whether the law is isotropic: at F = I its tangent is linear elasticity with
  // shear_modulus() and bulk_modulus().
  virtual bool isotropic() const { return true; }
};

using MaterialFactory = std::function<std::unique_ptr<Material>(const ParamSet&)>;

// A law registered by name: its factory, and parameters it is valid with, with which
// tests/fem/test_material_laws.cpp checks every registered law (stress and tangent
// against finite differences, symmetry, objectivity, W = W_iso + U): registering a law
// is what gets it checked.
struct MaterialLaw {
  MaterialFactory make;
  std::vector<std::pair<std::string, std::vector<double>>> example;
  std::vector<std::pair<std::string, std::string>> example_strings = {};
};

// name -> factory. Names: neo_hookean (mu, kappa), mooney_rivlin (c10, c01, kappa),
// yeoh (c1, c2, c3, kappa), ogden (mu: [..], alpha: [..], kappa), fabric (a
// neo-Hookean matrix mu, kappa plus tension-only fibres: fibre_modulus, fibres). Presets
// dragon_skin_10 and dragon_skin_30 take optional kappa. The bulk modulus may be
// given as kappa [Pa] or as Poisson's ratio nu (one of them is required, except for
// the presets, which default to nu = 0.49). Presets also take `law: yeoh`
// (default) or `law: neo_hookean`; their coefficients are fits to the tensile data
// in shared/data/materials over <= 200 % strain (see fem/material.cpp).
const std::map<std::string, MaterialLaw>& material_registry();
// The registry's example parameters of law `name` (model = name) as a ParamSet.
ParamSet example_parameters(const std::string& name);

// Builds `params.string("model")`; unknown names and bad parameters throw InputError.
std::unique_ptr<Material> make_material(const ParamSet& params);

// Law factories (one file each: fem/material_<name>.cpp), registered by name in
// fem/material.cpp. Each validates its keys (allow_only) and ranges.
std::unique_ptr<Material> make_neo_hookean(const ParamSet& params);
std::unique_ptr<Material> make_mooney_rivlin(const ParamSet& params);
std::unique_ptr<Material> make_yeoh(const ParamSet& params);
std::unique_ptr<Material> make_ogden(const ParamSet& params);
std::unique_ptr<Material> make_fabric(const ParamSet& params);

// Helpers for the factories.
// Bulk modulus [Pa] from `kappa` [Pa] or Poisson's ratio `nu` (exactly one is
// required): kappa = 2 mu0 (1 + nu) / (3 (1 - 2 nu)), mu0 = small-strain shear modulus.
double bulk_modulus_from_params(const ParamSet& params, double mu0);
// `key` must be a number in (0, hi]; the message says what the parameter is.
double positive_parameter(const ParamSet& params, const std::string& key, double hi, const std::string& what);
// Fibre families of a fabric: `fibres` as 3 numbers per family (default the warp along
// x and the weft along y), each normalised; a zero direction or a list whose length is
// not a multiple of 3 throws InputError at the key.
std::vector<Eigen::Vector3d> fibre_directions(const ParamSet& params);

}  // namespace morphfem
