// Tensile-test reader and hyperelastic fits (formulas in material_fit.h).
#include "fem/material_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <sstream>

#include "core/errors.h"
#include "core/json.h"
#include "core/test_machine_export.h"

namespace morphfem {

TensileTest tensile_test_from_export(const SpecimenExport& s) {
  TensileTest test;
  test.file = s.file;
  test.header = s.header;
  test.material = s.header_value("material");
  if (test.material.empty()) test.material = s.label;
  using Q = ExportQuantity;
  const ExportColumn* eng_strain = s.find(Q::strain, "", {"true"});
  const ExportColumn* eng_stress = s.find(Q::stress, "", {"true"});
  const ExportColumn* true_strain = s.find(Q::strain, "true");
  const ExportColumn* true_stress = s.find(Q::stress, "true");
  const ExportColumn* extension = s.find(Q::displacement);
  const ExportColumn* force = s.find(Q::force);
  double gauge = 0, area = 0, width = 0, thickness = 0;
  const bool has_gauge =
      s.header_si("gauge length", gauge) || s.header_si("gage length", gauge) || s.header_si("specimen length", gauge);
  const bool has_area =
      s.header_si("cross-section", area) || s.header_si("cross section", area) || s.header_si("area", area) ||
      (s.header_si("width", width) && s.header_si("thickness", thickness) && (area = width * thickness) > 0.0);
  const size_t n = s.rows();
  if (eng_strain && eng_stress) {
    test.conversion = "stretch = 1 + '" + eng_strain->label + "', nominal stress = '" + eng_stress->label +
                      "' (force / initial cross-section)";
    for (size_t i = 0; i < n; ++i) {
      test.stretch.push_back(1.0 + eng_strain->values[i]);
      test.nominal_stress.push_back(eng_stress->values[i]);
    }
  } else if (extension && force && has_gauge && has_area && gauge > 0.0 && area > 0.0) {
    std::ostringstream c;
    c << "stretch = 1 + '" << extension->label << "' / gauge length " << gauge * 1e3 << " mm, nominal stress = '"
      << force->label << "' / cross-section " << area * 1e6 << " mm^2";
    test.conversion = c.str();
    for (size_t i = 0; i < n; ++i) {
      test.stretch.push_back(1.0 + extension->values[i] / gauge);
      test.nominal_stress.push_back(force->values[i] / area);
    }
  } else if (true_strain && true_stress) {
    test.conversion = "stretch = exp('" + true_strain->label + "'), nominal stress = '" + true_stress->label +
                      "' / stretch (incompressible)";
    for (size_t i = 0; i < n; ++i) {
      const double lambda = std::exp(true_strain->values[i]);
      test.stretch.push_back(lambda);
      test.nominal_stress.push_back(true_stress->values[i] / lambda);
    }
  } else {
    std::string found;
    for (const auto& c : s.columns) found += (found.empty() ? "'" : ", '") + c.label + "'";
    throw InputError(s.where(),
                     "no usable stress-strain columns: need an engineering strain and stress, or an extension and "
                     "a load with the specimen length and cross-section in the header block, or a true strain and "
                     "stress; found columns " +
                         found);
  }
  if (test.stretch.size() < 2) throw InputError(s.where(), "fewer than two data rows");
  return test;
}

std::vector<TensileTest> read_tensile_tests(const std::string& path) {
  std::vector<TensileTest> tests;
  for (const auto& block : read_test_machine_export(path)) tests.push_back(tensile_test_from_export(block));
  return tests;
}

TensileTest read_tensile_csv(const std::string& path) {
  auto tests = read_tensile_tests(path);
  return tests.front();
}

// ---------------------------------------------------------------------------------
// Closed forms.

double uniaxial_stress_neo_hookean(double lambda, double mu) { return mu * (lambda - 1.0 / (lambda * lambda)); }

double uniaxial_stress_yeoh(double lambda, double c1, double c2, double c3) {
  const double x = lambda * lambda + 2.0 / lambda - 3.0;
  return 2.0 * (lambda - 1.0 / (lambda * lambda)) * (c1 + 2.0 * c2 * x + 3.0 * c3 * x * x);
}

double uniaxial_stress_ogden(double lambda, const std::vector<double>& mu, const std::vector<double>& alpha) {
  double P = 0;
  for (size_t p = 0; p < mu.size(); ++p)
    P += mu[p] * (std::pow(lambda, alpha[p] - 1.0) - std::pow(lambda, -0.5 * alpha[p] - 1.0));
  return P;
}

double FitResult::value(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return values[i];
  throw std::out_of_range("FitResult::value: no coefficient " + name);
}

namespace {

template <class Model>
double rms_error(const std::vector<double>& stretch, const std::vector<double>& P, Model model) {
  double sum = 0;
  for (size_t i = 0; i < stretch.size(); ++i) sum += std::pow(model(stretch[i]) - P[i], 2);
  return std::sqrt(sum / static_cast<double>(stretch.size()));
}

// R^2 = 1 - SS_res / SS_tot with SS_res = n rms^2, SS_tot = sum (P - mean P)^2.
double r_squared(const std::vector<double>& P, double rms) {
  double mean = 0, ss_tot = 0;
  for (double p : P) mean += p / static_cast<double>(P.size());
  for (double p : P) ss_tot += (p - mean) * (p - mean);
  return ss_tot > 0.0 ? 1.0 - static_cast<double>(P.size()) * rms * rms / ss_tot : 0.0;
}

void check_fit_data(const std::vector<double>& stretch, const std::vector<double>& P, size_t unknowns) {
  if (stretch.size() != P.size()) throw std::invalid_argument("fit: stretch and stress differ in length");
  if (stretch.size() < unknowns + 1)
    throw InputError("", "too few data points (" + std::to_string(stretch.size()) + ") for a fit with " +
                             std::to_string(unknowns) + " unknowns");
}

// Linear least squares min |B c - P| with column scaling, via column-pivoting QR.
Eigen::VectorXd linear_lsq(const Eigen::MatrixXd& B, const Eigen::VectorXd& P) {
  Eigen::VectorXd scale = B.colwise().norm().transpose();
  for (int j = 0; j < scale.size(); ++j)
    if (scale(j) == 0.0) scale(j) = 1.0;
  const Eigen::MatrixXd Bs = B * scale.cwiseInverse().asDiagonal();
  return Bs.colPivHouseholderQr().solve(P).cwiseQuotient(scale);
}

// Standard errors of linear least-squares coefficients c of y ~ B c (see FitResult).
std::vector<double> linear_std_errors(const Eigen::MatrixXd& B, const Eigen::VectorXd& y, const Eigen::VectorXd& c) {
  const long n = B.rows(), p = B.cols();
  if (n <= p) return std::vector<double>(static_cast<size_t>(p), std::numeric_limits<double>::quiet_NaN());
  const double s2 = (y - B * c).squaredNorm() / static_cast<double>(n - p);
  // (B^T B)^-1 through the column-scaled normal matrix (columns differ by orders).
  Eigen::VectorXd scale = B.colwise().norm().transpose();
  for (int j = 0; j < scale.size(); ++j)
    if (scale(j) == 0.0) scale(j) = 1.0;
  const Eigen::MatrixXd Bs = B * scale.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd inv = (Bs.transpose() * Bs).inverse();
  std::vector<double> se(static_cast<size_t>(p));
  for (long j = 0; j < p; ++j) se[static_cast<size_t>(j)] = std::sqrt(s2 * inv(j, j)) / scale(j);
  return se;
}

}  // namespace

FitResult fit_neo_hookean(const std::vector<double>& stretch, const std::vector<double>& P) {
  check_fit_data(stretch, P, 1);
  const int n = static_cast<int>(stretch.size());
  Eigen::MatrixXd B(n, 1);
  Eigen::VectorXd y(n);
  double num = 0, den = 0;
  for (int i = 0; i < n; ++i) {
    const double f = stretch[i] - 1.0 / (stretch[i] * stretch[i]);
    B(i, 0) = f;
    y(i) = P[i];
    num += f * P[i];
    den += f * f;
  }
  FitResult r;
  r.model = "neo_hookean";
  r.names = {"mu"};
  r.values = {num / den};
  r.std_errors = linear_std_errors(B, y, Eigen::VectorXd::Constant(1, num / den));
  r.small_strain_mu = r.values[0];
  r.stable = r.values[0] > 0.0;
  r.rms = rms_error(stretch, P, [&](double l) { return uniaxial_stress_neo_hookean(l, r.values[0]); });
  r.r2 = r_squared(P, r.rms);
  return r;
}

FitResult fit_yeoh(const std::vector<double>& stretch, const std::vector<double>& P) {
  check_fit_data(stretch, P, 3);
  const int n = static_cast<int>(stretch.size());
  Eigen::MatrixXd B(n, 3);
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) {
    const double l = stretch[i], x = l * l + 2.0 / l - 3.0, f = 2.0 * (l - 1.0 / (l * l));
    B.row(i) << f, 2.0 * f * x, 3.0 * f * x * x;
    y(i) = P[i];
  }
  const Eigen::VectorXd c = linear_lsq(B, y);
  FitResult r;
  r.model = "yeoh";
  r.names = {"c1", "c2", "c3"};
  r.values = {c(0), c(1), c(2)};
  r.std_errors = linear_std_errors(B, y, c);
  r.small_strain_mu = 2.0 * c(0);
  // Stable if dW/dI1 = c1 + 2 c2 x + 3 c3 x^2 > 0 for 0 <= x <= 7 (the range the law accepts).
  r.stable = c(0) > 0.0;
  for (double x = 0; x <= 7.0; x += 0.01) r.stable = r.stable && c(0) + 2.0 * c(1) * x + 3.0 * c(2) * x * x > 0.0;
  r.rms = rms_error(stretch, P, [&](double l) { return uniaxial_stress_yeoh(l, c(0), c(1), c(2)); });
  r.r2 = r_squared(P, r.rms);
  return r;
}

