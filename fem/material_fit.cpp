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
#include <optional>
#include <sstream>

#include "core/errors.h"
#include "core/json.h"

namespace morphfem {

namespace {

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ';')) out.push_back(trim(field));
  if (!line.empty() && line.back() == ';') out.push_back("");
  return out;
}

// A number, accepting a decimal comma ("0,25") as European exports write it.
std::optional<double> parse_number(std::string s) {
  s = trim(s);
  if (s.empty()) return std::nullopt;
  if (s.find(',') != std::string::npos && s.find('.') == std::string::npos) std::replace(s.begin(), s.end(), ',', '.');
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

bool contains(const std::string& s, const std::string& what) { return s.find(what) != std::string::npos; }

// Unit in parentheses of a column or header name, lower case ("(MPa)" -> "mpa").
std::string unit_of(const std::string& name) {
  const size_t a = name.rfind('('), b = name.rfind(')');
  if (a == std::string::npos || b == std::string::npos || b < a) return "";
  return lower(trim(name.substr(a + 1, b - a - 1)));
}

// Factor to Pa for a stress unit; 0 if unknown.
double stress_unit(const std::string& unit) {
  if (unit == "mpa" || unit == "n/mm^2" || unit == "n/mm2" || unit == "n/mm²") return 1e6;
  if (unit == "kpa") return 1e3;
  if (unit == "pa" || unit == "n/m^2") return 1.0;
  if (unit == "psi") return 6894.757;
  return 0.0;
}

// Factor to a fraction for a strain unit; 0 if unknown.
double strain_unit(const std::string& unit) {
  if (unit.empty() || unit == "mm/mm" || unit == "-" || unit == "m/m") return 1.0;
  if (unit == "%") return 0.01;
  return 0.0;
}

double length_unit_mm(const std::string& unit) {
  if (unit == "mm") return 1.0;
  if (unit == "cm") return 10.0;
  if (unit == "m") return 1000.0;
  return 0.0;
}

double force_unit_n(const std::string& unit) {
  if (unit == "n") return 1.0;
  if (unit == "kn") return 1e3;
  return 0.0;
}

double area_unit_mm2(const std::string& unit) {
  if (unit == "mm^2" || unit == "mm2" || unit == "mm²") return 1.0;
  if (unit == "cm^2" || unit == "cm2" || unit == "cm²") return 100.0;
  if (unit == "m^2" || unit == "m2") return 1e6;
  return 0.0;
}

}  // namespace

