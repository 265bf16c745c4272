// Pull-test analysis (method and definitions in pull_test.h).
#include "optim/pull_test.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <optional>
#include <random>
#include <sstream>

#include "core/errors.h"
#include "core/json.h"

namespace morphfem {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(m), v.end());
  double med = v[m];
  if (v.size() % 2 == 0) med = 0.5 * (med + *std::max_element(v.begin(), v.begin() + static_cast<long>(m)));
  return med;
}

// 5-point running median then 5-point running mean (windows shrink at the ends).
std::vector<double> smooth(const std::vector<double>& f) {
  const long n = static_cast<long>(f.size()), h = 2;
  std::vector<double> med(f.size()), out(f.size());
  for (long i = 0; i < n; ++i) {
    std::vector<double> w(f.begin() + std::max(0L, i - h), f.begin() + std::min(n, i + h + 1));
    med[i] = median_of(w);
  }
  for (long i = 0; i < n; ++i) {
    double s = 0;
    long count = 0;
    for (long j = std::max(0L, i - h); j < std::min(n, i + h + 1); ++j, ++count) s += med[j];
    out[i] = s / static_cast<double>(count);
  }
  return out;
}

bool is_foot_token(const std::string& t) {
  return t == "inflated" || t == "uninflated" || t == "deflated" || t == "vacuum";
}

std::vector<std::string> name_tokens(const std::string& stem) {
  std::vector<std::string> tokens;
  std::string cur;
  for (char c : stem) {
    if (c == '_' || c == '-' || c == ' ' || c == '.') {
      if (!cur.empty()) tokens.push_back(lower(cur));
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) tokens.push_back(lower(cur));
  return tokens;
}

}  // namespace

PullCurve pull_curve_from_export(const SpecimenExport& s) {
  PullCurve c;
  c.file = s.file;
  c.label = s.label;
  const ExportColumn* x = s.find(ExportQuantity::displacement);
  const ExportColumn* f = s.find(ExportQuantity::force);
  const ExportColumn* t = s.find(ExportQuantity::time);
  if (!x || !f) throw InputError(s.where(), "a pull test needs a displacement column (mm) and a force column (N)");
  if (s.rows() < 20) throw InputError(s.where(), "a pull test needs at least 20 data rows");
  c.displacement = x->values;
  const double x0 = c.displacement.front();
  for (double& v : c.displacement) v -= x0;
  c.force = f->values;
  if (t) c.time = t->values;
  c.surface = lower(s.header_value("surface"));
  c.foot_state = lower(s.header_value("foot"));
  if (c.foot_state.empty()) c.foot_state = lower(s.header_value("state"));
  const auto tokens = name_tokens(std::filesystem::path(s.file).stem().string());
  if (c.surface.empty() && !tokens.empty() && !is_foot_token(tokens[0])) c.surface = tokens[0];
  if (c.foot_state.empty())
    for (const auto& tok : tokens)
      if (is_foot_token(tok)) c.foot_state = tok;
  if (c.surface.empty()) c.surface = "unknown";
  if (c.foot_state.empty()) c.foot_state = "unknown";
  return c;
}

