#include "optim/friction_calibration.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <random>
#include <set>
#include <sstream>

#include "core/calibration_file.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/plot.h"
#include "core/test_machine_export.h"
#include "optim/pull_test.h"

namespace morphfem {

FrictionFitResult fit_friction(const std::vector<PullCurve>& curves, double weight_N, const FrictionFitOptions& options,
                               MPI_Comm comm) {
  if (curves.empty()) throw InputError("friction fit", "no curves");
  FrictionFitResult result;
  DragParameters model = options.model;
  model.weight_N = weight_N;
  model.travel = options.travel;
  if (options.start.size() == 3) {
    result.start = options.start;
  } else {
    std::vector<double> peak, kinetic, slope;
    for (const auto& c : curves) {
      const PullAnalysis a = analyse_pull(c, weight_N);
      peak.push_back(a.mu_peak);
      kinetic.push_back(std::min(a.mu_kinetic, a.mu_peak));
      slope.push_back(a.slope_N_per_m);
    }
    result.start = {summarize(peak).median, summarize(kinetic).median, summarize(slope).median};
  }
  LeastSquaresProblem pb;
  pb.names = {"mu_static", "mu_kinetic", "stiffness_N_per_m"};
  pb.start = result.start;
  pb.scale = result.start;
  pb.lower = {0.2 * result.start[0], 0.2 * result.start[1], 0.2 * result.start[2]};
  pb.upper = {5.0 * result.start[0], 5.0 * result.start[1], 5.0 * result.start[2]};
  std::vector<double> data_peaks;   // static peak force of each curve [N]
  std::vector<PullTarget> targets;  // pointwise to just past each curve's static peak, then 2 mm blocks
  for (const auto& c : curves) {
    const PullAnalysis a = analyse_pull(c, weight_N);
    targets.push_back(
        make_pull_target(c, options.travel, a.peak_m + options.split_after_peak, options.block, a.noise_N));
    pb.n_residuals += targets.back().size() + 1;
    data_peaks.push_back(a.peak_force_N);
  }
  pb.residuals = [&](const std::vector<double>& p, std::vector<double>& r) {
    DragParameters q = model;
    q.mu_static = p[0];
    q.mu_kinetic = std::min(p[1], p[0]);  // the friction law needs mu_k <= mu_s
    q.stiffness = p[2];
    const DragCurve sim = run_drag_test(q, comm);
    if (!sim.completed) return false;
    r.clear();
    for (const auto& t : targets) append_target_residuals(sim.displacement, sim.force, t, r);
    // The static peak of each curve as one more residual: in the stick-slip regime a
    // larger mu_static with a smaller mu_kinetic gives the same mean sliding force, and
    // the few samples at the peak alone leave that valley shallow.
    PullCurve simulated;
    simulated.displacement = sim.displacement;
    simulated.force = sim.force;
    const double sim_peak = analyse_pull(simulated, weight_N).peak_force_N;
    for (double peak : data_peaks) r.push_back(sim_peak - peak);
    return true;
  };
  // The simulated static peak is quantised by the time step: the force grows by
  // k v_model dt per step, so mu_static is resolved to dmu = k v_model dt / W (uniform
  // error, standard uncertainty dmu / sqrt(12)); mu_kinetic (a plateau) and k (a slope)
  // are not quantised.
  const double dmu = result.start[2] * model.speed * model.model_speed_factor * model.dt / weight_N;
  pb.model_resolution = {dmu / std::sqrt(12.0), 0.0, 0.0};
  result.fit = fit_least_squares(pb, options.max_evaluations);
  DragParameters best = model;
  best.mu_static = result.fit.values[0];
  best.mu_kinetic = std::min(result.fit.values[1], result.fit.values[0]);
  best.stiffness = result.fit.values[2];
  result.best = run_drag_test(best, comm);
  return result;
}

int write_simulated_pull(const SimulatedPullOptions& o, MPI_Comm comm) {
  const DragParameters& p = o.model;
  const std::string& out_file = o.out_file;
  if (out_file.empty()) throw InputError("calibrate drag", "--out FILE.csv is required");
  const DragCurve c = run_drag_test(p, comm);
  if (!c.completed) throw SolveError("calibrate drag: the simulated pull test did not complete");
  PullCurve curve;
  curve.label = std::filesystem::path(out_file).stem().string();
  curve.surface = o.surface;
  curve.foot_state = o.foot;
  curve.time = c.time;
  curve.displacement = c.displacement;
  curve.force = c.force;
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  if (o.noise_N > 0)
    for (double& f : curve.force) f += o.noise_N * n01(rng);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) {
    write_file_atomic(out_file, pull_export_text(curve, p.weight_N, false));
    std::cout << out_file << ": " << c.force.size() << " samples, " << std::setprecision(3) << c.wall_s << " s\n";
  }
  return 0;
}