namespace {

// The Ogden least-squares problem in scaled form: stresses divided by S = max |P| so
// the residuals are O(1); unknowns theta = (mu_1/S .. mu_N/S, alpha_1 .. alpha_N).
struct OgdenProblem {
  int terms = 0;
  Eigen::VectorXd y;     // P_i / S [-]
  Eigen::VectorXd logl;  // log lambda_i [-]

  int points() const { return static_cast<int>(y.size()); }

  // r_i = sum_p mu_p (lambda_i^(alpha_p - 1) - lambda_i^(-alpha_p/2 - 1)) - y_i, and
  // its Jacobian dr/dmu_p = e1 - e2, dr/dalpha_p = mu_p log(lambda) (e1 + e2 / 2).
  void residual(const Eigen::VectorXd& th, Eigen::VectorXd& r, Eigen::MatrixXd* Jac) const {
    const int n = points();
    r = -y;
    if (Jac) Jac->resize(n, 2 * terms);
    for (int p = 0; p < terms; ++p) {
      const double mu = th(p), a = th(terms + p);
      for (int i = 0; i < n; ++i) {
        const double e1 = std::exp((a - 1.0) * logl(i)), e2 = std::exp((-0.5 * a - 1.0) * logl(i));
        r(i) += mu * (e1 - e2);
        if (Jac) {
          (*Jac)(i, p) = e1 - e2;
          (*Jac)(i, terms + p) = mu * logl(i) * (e1 + 0.5 * e2);
        }
      }
    }
  }