namespace {

// Noise sigma [N] from second differences: for white noise of sigma s,
// F[i+1] - 2 F[i] + F[i-1] has sigma s sqrt(6), and its MAD is 1.4826 times sigma.
double force_noise(const std::vector<double>& F) {
  std::vector<double> d2;
  for (size_t i = 1; i + 1 < F.size(); ++i) d2.push_back(std::abs(F[i + 1] - 2.0 * F[i] + F[i - 1]));
  return 1.4826 * median_of(d2) / std::sqrt(6.0);
}

// Static peak: the index of the running maximum of the smoothed force `Fs` when the
// force first drops (by 4 sigma or 3 %) after exceeding 20 % of its global maximum;
// the global maximum if it never drops.
size_t smoothed_peak_index(const std::vector<double>& Fs, double noise_N) {
  const double global_max = *std::max_element(Fs.begin(), Fs.end());
  size_t p = static_cast<size_t>(std::max_element(Fs.begin(), Fs.end()) - Fs.begin());
  double running = -std::numeric_limits<double>::infinity();
  size_t arg = 0;
  for (size_t i = 0; i < Fs.size(); ++i) {
    if (Fs[i] > running) {
      running = Fs[i];
      arg = i;
    }
    if (running > 0.2 * global_max && Fs[i] < running - std::max(4.0 * noise_N, 0.03 * running)) {
      p = arg;
      break;
    }
  }
  return p;
}

// Peak force: the largest 3-point mean of the raw force within 3 samples of p (the
// 5+5-point smoothing would blunt the slip cusp). Returns its index, the force in
// `peak_force_N`. The window of the linear fit ends there, so it holds no point of
// the drop (the smoothed maximum can sit a sample or two past the cusp).
size_t raw_peak_index(const std::vector<double>& F, size_t p, double& peak_force_N) {
  const size_t n = F.size();
  peak_force_N = -std::numeric_limits<double>::infinity();
  size_t top = p;
  for (size_t i = (p > 4 ? p - 3 : 1); i <= std::min(p + 3, n - 2); ++i) {
    const double f3 = (F[i - 1] + F[i] + F[i + 1]) / 3.0;
    if (f3 > peak_force_N) {
      peak_force_N = f3;
      top = i;
    }
  }
  return top;
}

// F ~ a + k xi (+ knee) on the window scaled to xi in [0, 1]; b is where the linear
// regime ends (1 without a knee).
struct HingeFit {
  double sse = 0, b = 1.0, a = 0, k = 0;
  bool knee = false;
};

// The best hinge F = a + k xi - c g(xi - b), c > 0, over knee positions b (the window's
// points, ends excluded) and knee shapes g(d) = l^2 (d/l - 1 + exp(-d/l)) for l from
// 1 % of the window to 3 windows (the largest is the parabola d^2/2 to within a few
// %); `line` when no hinge fits better.
HingeFit best_hinge(const Eigen::VectorXd& xi, const Eigen::VectorXd& y, const HingeFit& line) {
  const int m = static_cast<int>(xi.size());
  HingeFit best = line;
  Eigen::MatrixXd H(m, 3);
  H.col(0).setOnes();
  H.col(1) = xi;
  for (int j = 3; j < m - 2; ++j) {
    const double b = xi(j);
    for (double ell = 0.01; ell < 3.0; ell *= 1.5) {
      for (int i = 0; i < m; ++i) {
        const double u = std::max(0.0, xi(i) - b) / ell;
        H(i, 2) = -ell * ell * (u - 1.0 + std::exp(-u));
      }
      const Eigen::Vector3d c = H.colPivHouseholderQr().solve(y);
      if (!(c(2) > 0.0)) continue;
      const double sse = (H * c - y).squaredNorm();
      if (sse < best.sse) best = {sse, b, c(0), c(1), true};
    }
  }
  return best;
}

// The linear regime over the window s .. p: a line, or a line with a knee where the
// knee improves the fit significantly. Fills linear_end_m, linear_end_force_N,
// slope_N_per_m and knee_found of `a` (whose noise and peak are known).
void fit_linear_regime(const std::vector<double>& x, const std::vector<double>& F, size_t s, size_t p,
                       PullAnalysis& a) {
  // Coordinates scaled to the window (conditioning).
  const double xs = x[s], L = std::max(x[p] - x[s], 1e-12);
  const int m = static_cast<int>(p - s + 1);
  Eigen::VectorXd xi(m), y(m);
  for (int i = 0; i < m; ++i) {
    xi(i) = (x[s + i] - xs) / L;
    y(i) = F[s + i];
  }
  Eigen::MatrixXd B(m, 2);
  B.col(0).setOnes();
  B.col(1) = xi;
  const Eigen::Vector2d coefficients = B.colPivHouseholderQr().solve(y);
  const HingeFit line{(B * coefficients - y).squaredNorm(), 1.0, coefficients(0), coefficients(1), false};
  HingeFit best = best_hinge(xi, y, line);
  // A knee must improve the fit by more than the noise, and by more than a load cell
  // resolves (0.1 % of the peak force): a noise-free (simulated) curve would otherwise
  // take the slight, gradual creep of its regularised friction for a knee.
  const double resolution = std::max(a.noise_N, 1e-3 * a.peak_force_N);
  if (best.knee && line.sse - best.sse < 25.0 * resolution * resolution) best = line;
  a.knee_found = best.knee;
  a.linear_end_m = xs + best.b * L;
  // Without a knee the line runs to the peak; the fitted line there can overshoot the
  // rounded top, so it is capped by the smoothed peak force.
  a.linear_end_force_N = best.knee ? best.a + best.k * best.b : std::min(best.a + best.k * best.b, a.peak_force_N);
  a.slope_N_per_m = best.k / L;
}

// Kinetic force [N]: mean over the last 75 % of the travel after the peak p; sets
// kinetic_from_m and kinetic_force_N of `a`.
void kinetic_force(const std::vector<double>& x, const std::vector<double>& F, size_t p, PullAnalysis& a) {
  a.kinetic_from_m = x[p] + 0.25 * (x.back() - x[p]);
  double sum = 0;
  int count = 0;
  for (size_t i = p; i < F.size(); ++i)
    if (x[i] >= a.kinetic_from_m) {
      sum += F[i];
      ++count;
    }
  a.kinetic_force_N = count > 0 ? sum / count : 0.0;
}

}  // namespace