namespace {

// The pull tests of the exports in one (surface, foot state) group: those matching
// `surface` and `foot` (empty: any); InputError if none match or several groups remain.
// `group` is "surface/foot_state".
std::vector<PullCurve> read_pull_group(const std::vector<std::string>& inputs, const std::string& surface,
                                       const std::string& foot, std::string& group) {
  std::vector<PullCurve> curves;
  std::set<std::string> groups;
  for (const auto& s : read_test_machine_exports(inputs)) {
    PullCurve c = pull_curve_from_export(s);
    if ((!surface.empty() && c.surface != surface) || (!foot.empty() && c.foot_state != foot)) continue;
    groups.insert(c.surface + "/" + c.foot_state);
    curves.push_back(std::move(c));
  }
  if (curves.empty()) throw InputError("calibrate friction", "no pull test matches --surface/--foot");
  if (groups.size() > 1) {
    std::string list;
    for (const auto& g : groups) list += " " + g;
    throw InputError("calibrate friction", "the curves belong to several groups (" + list +
                                               " ): fit one at a time with --surface and --foot");
  }
  group = *groups.begin();
  return curves;
}

// The fitted coefficients with standard errors, 95 % intervals and starts.
void print_friction_fit(const std::string& group, const std::vector<PullCurve>& curves, double travel_m,
                        const FrictionFitResult& r) {
  const LeastSquaresFit& f = r.fit;
  std::cout << "friction fit: " << group << ", " << curves.size() << " curve(s), travel <= " << travel_m * 1e3
            << " mm, " << f.residuals.size() << " residuals, " << f.evaluations << " simulations, TAO POUNDERS "
            << f.reason << "\n";
  for (size_t j = 0; j < f.names.size(); ++j)
    std::cout << "  " << std::left << std::setw(18) << f.names[j] << std::right << std::setprecision(6) << std::setw(12)
              << f.values[j] << "  +/- " << std::setw(10) << f.std_error[j] << "  95% CI [" << f.ci_low[j] << ", "
              << f.ci_high[j] << "]  (start " << r.start[j] << ")\n";
  std::cout << "  residual RMS " << f.rms << " N\n";
}

// friction_SURFACE_FOOT.yaml, the calibration file scenes load.
void write_friction_calibration(const FrictionCalibrationOptions& o, const std::vector<PullCurve>& curves,
                                const FrictionFitResult& r) {
  const LeastSquaresFit& f = r.fit;
  Calibration cal;
  cal.kind = "friction";
  cal.command = "morphfem calibrate friction";
  cal.command += o.command_arguments;
  cal.created = now_utc();
  cal.group = {{"surface", curves.front().surface}, {"foot_state", curves.front().foot_state}};
  const std::vector<std::string> units = {"-", "-", "N/m"};
  for (size_t j = 0; j < f.names.size(); ++j)
    cal.parameters.emplace_back(f.names[j],
                                CalibratedValue{f.values[j], f.std_error[j], f.ci_low[j], f.ci_high[j], units[j]});
  cal.fit = {{"method", "PETSc TAO POUNDERS on the simulated drag test (sim/drag_scene.h)"},
             {"residual_rms_N", json_number(f.rms)},
             {"residuals", std::to_string(f.residuals.size())},
             {"evaluations", std::to_string(f.evaluations)},
             {"converged", f.converged ? "true" : "false"},
             {"reason", f.reason},
             {"travel_m", json_number(o.fit.travel)},
             {"weight_N", json_number(o.weight_N)}};
  for (const auto& c : curves) cal.data.push_back({c.file, sha256_file(c.file), c.label});
  const std::string yaml = (std::filesystem::path(o.out_dir) /
                            ("friction_" + cal.group["surface"] + "_" + cal.group["foot_state"] + ".yaml"))
                               .string();
  write_calibration_file(yaml, cal);
  std::cout << "calibration: " << yaml << "\n";
}

// Overlay table friction_overlay.csv (every data sample within the travel [mm, N] and
// the simulated curve) and its plot.
void write_friction_overlay(const std::string& dir, const std::vector<PullCurve>& curves, double travel_m,
                            const FrictionFitResult& r) {
  std::ostringstream csv;
  csv << std::setprecision(8) << "curve,displacement_mm,force_N\n";
  for (const auto& c : curves)
    for (size_t i = 0; i < c.displacement.size(); ++i)
      if (c.displacement[i] <= travel_m)
        csv << '"' << c.label << "\"," << c.displacement[i] * 1e3 << ',' << c.force[i] << '\n';
  for (size_t i = 0; i < r.best.displacement.size(); ++i)
    csv << "simulated," << r.best.displacement[i] * 1e3 << ',' << r.best.force[i] << '\n';
  const std::string overlay = (std::filesystem::path(dir) / "friction_overlay.csv").string();
  write_file_atomic(overlay, csv.str());
  const std::string png = (std::filesystem::path(dir) / "friction_overlay.png").string();
  if (run_plot_script("plot_calibration.py", {"friction", overlay, png}, "the calibration"))
    std::cout << "plot: " << png << "\n";
}

}  // namespace

int calibrate_friction(const FrictionCalibrationOptions& o, MPI_Comm comm) {
  if (o.weight_N <= 0) throw InputError("calibrate friction", "--weight-N W (the robot's weight [N]) is required");
  if (o.inputs.empty()) throw InputError("calibrate friction", "no export files or folders given");
  std::string group;
  const std::vector<PullCurve> curves = read_pull_group(o.inputs, o.surface, o.foot, group);
  const FrictionFitResult r = fit_friction(curves, o.weight_N, o.fit, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return 0;
  print_friction_fit(group, curves, o.fit.travel, r);
  if (!o.out_dir.empty()) {
    std::filesystem::create_directories(o.out_dir);
    write_friction_calibration(o, curves, r);
    write_friction_overlay(o.out_dir, curves, o.fit.travel, r);
  }
  return 0;
}

}  // namespace morphfem
