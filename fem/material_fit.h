// Calibration of hyperelastic laws from uniaxial tensile tests.
//
// Input: test-machine exports read by core/test_machine_export.h: a header block of
// specimen parameters ("Specimen Length (mm);33", "Specimen Cross-section (cm^2);0.18",
// ...), column names with units, then numeric rows (converted to SI). Conversion to stretch lambda and nominal
// (first Piola-Kirchhoff) stress P, in order of preference:
//   1. engineering strain + engineering stress columns: lambda = 1 + strain,
//      P = engineering stress (= force / initial cross-section);
//   2. extension + force columns: lambda = 1 + extension / gauge length,
//      P = force / initial cross-section (both from the header block);
//   3. true (logarithmic) strain + true stress: lambda = exp(true strain),
//      P = true stress / lambda (incompressible: A = A0 / lambda).
// Engineering columns are those whose name does not contain "true".
//
// Fits (incompressible uniaxial tension, lambda_2 = lambda_3 = lambda^(-1/2)):
//   P = 2 (lambda - lambda^-2) (dW/dI1 + dW/dI2 / lambda),
//   neo-Hookean  P = mu (lambda - lambda^-2)                         (linear LSQ)
//   Yeoh         P = 2 (lambda - lambda^-2)(c1 + 2 c2 x + 3 c3 x^2),
//                x = lambda^2 + 2/lambda - 3                          (linear LSQ)
//   Ogden (N)    P = sum_p mu_p (lambda^(alpha_p - 1) - lambda^(-alpha_p/2 - 1))
//                (Levenberg-Marquardt from a grid of starting exponents)
// All least squares on P, unweighted, over the points with 0 < strain <= max_strain.
#pragma once
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "core/test_machine_export.h"

namespace morphfem {

struct TensileTest {
  std::string file;
  std::string material;                       // header "Material", else the file name
  std::map<std::string, std::string> header;  // specimen parameters, key -> value
  std::string conversion;                     // how lambda and P were obtained
  std::vector<double> stretch;                // lambda [-]
  std::vector<double> nominal_stress;         // P [Pa]
};

// Reads an export with the test-machine reader (core/test_machine_export.h: any
// separator, decimal commas, units row or units in names); bad files throw
// InputError naming the file and line. read_tensile_csv: the first specimen block.
TensileTest read_tensile_csv(const std::string& path);
std::vector<TensileTest> read_tensile_tests(const std::string& path);
TensileTest tensile_test_from_export(const SpecimenExport& specimen);

// Incompressible uniaxial nominal stress [Pa] of the laws (closed forms above).
double uniaxial_stress_neo_hookean(double lambda, double mu);
double uniaxial_stress_yeoh(double lambda, double c1, double c2, double c3);
double uniaxial_stress_ogden(double lambda, const std::vector<double>& mu, const std::vector<double>& alpha);

struct FitResult {
  std::string model;               // "neo_hookean", "yeoh", "ogden"
  std::vector<std::string> names;  // coefficient names: mu | c1 c2 c3 | mu1 alpha1 ...
  std::vector<double> values;      // [Pa] for moduli, [-] for exponents
  // Standard errors of the linear fits (neo-Hookean, Yeoh): sqrt of the diagonal of
  // s^2 (B^T B)^-1, s^2 = SS_res / (n - p); empty for the iterative (Ogden) fits.
  std::vector<double> std_errors;
  double rms = 0;              // RMS error of P [Pa]
  double r2 = 0;               // coefficient of determination 1 - SS_res / SS_tot [-]
  double small_strain_mu = 0;  // small-strain shear modulus [Pa]
  bool stable = true;          // usable as a law (Yeoh: dW/dI1 > 0 up to x = 7; Ogden: mu_p alpha_p > 0)
  bool converged = true;       // iterative fits only
  double value(const std::string& name) const;
};

FitResult fit_neo_hookean(const std::vector<double>& stretch, const std::vector<double>& P);
FitResult fit_yeoh(const std::vector<double>& stretch, const std::vector<double>& P);
FitResult fit_ogden(const std::vector<double>& stretch, const std::vector<double>& P, int terms);

// The points of `test` with 0 < engineering strain <= max_strain (stops at the first
// point beyond it, so a post-failure tail is never used).
void select_strain_range(const TensileTest& test, double max_strain, std::vector<double>& stretch,
                         std::vector<double>& P);

// Every specimen of every *.csv export in `data_dir` (sorted by file name) fitted
// over 0 < engineering strain <= max_strain: neo-Hookean, Yeoh, Ogden N = 1, 2, 3 (in
// that order). InputError for a missing or empty directory or a malformed file.
struct MaterialFits {
  TensileTest test;
  double max_strain = 0;
  std::vector<double> stretch, stress;  // the fitted points: lambda [-], P [Pa]
  std::vector<FitResult> fits;
};
std::vector<MaterialFits> fit_material_directory(const std::string& data_dir, double max_strain);

// Fits every *.csv in `data_dir` and prints a table per material and model
// (coefficients, RMS error in kPa, range used), or JSON with `json`; a non-empty
// `curves_file` gets data and fitted curves as CSV (for scripts/plot_material_fit.py).
// Returns 0; bad data throw InputError. (`morphfem fit-materials`, app/, reads these
// options from its command line.)
struct FitMaterialsOptions {
  std::string data_dir;
  double max_strain = 2.0;  // engineering strain [-], in (0.05, 20]
  bool json = false;
  std::string curves_file;
};
int fit_materials(const FitMaterialsOptions& options, std::ostream& out = std::cout);

}  // namespace morphfem