PullAnalysis analyse_pull(const PullCurve& curve, double weight_N) {
  if (!(weight_N > 0.0)) throw std::invalid_argument("analyse_pull: weight must be > 0");
  const auto& x = curve.displacement;
  const auto& F = curve.force;
  const size_t n = F.size();
  if (n < 20 || x.size() != n) throw InputError(curve.file, "pull test: fewer than 20 points");
  PullAnalysis a;
  a.noise_N = force_noise(F);
  const std::vector<double> Fs = smooth(F);
  if (!(*std::max_element(Fs.begin(), Fs.end()) > 0.0))
    throw InputError(curve.file, "pull test: the force never rises above zero");
  const size_t p = raw_peak_index(F, smoothed_peak_index(Fs, a.noise_N), a.peak_force_N);
  a.peak_m = x[p];
  // Window: first point above 5 % of the peak .. p.
  size_t s = 0;
  while (s < p && Fs[s] < 0.05 * a.peak_force_N) ++s;
  if (p < s + 6) throw InputError(curve.file, "pull test: fewer than 6 points between the slack and the peak");
  a.linear_start_m = x[s];
  fit_linear_regime(x, F, s, p, a);
  kinetic_force(x, F, p, a);
  a.mu_linear = a.linear_end_force_N / weight_N;
  a.mu_peak = a.peak_force_N / weight_N;
  a.mu_kinetic = a.kinetic_force_N / weight_N;
  return a;
}

Summary summarize(std::vector<double> v) {
  Summary s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  auto quantile = [&](double q) {
    const double h = (v.size() - 1) * q;
    const size_t lo = static_cast<size_t>(std::floor(h));
    const size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (h - lo) * (v[hi] - v[lo]);
  };
  s.median = quantile(0.5);
  s.q1 = quantile(0.25);
  s.q3 = quantile(0.75);
  s.min = v.front();
  s.max = v.back();
  for (double x : v) s.mean += x / v.size();
  if (v.size() > 1) {
    for (double x : v) s.sd += (x - s.mean) * (x - s.mean);
    s.sd = std::sqrt(s.sd / (v.size() - 1));
  }
  return s;
}

PullCurve synthesize_pull(const SyntheticPull& p) {
  if (!(p.mu_peak >= p.mu_linear && p.mu_linear > 0 && p.mu_kinetic > 0 && p.stiffness_N_per_m > 0))
    throw std::invalid_argument("synthesize_pull: need mu_peak >= mu_linear > 0, mu_kinetic > 0, stiffness > 0");
  PullCurve c;
  c.label = "synthetic";
  const double W = p.weight_N, k = p.stiffness_N_per_m;
  const double F_L = p.mu_linear * W, F_P = p.mu_peak * W, F_K = p.mu_kinetic * W;
  const double x_L = p.slack_m + F_L / k;
  const double ell = std::max(1.5 * (F_P - F_L) / k, 1e-9);
  // Knee reaches F_P where 1 - exp(-dx/ell) = (F_P - F_L)/(k ell) = 2/3.
  const double x_P = F_P > F_L ? x_L + ell * std::log(3.0) : x_L;
  std::mt19937 rng(p.seed);
  std::normal_distribution<double> noise(0.0, p.noise_N);
  const double dt = 1.0 / p.rate_Hz;
  const int samples = static_cast<int>(std::floor(p.travel_m / p.speed_m_per_s / dt)) + 1;
  for (int i = 0; i < samples; ++i) {
    const double t = i * dt, x = p.speed_m_per_s * t;
    double f;
    if (x < p.slack_m) {
      f = 0.0;
    } else if (x < x_L) {
      f = k * (x - p.slack_m);
    } else if (x < x_P) {
      f = F_L + k * ell * (1.0 - std::exp(-(x - x_L) / ell));
    } else {
      const double after = x - x_P;
      // Sawtooth in [-1, 1), zero mean over a period.
      const double phase = std::fmod(after / p.stick_slip_period_m, 1.0);
      const double saw = 2.0 * phase - 1.0;
      f = F_K + (F_P - F_K) * std::exp(-after / p.drop_m) +
          p.stick_slip * F_K * saw * (1.0 - std::exp(-after / p.drop_m));
    }
    c.time.push_back(t);
    c.displacement.push_back(x);
    c.force.push_back(f + noise(rng));
  }
  return c;
}