TensileTest read_tensile_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the tensile-test file");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  auto at = [&](size_t index) { return path + ":" + std::to_string(index + 1); };

  // The data start at the first row whose first two fields are numbers; the column
  // header is the last non-empty line before it; the lines above are the specimen block.
  size_t data_start = lines.size();
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto f = split_fields(lines[i]);
    if (f.size() >= 2 && parse_number(f[0]) && parse_number(f[1])) {
      data_start = i;
      break;
    }
  }
  if (data_start == lines.size())
    throw InputError(path, "no numeric data rows found (expected a ';'-separated export)");
  size_t header_line = data_start;
  for (size_t i = data_start; i-- > 0;) {
    const auto f = split_fields(lines[i]);
    if (std::any_of(f.begin(), f.end(), [](const std::string& s) { return !s.empty(); })) {
      header_line = i;
      break;
    }
  }
  if (header_line == data_start) throw InputError(at(data_start), "no column header line before the data");

  TensileTest test;
  test.file = path;
  for (size_t i = 0; i < header_line; ++i) {
    const auto f = split_fields(lines[i]);
    if (f.size() >= 2 && !f[0].empty()) test.header[f[0]] = f[1];
  }
  test.material = std::filesystem::path(path).stem().string();
  for (const auto& [key, value] : test.header)
    if (lower(key) == "material" && !value.empty()) test.material = value;

  // Identify columns.
  const auto columns = split_fields(lines[header_line]);
  std::optional<size_t> eng_strain, eng_stress, true_strain, true_stress, force, extension;
  for (size_t c = 0; c < columns.size(); ++c) {
    const std::string name = lower(columns[c]);
    const bool is_true = contains(name, "true");
    auto first = [c](std::optional<size_t>& slot) {
      if (!slot) slot = c;
    };
    if (contains(name, "strain")) first(is_true ? true_strain : eng_strain);
    if (contains(name, "stress")) first(is_true ? true_stress : eng_stress);
    if (contains(name, "load") || contains(name, "force")) first(force);
    if (contains(name, "extension") || contains(name, "displacement") || contains(name, "crosshead")) first(extension);
  }
  auto header_number = [&](const std::vector<std::string>& keys, double (*unit)(const std::string&), double& value) {
    for (const auto& [key, text] : test.header) {
      const std::string k = lower(key);
      for (const auto& want : keys)
        if (contains(k, want)) {
          const auto v = parse_number(text);
          const double factor = unit(unit_of(key));
          if (v && factor > 0.0) {
            value = *v * factor;
            return true;
          }
        }
    }
    return false;
  };
  double gauge_mm = 0, area_mm2 = 0;
  header_number({"gauge length", "specimen length", "gage length"}, length_unit_mm, gauge_mm);
  if (!header_number({"cross-section", "cross section", "area"}, area_unit_mm2, area_mm2)) {
    double width = 0, thickness = 0;
    if (header_number({"width"}, length_unit_mm, width) && header_number({"thickness"}, length_unit_mm, thickness))
      area_mm2 = width * thickness;
  }

  auto unknown_unit = [&](size_t c) {
    return InputError(at(header_line), "column '" + columns[c] + "': unknown unit '" + unit_of(columns[c]) + "'");
  };
  std::vector<size_t> used;
  std::function<void(const std::vector<double>&)> convert;
  if (eng_strain && eng_stress) {
    const double fe = strain_unit(unit_of(columns[*eng_strain]));
    const double fs = stress_unit(unit_of(columns[*eng_stress]));
    if (fe == 0.0) throw unknown_unit(*eng_strain);
    if (fs == 0.0) throw unknown_unit(*eng_stress);
    used = {*eng_strain, *eng_stress};
    test.conversion = "stretch = 1 + '" + columns[*eng_strain] + "', nominal stress = '" + columns[*eng_stress] +
                      "' (force / initial cross-section)";
    convert = [&, fe, fs](const std::vector<double>& v) {
      test.stretch.push_back(1.0 + fe * v[0]);
      test.nominal_stress.push_back(fs * v[1]);
    };
  } else if (extension && force && gauge_mm > 0.0 && area_mm2 > 0.0) {
    const double fl = length_unit_mm(unit_of(columns[*extension]));
    const double ff = force_unit_n(unit_of(columns[*force]));
    if (fl == 0.0) throw unknown_unit(*extension);
    if (ff == 0.0) throw unknown_unit(*force);
    used = {*extension, *force};
    std::ostringstream s;
    s << "stretch = 1 + '" << columns[*extension] << "' / gauge length " << gauge_mm << " mm, nominal stress = '"
      << columns[*force] << "' / cross-section " << area_mm2 << " mm^2";
    test.conversion = s.str();
    convert = [&, fl, ff, gauge_mm, area_mm2](const std::vector<double>& v) {
      test.stretch.push_back(1.0 + fl * v[0] / gauge_mm);
      test.nominal_stress.push_back(ff * v[1] / (area_mm2 * 1e-6));
    };
  } else if (true_strain && true_stress) {
    const double fe = strain_unit(unit_of(columns[*true_strain]));
    const double fs = stress_unit(unit_of(columns[*true_stress]));
    if (fe == 0.0) throw unknown_unit(*true_strain);
    if (fs == 0.0) throw unknown_unit(*true_stress);
    used = {*true_strain, *true_stress};
    test.conversion = "stretch = exp('" + columns[*true_strain] + "'), nominal stress = '" + columns[*true_stress] +
                      "' / stretch (incompressible)";
    convert = [&, fe, fs](const std::vector<double>& v) {
      const double lambda = std::exp(fe * v[0]);
      test.stretch.push_back(lambda);
      test.nominal_stress.push_back(fs * v[1] / lambda);
    };
  } else {
    std::string found;
    for (const auto& c : columns)
      if (!c.empty()) found += (found.empty() ? "'" : ", '") + c + "'";
    throw InputError(at(header_line),
                     "no usable stress-strain columns: need 'Engineering Strain' and 'Engineering Stress', or "
                     "'Extension' and 'Load' with the specimen length and cross-section in the header block, or "
                     "'True Strain' and 'True Stress'; found columns " +
                         found);
  }

  std::vector<double> values(used.size());
  for (size_t i = data_start; i < lines.size(); ++i) {
    const auto f = split_fields(lines[i]);
    if (std::all_of(f.begin(), f.end(), [](const std::string& s) { return s.empty(); })) continue;
    for (size_t k = 0; k < used.size(); ++k) {
      const size_t c = used[k];
      if (c >= f.size() || f[c].empty()) throw InputError(at(i), "missing value in column '" + columns[c] + "'");
      const auto v = parse_number(f[c]);
      if (!v) throw InputError(at(i), "column '" + columns[c] + "': '" + f[c] + "' is not a number");
      values[k] = *v;
    }
    convert(values);
  }
  if (test.stretch.size() < 2) throw InputError(path, "fewer than two data rows");
  return test;
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

}  // namespace