  // Given exponents, the moduli are a linear least-squares problem (used for starts).
  Eigen::VectorXd moduli_for(const std::vector<double>& alpha) const {
    const int n = points();
    Eigen::MatrixXd B(n, terms);
    for (int p = 0; p < terms; ++p)
      for (int i = 0; i < n; ++i)
        B(i, p) = std::exp((alpha[p] - 1.0) * logl(i)) - std::exp((-0.5 * alpha[p] - 1.0) * logl(i));
    return linear_lsq(B, y);
  }

  // Levenberg-Marquardt on |r|^2 from `th`: returns (theta, cost); `converged` when the
  // decrease or the step became negligible, or no damping gives a descent.
  std::pair<Eigen::VectorXd, double> levenberg_marquardt(Eigen::VectorXd th, int max_iterations,
                                                         bool& converged) const {
    Eigen::VectorXd r, r_new;
    Eigen::MatrixXd Jac;
    residual(th, r, &Jac);
    double cost = r.squaredNorm(), damping = 1e-3;
    converged = false;
    for (int it = 0; it < max_iterations && !converged; ++it) {
      const Eigen::MatrixXd JtJ = Jac.transpose() * Jac;
      const Eigen::VectorXd g = Jac.transpose() * r;
      bool accepted = false;
      while (!accepted && damping < 1e14) {
        Eigen::MatrixXd H = JtJ;
        H.diagonal() += damping * JtJ.diagonal().cwiseMax(1e-12);
        const Eigen::VectorXd step = H.ldlt().solve(-g);
        const Eigen::VectorXd th_new = th + step;
        residual(th_new, r_new, nullptr);
        const double cost_new = r_new.squaredNorm();
        if (std::isfinite(cost_new) && cost_new <= cost) {
          const double decrease = cost - cost_new;
          th = th_new;
          residual(th, r, &Jac);
          damping = std::max(damping / 3.0, 1e-12);
          accepted = true;
          if (decrease <= 1e-15 * cost + 1e-30 || step.norm() <= 1e-12 * (1.0 + th.norm())) converged = true;
          cost = cost_new;
        } else {
          damping *= 4.0;
        }
      }
      if (!accepted) converged = true;  // no descent possible: at a (local) minimum
    }
    return std::pair{th, cost};
  }
};

// Scales the data (S = max |P|, 1 if all zero) into an OgdenProblem.
OgdenProblem ogden_problem(const std::vector<double>& stretch, const std::vector<double>& P, int terms, double& S) {
  S = 0;
  for (double p : P) S = std::max(S, std::abs(p));
  if (S == 0.0) S = 1.0;
  const int n = static_cast<int>(stretch.size());
  OgdenProblem problem;
  problem.terms = terms;
  problem.y.resize(n);
  problem.logl.resize(n);
  for (int i = 0; i < n; ++i) {
    problem.y(i) = P[i] / S;
    problem.logl(i) = std::log(stretch[i]);
  }
  return problem;
}

// Starts: every set of `terms` distinct exponents from a grid, moduli by linear LSQ,
// a few LM iterations each. Returns the finite ones as (cost, theta), cheapest first.
std::vector<std::pair<double, Eigen::VectorXd>> ogden_starts(const OgdenProblem& problem) {
  const int terms = problem.terms;
  const std::vector<double> grid = {-4.0, -2.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0};
  const int G = static_cast<int>(grid.size());
  std::vector<int> pick(terms);
  for (int p = 0; p < terms; ++p) pick[p] = p;
  std::vector<std::pair<double, Eigen::VectorXd>> candidates;  // (cost, theta)
  while (true) {
    std::vector<double> alpha(terms);
    for (int p = 0; p < terms; ++p) alpha[p] = grid[pick[p]];
    Eigen::VectorXd th(2 * terms);
    th.head(terms) = problem.moduli_for(alpha);
    for (int p = 0; p < terms; ++p) th(terms + p) = alpha[p];
    bool converged = false;
    auto [th_fit, cost] = problem.levenberg_marquardt(th, 30, converged);
    if (std::isfinite(cost) && th_fit.allFinite()) candidates.emplace_back(cost, th_fit);
    // next combination (lexicographic)
    int p = terms - 1;
    while (p >= 0 && pick[p] == G - terms + p) --p;
    if (p < 0) break;
    ++pick[p];
    for (int q = p + 1; q < terms; ++q) pick[q] = pick[q - 1] + 1;
  }
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return candidates;
}

// The best of the three cheapest starts, each iterated to convergence.
struct OgdenSolution {
  Eigen::VectorXd theta;
  double cost = std::numeric_limits<double>::infinity();
  bool converged = false;
};
OgdenSolution refine_ogden_starts(const OgdenProblem& problem,
                                  const std::vector<std::pair<double, Eigen::VectorXd>>& candidates) {
  OgdenSolution best;
  for (size_t k = 0; k < std::min<size_t>(3, candidates.size()); ++k) {
    bool converged = false;
    auto [th_fit, cost] = problem.levenberg_marquardt(candidates[k].second, 1000, converged);
    if (cost < best.cost && th_fit.allFinite()) {
      best.theta = th_fit;
      best.cost = cost;
      best.converged = converged;
    }
  }
  return best;
}

// The fit in physical units (mu_p = S theta_p), terms reported sorted by exponent,
// with mu0 = sum mu_p alpha_p / 2 and stability mu_p alpha_p > 0.
FitResult ogden_result(const OgdenSolution& best, double S, int terms, const std::vector<double>& stretch,
                       const std::vector<double>& P) {
  FitResult r;
  r.model = "ogden";
  r.converged = best.converged;
  std::vector<double> mu(terms), alpha(terms);
  for (int p = 0; p < terms; ++p) {
    mu[p] = best.theta(p) * S;
    alpha[p] = best.theta(terms + p);
  }
  std::vector<int> order(terms);
  for (int p = 0; p < terms; ++p) order[p] = p;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return alpha[a] < alpha[b]; });
  for (int k = 0; k < terms; ++k) {
    const int p = order[k];
    r.names.push_back("mu" + std::to_string(k + 1));
    r.values.push_back(mu[p]);
    r.names.push_back("alpha" + std::to_string(k + 1));
    r.values.push_back(alpha[p]);
    r.small_strain_mu += 0.5 * mu[p] * alpha[p];
    r.stable = r.stable && mu[p] * alpha[p] > 0.0;
  }
  r.rms = rms_error(stretch, P, [&](double l) { return uniaxial_stress_ogden(l, mu, alpha); });
  r.r2 = r_squared(P, r.rms);
  return r;
}

}  // namespace