std::string pull_export_text(const PullCurve& c, double weight_N, bool decimal_comma, const std::string& machine,
                             double speed_mm_per_min) {
  std::ostringstream o;
  auto num = [&](double v, int digits) {
    std::ostringstream s;
    s << std::setprecision(digits) << v;
    std::string t = s.str();
    if (decimal_comma) std::replace(t.begin(), t.end(), '.', ',');
    return t;
  };
  o << "Specimen label;" << c.label << ";;\n"
    << "Test type;Pull test (friction);;\n"
    << "Machine;" << machine << ";;\n"
    << "Surface;" << c.surface << ";;\n"
    << "Foot state;" << c.foot_state << ";;\n"
    << "Robot weight (N);" << num(weight_N, 8) << ";;\n"
    << "Speed (mm/min);" << num(speed_mm_per_min, 6) << ";;\n"
    << ";;;\n"
    << "Time;Extension;Load\n"
    << "(s);(mm);(N)\n";
  for (size_t i = 0; i < c.force.size(); ++i)
    o << num(c.time.empty() ? 0.0 : c.time[i], 8) << ';' << num(c.displacement[i] * 1e3, 8) << ';' << num(c.force[i], 8)
      << '\n';
  return o.str();
}

int write_synthetic_pulls(const SyntheticPullSet& set, std::ostream& out) {
  SyntheticPull p = set.model;
  const std::string &dir = set.out_dir, &surface = set.surface, &foot = set.foot;
  const int repeats = set.repeats;
  const bool comma = set.decimal_comma;
  if (dir.empty()) throw InputError("calibrate synth-pull", "--out DIR is required");
  if (p.mu_peak < p.mu_linear) throw InputError("calibrate synth-pull", "--mu-peak must be >= --mu-linear");
  std::filesystem::create_directories(dir);
  const unsigned seed0 = p.seed;
  for (int r = 1; r <= repeats; ++r) {
    p.seed = seed0 + static_cast<unsigned>(r);
    PullCurve c = synthesize_pull(p);
    c.surface = surface;
    c.foot_state = foot;
    std::ostringstream name;
    name << surface << "_" << foot << "_" << std::setw(2) << std::setfill('0') << r;
    c.label = name.str();
    const std::string path = (std::filesystem::path(dir) / (name.str() + ".csv")).string();
    write_file_atomic(path, pull_export_text(c, p.weight_N, comma));
    out << path << "\n";
  }
  return 0;
}