FitResult fit_neo_hookean(const std::vector<double>& stretch, const std::vector<double>& P) {
  check_fit_data(stretch, P, 1);
  double num = 0, den = 0;
  for (size_t i = 0; i < stretch.size(); ++i) {
    const double f = stretch[i] - 1.0 / (stretch[i] * stretch[i]);
    num += f * P[i];
    den += f * f;
  }
  FitResult r;
  r.model = "neo_hookean";
  r.names = {"mu"};
  r.values = {num / den};
  r.small_strain_mu = r.values[0];
  r.stable = r.values[0] > 0.0;
  r.rms = rms_error(stretch, P, [&](double l) { return uniaxial_stress_neo_hookean(l, r.values[0]); });
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
  r.small_strain_mu = 2.0 * c(0);
  // Stable if dW/dI1 = c1 + 2 c2 x + 3 c3 x^2 > 0 for 0 <= x <= 7 (the range the law accepts).
  r.stable = c(0) > 0.0;
  for (double x = 0; x <= 7.0; x += 0.01) r.stable = r.stable && c(0) + 2.0 * c(1) * x + 3.0 * c(2) * x * x > 0.0;
  r.rms = rms_error(stretch, P, [&](double l) { return uniaxial_stress_yeoh(l, c(0), c(1), c(2)); });
  return r;
}