FitResult fit_ogden(const std::vector<double>& stretch, const std::vector<double>& P, int terms) {
  if (terms < 1 || terms > 4) throw std::invalid_argument("fit_ogden: 1 to 4 terms");
  check_fit_data(stretch, P, 2 * static_cast<size_t>(terms));
  double S = 1;
  const OgdenProblem problem = ogden_problem(stretch, P, terms, S);
  const auto candidates = ogden_starts(problem);
  if (candidates.empty()) throw InputError("", "Ogden fit failed: no finite solution from any start");
  return ogden_result(refine_ogden_starts(problem, candidates), S, terms, stretch, P);
}

void select_strain_range(const TensileTest& test, double max_strain, std::vector<double>& stretch,
                         std::vector<double>& P) {
  stretch.clear();
  P.clear();
  for (size_t i = 0; i < test.stretch.size(); ++i) {
    const double strain = test.stretch[i] - 1.0;
    if (strain > max_strain) break;
    if (strain > 0.0) {
      stretch.push_back(test.stretch[i]);
      P.push_back(test.nominal_stress[i]);
    }
  }
}

// ---------------------------------------------------------------------------------
// Every file of a directory, and what is printed of the fits.

std::vector<MaterialFits> fit_material_directory(const std::string& data_dir, double max_strain) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(data_dir)) throw InputError(data_dir, "data directory does not exist");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(data_dir))
    if (entry.is_regular_file() && entry.path().extension() == ".csv") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(data_dir, "no *.csv tensile-test files in the data directory");
  std::vector<MaterialFits> out;
  for (const auto& file : files)
    for (auto& t : read_tensile_tests(file)) {  // every specimen block of every file
      MaterialFits m;
      m.test = std::move(t);
      m.max_strain = max_strain;
      select_strain_range(m.test, max_strain, m.stretch, m.stress);
      m.fits = {fit_neo_hookean(m.stretch, m.stress), fit_yeoh(m.stretch, m.stress)};
      for (int N = 1; N <= 3; ++N) m.fits.push_back(fit_ogden(m.stretch, m.stress, N));
      out.push_back(std::move(m));
    }
  return out;
}