namespace {

struct PullRow {
  PullCurve curve;
  PullAnalysis analysis;
};

// Every specimen of the exports (files or folders) read and analysed.
std::vector<PullRow> analyse_exports(const std::vector<std::string>& inputs, double weight_N) {
  std::vector<PullRow> rows;
  for (const auto& s : read_test_machine_exports(inputs)) {
    PullCurve c = pull_curve_from_export(s);
    PullAnalysis a = analyse_pull(c, weight_N);
    rows.push_back({std::move(c), a});
  }
  return rows;
}

// The per-test table on `out`; returns the same rows as pull_tests.csv (lengths in mm,
// slope in N/mm).
std::string print_pull_rows(const std::vector<PullRow>& rows, std::ostream& out) {
  std::ostringstream csv;
  csv << std::setprecision(8)
      << "file,label,surface,foot_state,mu_linear,mu_peak,mu_kinetic,linear_end_mm,linear_end_force_N,slope_N_per_mm,"
         "peak_mm,peak_force_N,kinetic_force_N,noise_N,knee_found\n";
  out << std::left << std::setw(28) << "test" << std::setw(10) << "surface" << std::setw(12) << "foot" << std::right
      << std::setw(10) << "mu_lin" << std::setw(10) << "mu_peak" << std::setw(10) << "mu_kin" << std::setw(12)
      << "x_L [mm]" << std::setw(12) << "noise [N]\n";
  for (const auto& r : rows) {
    const auto& a = r.analysis;
    out << std::left << std::setw(28) << r.curve.label << std::setw(10) << r.curve.surface << std::setw(12)
        << r.curve.foot_state << std::right << std::fixed << std::setprecision(4) << std::setw(10) << a.mu_linear
        << std::setw(10) << a.mu_peak << std::setw(10) << a.mu_kinetic << std::setprecision(3) << std::setw(12)
        << a.linear_end_m * 1e3 << std::setprecision(5) << std::setw(11) << a.noise_N << "\n"
        << std::defaultfloat;
    csv << '"' << r.curve.file << "\",\"" << r.curve.label << "\"," << r.curve.surface << ',' << r.curve.foot_state
        << ',' << a.mu_linear << ',' << a.mu_peak << ',' << a.mu_kinetic << ',' << a.linear_end_m * 1e3 << ','
        << a.linear_end_force_N << ',' << a.slope_N_per_m * 1e-3 << ',' << a.peak_m * 1e3 << ',' << a.peak_force_N
        << ',' << a.kinetic_force_N << ',' << a.noise_N << ',' << (a.knee_found ? 1 : 0) << '\n';
  }
  return csv.str();
}

// Statistics of mu_linear, mu_peak and mu_kinetic per (surface, foot state): a table
// on `out`, and one JSON object per group.
std::vector<Json> summarise_pull_groups(const std::vector<PullRow>& rows, std::ostream& out) {
  std::map<std::pair<std::string, std::string>, std::vector<const PullRow*>> groups;
  for (const auto& r : rows) groups[{r.curve.surface, r.curve.foot_state}].push_back(&r);
  std::vector<Json> json_groups;
  out << "\n"
      << std::left << std::setw(22) << "group" << std::setw(12) << "coefficient" << std::right << std::setw(4) << "n"
      << std::setw(9) << "median" << std::setw(9) << "q1" << std::setw(9) << "q3" << std::setw(9) << "mean"
      << std::setw(9) << "sd"
      << "\n";
  for (const auto& [key, members] : groups) {
    Json g;
    g.add("surface", key.first).add("foot_state", key.second).add("tests", static_cast<int>(members.size()));
    for (const char* name : {"mu_linear", "mu_peak", "mu_kinetic"}) {
      std::vector<double> v;
      for (const PullRow* r : members)
        v.push_back(std::string(name) == "mu_linear" ? r->analysis.mu_linear
                    : std::string(name) == "mu_peak" ? r->analysis.mu_peak
                                                     : r->analysis.mu_kinetic);
      const Summary s = summarize(v);
      Json j;
      j.add("n", s.n).add("median", s.median).add("q1", s.q1).add("q3", s.q3).add("mean", s.mean).add("sd", s.sd);
      j.add("min", s.min).add("max", s.max);
      g.add(name, j);
      out << std::left << std::setw(22) << (key.first + "/" + key.second) << std::setw(12) << name << std::right
          << std::fixed << std::setw(4) << s.n << std::setprecision(4) << std::setw(9) << s.median << std::setw(9)
          << s.q1 << std::setw(9) << s.q3 << std::setw(9) << s.mean << std::setw(9) << s.sd << "\n"
          << std::defaultfloat;
    }
    json_groups.push_back(g);
  }
  return json_groups;
}

// pull_tests.csv, pull_summary.json and (with python3 and the script) a box plot in
// o.out_dir.
void write_pull_outputs(const PullTestsOptions& o, const std::string& csv, const std::vector<Json>& json_groups,
                        std::ostream& out) {
  const std::string& dir = o.out_dir;
  const std::string& plot_script = o.plot_script;
  std::filesystem::create_directories(dir);
  const std::string csv_path = (std::filesystem::path(dir) / "pull_tests.csv").string();
  write_file_atomic(csv_path, csv);
  Json root;
  root.add("command", "morphfem calibrate pull-tests" + o.command_arguments)
      .add("weight_N", o.weight_N)
      .add("groups", json_groups);
  write_file_atomic((std::filesystem::path(dir) / "pull_summary.json").string(), root.str(true) + "\n");
  if (!plot_script.empty() && std::filesystem::exists("/usr/bin/python3") && std::filesystem::exists(plot_script)) {
    const std::string png = (std::filesystem::path(dir) / "pull_boxplot.png").string();
    const std::string command = "/usr/bin/python3 '" + plot_script + "' pull '" + csv_path + "' '" + png + "' >&2";
    if (std::system(command.c_str()) == 0) out << "box plot: " << png << "\n";
  }
}

}  // namespace

int analyse_pull_tests(const PullTestsOptions& o, std::ostream& out) {
  if (o.weight_N <= 0) throw InputError("calibrate pull-tests", "--weight-N W (the robot's weight [N]) is required");
  if (o.inputs.empty()) throw InputError("calibrate pull-tests", "no export files or folders given");
  const std::vector<PullRow> rows = analyse_exports(o.inputs, o.weight_N);
  const std::string csv = print_pull_rows(rows, out);
  const std::vector<Json> json_groups = summarise_pull_groups(rows, out);
  if (!o.out_dir.empty()) write_pull_outputs(o, csv, json_groups, out);
  return 0;
}

}  // namespace morphfem