FitResult fit_ogden(const std::vector<double>& stretch, const std::vector<double>& P, int terms) {
  if (terms < 1 || terms > 4) throw std::invalid_argument("fit_ogden: 1 to 4 terms");
  check_fit_data(stretch, P, 2 * static_cast<size_t>(terms));
  const int n = static_cast<int>(stretch.size()), m = 2 * terms;
  // Work with stresses scaled to O(1): theta = (mu_1/S .. mu_N/S, alpha_1 .. alpha_N).
  double S = 0;
  for (double p : P) S = std::max(S, std::abs(p));
  if (S == 0.0) S = 1.0;
  Eigen::VectorXd y(n), logl(n);
  for (int i = 0; i < n; ++i) {
    y(i) = P[i] / S;
    logl(i) = std::log(stretch[i]);
  }
  auto residual = [&](const Eigen::VectorXd& th, Eigen::VectorXd& r, Eigen::MatrixXd* Jac) {
    r = -y;
    if (Jac) Jac->resize(n, m);
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
  };
  // Given exponents, the moduli are a linear least-squares problem (used for starts).
  auto moduli_for = [&](const std::vector<double>& alpha) {
    Eigen::MatrixXd B(n, terms);
    for (int p = 0; p < terms; ++p)
      for (int i = 0; i < n; ++i)
        B(i, p) = std::exp((alpha[p] - 1.0) * logl(i)) - std::exp((-0.5 * alpha[p] - 1.0) * logl(i));
    return linear_lsq(B, y);
  };
  auto levenberg_marquardt = [&](Eigen::VectorXd th, int max_iterations, bool& converged) {
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
  };

  // Starts: every set of `terms` distinct exponents from a grid, moduli by linear LSQ,
  // a few LM iterations each; the best starts are then iterated to convergence.
  const std::vector<double> grid = {-4.0, -2.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0};
  const int G = static_cast<int>(grid.size());
  std::vector<int> pick(terms);
  for (int p = 0; p < terms; ++p) pick[p] = p;
  std::vector<std::pair<double, Eigen::VectorXd>> candidates;  // (cost, theta)
  while (true) {
    std::vector<double> alpha(terms);
    for (int p = 0; p < terms; ++p) alpha[p] = grid[pick[p]];
    Eigen::VectorXd th(m);
    th.head(terms) = moduli_for(alpha);
    for (int p = 0; p < terms; ++p) th(terms + p) = alpha[p];
    bool converged = false;
    auto [th_fit, cost] = levenberg_marquardt(th, 30, converged);
    if (std::isfinite(cost) && th_fit.allFinite()) candidates.emplace_back(cost, th_fit);
    // next combination (lexicographic)
    int p = terms - 1;
    while (p >= 0 && pick[p] == G - terms + p) --p;
    if (p < 0) break;
    ++pick[p];
    for (int q = p + 1; q < terms; ++q) pick[q] = pick[q - 1] + 1;
  }
  if (candidates.empty()) throw InputError("", "Ogden fit failed: no finite solution from any start");
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  Eigen::VectorXd best;
  double best_cost = std::numeric_limits<double>::infinity();
  bool best_converged = false;
  for (size_t k = 0; k < std::min<size_t>(3, candidates.size()); ++k) {
    bool converged = false;
    auto [th_fit, cost] = levenberg_marquardt(candidates[k].second, 1000, converged);
    if (cost < best_cost && th_fit.allFinite()) {
      best = th_fit;
      best_cost = cost;
      best_converged = converged;
    }
  }

  FitResult r;
  r.model = "ogden";
  r.converged = best_converged;
  std::vector<double> mu(terms), alpha(terms);
  for (int p = 0; p < terms; ++p) {
    mu[p] = best(p) * S;
    alpha[p] = best(terms + p);
  }
  // Report terms sorted by exponent.
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
  return r;
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
// Command line.

int fit_materials_main(const std::vector<std::string>& args, const std::string& default_data_dir, std::ostream& out) {
  const std::string usage =
      "usage: morphfem fit-materials [--data-dir DIR] [--max-strain 2.0] [--json] [--curves FILE.csv]";
  std::string data_dir = default_data_dir, curves_file;
  double max_strain = 2.0;
  bool json = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw InputError("fit-materials", "option " + a + " needs a value; " + usage);
      return args[++i];
    };
    if (a == "--data-dir") {
      data_dir = value();
    } else if (a == "--max-strain") {
      const std::string& v = value();
      const auto x = parse_number(v);
      if (!x || *x <= 0.05 || *x > 20.0)
        throw InputError("fit-materials", "--max-strain '" + v + "' must be an engineering strain in (0.05, 20]");
      max_strain = *x;
    } else if (a == "--json") {
      json = true;
    } else if (a == "--curves") {
      curves_file = value();
    } else if (a == "--help" || a == "-h") {
      out << usage << "\n";
      return 0;
    } else {
      throw InputError("fit-materials", "unknown argument '" + a + "'; " + usage);
    }
  }
  if (data_dir.empty()) throw InputError("fit-materials", "no data directory: give --data-dir DIR");
  namespace fs = std::filesystem;
  if (!fs::is_directory(data_dir)) throw InputError(data_dir, "data directory does not exist");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(data_dir))
    if (entry.is_regular_file() && entry.path().extension() == ".csv") files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw InputError(data_dir, "no *.csv tensile-test files in the data directory");

  std::vector<Json> json_materials;
  std::ostringstream curves;
  curves << "material,stretch,data_nominal_stress_pa,neo_hookean_pa,yeoh_pa,ogden1_pa,ogden2_pa,ogden3_pa\n";
  curves << std::setprecision(10);
  for (const auto& file : files) {
    const TensileTest test = read_tensile_csv(file);
    std::vector<double> stretch, P;
    select_strain_range(test, max_strain, stretch, P);
    std::vector<FitResult> fits = {fit_neo_hookean(stretch, P), fit_yeoh(stretch, P)};
    for (int N = 1; N <= 3; ++N) fits.push_back(fit_ogden(stretch, P, N));

    if (json) {
      std::vector<Json> json_fits;
      for (const auto& f : fits) {
        Json c;
        for (size_t k = 0; k < f.names.size(); ++k) c.add(f.names[k], f.values[k]);
        Json j;
        j.add("model", f.model)
            .add("coefficients", c)
            .add("rms_pa", f.rms)
            .add("small_strain_mu_pa", f.small_strain_mu)
            .add("stable", f.stable)
            .add("converged", f.converged);
        json_fits.push_back(j);
      }
      Json m;
      m.add("file", fs::path(file).filename().string())
          .add("material", test.material)
          .add("conversion", test.conversion)
          .add("max_strain", max_strain)
          .add("points", static_cast<int>(stretch.size()))
          .add("stretch_range", std::vector<double>{stretch.front(), stretch.back()})
          .add("fits", json_fits);
      json_materials.push_back(m);
    } else {
      out << test.material << "  (" << fs::path(file).filename().string() << ")\n"
          << "  " << test.conversion << "\n"
          << "  fitted range: engineering strain <= " << max_strain << " -> stretch " << std::setprecision(4)
          << stretch.front() << " .. " << stretch.back() << ", " << stretch.size() << " points\n";
      out << "  " << std::left << std::setw(14) << "model" << std::setw(64) << "coefficients [Pa; alpha -]"
          << std::right << std::setw(10) << "RMS [kPa]" << std::setw(12) << "mu0 [kPa]"
          << "  stable\n";
      for (const auto& f : fits) {
        std::ostringstream c;
        c << std::setprecision(5);
        for (size_t k = 0; k < f.names.size(); ++k) c << (k ? ", " : "") << f.names[k] << " = " << f.values[k];
        std::string label = f.model;
        if (f.model == "ogden") label += " N=" + std::to_string(f.names.size() / 2);
        out << "  " << std::left << std::setw(14) << label << std::setw(64) << c.str() << std::right << std::fixed
            << std::setprecision(3) << std::setw(10) << f.rms / 1e3 << std::setw(12) << std::setprecision(2)
            << f.small_strain_mu / 1e3 << "  " << (f.stable ? "yes" : "NO") << (f.converged ? "" : " (not converged)")
            << "\n"
            << std::defaultfloat;
      }
      out << "\n";
    }
    if (!curves_file.empty()) {
      for (size_t i = 0; i < stretch.size(); ++i) {
        const double l = stretch[i];
        curves << '"' << test.material << '"' << ',' << l << ',' << P[i] << ','
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
  }
  if (json) {
    Json root;
    root.add("max_strain", max_strain).add("materials", json_materials);
    out << root.str(true) << "\n";
  }
  if (!curves_file.empty()) write_file_atomic(curves_file, curves.str());
  return 0;
}

}  // namespace morphfem