namespace {

// One material's fits as JSON: file, conversion, range and per model the coefficients,
// RMS [Pa], R^2, small-strain mu [Pa], stability and convergence.
Json material_fits_json(const MaterialFits& m) {
  namespace fs = std::filesystem;
  std::vector<Json> json_fits;
  for (const auto& f : m.fits) {
    Json c;
    for (size_t k = 0; k < f.names.size(); ++k) c.add(f.names[k], f.values[k]);
    Json j;
    j.add("model", f.model)
        .add("coefficients", c)
        .add("rms_pa", f.rms)
        .add("r2", f.r2)
        .add("small_strain_mu_pa", f.small_strain_mu)
        .add("stable", f.stable)
        .add("converged", f.converged);
    json_fits.push_back(j);
  }
  Json material;
  material.add("file", fs::path(m.test.file).filename().string())
      .add("material", m.test.material)
      .add("conversion", m.test.conversion)
      .add("max_strain", m.max_strain)
      .add("points", static_cast<int>(m.stretch.size()))
      .add("stretch_range", std::vector<double>{m.stretch.front(), m.stretch.back()})
      .add("fits", json_fits);
  return material;
}

// One material's table: a heading (material, file, conversion, fitted range), then a
// row per model with coefficients, RMS [kPa], R^2, mu0 [kPa] and stability.
void print_material_fits(const MaterialFits& m, std::ostream& out) {
  namespace fs = std::filesystem;
  const TensileTest& test = m.test;
  const std::vector<double>& stretch = m.stretch;
  out << test.material << "  (" << fs::path(test.file).filename().string() << ")\n"
      << "  " << test.conversion << "\n"
      << "  fitted range: engineering strain <= " << m.max_strain << " -> stretch " << std::setprecision(4)
      << stretch.front() << " .. " << stretch.back() << ", " << stretch.size() << " points\n";
  out << "  " << std::left << std::setw(14) << "model" << std::setw(64) << "coefficients [Pa; alpha -]" << std::right
      << std::setw(10) << "RMS [kPa]" << std::setw(9) << "R^2" << std::setw(12) << "mu0 [kPa]"
      << "  stable\n";
  for (const auto& f : m.fits) {
    std::ostringstream c;
    c << std::setprecision(5);
    for (size_t k = 0; k < f.names.size(); ++k) c << (k ? ", " : "") << f.names[k] << " = " << f.values[k];
    std::string label = f.model;
    if (f.model == "ogden") label += " N=" + std::to_string(f.names.size() / 2);
    out << "  " << std::left << std::setw(14) << label << std::setw(64) << c.str() << std::right << std::fixed
        << std::setprecision(3) << std::setw(10) << f.rms / 1e3 << std::setprecision(5) << std::setw(9) << f.r2
        << std::setw(12) << std::setprecision(2) << f.small_strain_mu / 1e3 << "  " << (f.stable ? "yes" : "NO")
        << (f.converged ? "" : " (not converged)") << "\n"
        << std::defaultfloat;
  }
  out << "\n";
}

// One CSV row per fitted point: material, stretch, data P and the fitted P [Pa] of
// neo-Hookean, Yeoh and Ogden N = 1, 2, 3 (the order of MaterialFits::fits).
void append_fit_curves(const MaterialFits& m, std::ostream& curves) {
  const std::vector<FitResult>& fits = m.fits;
  for (size_t i = 0; i < m.stretch.size(); ++i) {
    const double l = m.stretch[i];
    curves << '"' << m.test.material << '"' << ',' << l << ',' << m.stress[i] << ','
           << uniaxial_stress_neo_hookean(l, fits[0].values[0]) << ','
           << uniaxial_stress_yeoh(l, fits[1].values[0], fits[1].values[1], fits[1].values[2]);
    for (int N = 1; N <= 3; ++N) {
      const auto& f = fits[1 + N];
      std::vector<double> mu, alpha;
      for (size_t k = 0; k < f.values.size(); k += 2) {
        mu.push_back(f.values[k]);
        alpha.push_back(f.values[k + 1]);
      }
      curves << ',' << uniaxial_stress_ogden(l, mu, alpha);
    }
    curves << '\n';
  }
}

}  // namespace

int fit_materials(const FitMaterialsOptions& o, std::ostream& out) {
  if (o.data_dir.empty()) throw InputError("fit-materials", "no data directory: give --data-dir DIR");
  std::vector<Json> json_materials;
  std::ostringstream curves;
  curves << "material,stretch,data_nominal_stress_pa,neo_hookean_pa,yeoh_pa,ogden1_pa,ogden2_pa,ogden3_pa\n";
  curves << std::setprecision(10);
  for (const MaterialFits& m : fit_material_directory(o.data_dir, o.max_strain)) {
    if (o.json)
      json_materials.push_back(material_fits_json(m));
    else
      print_material_fits(m, out);
    if (!o.curves_file.empty()) append_fit_curves(m, curves);
  }
  if (o.json) {
    Json root;
    root.add("max_strain", o.max_strain).add("materials", json_materials);
    out << root.str(true) << "\n";
  }
  if (!o.curves_file.empty()) write_file_atomic(o.curves_file, curves.str());
  return 0;
}

}  // namespace morphfem
