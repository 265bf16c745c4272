// `morphfem calibrate ...` (see calibrate_cli.h and the usage text below).
#include "app/calibrate_cli.h"

#include <petscsys.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <random>
#include <set>
#include <sstream>

#include "app/drag_scene.h"
#include "app/plot.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/test_machine_export.h"
#include "fem/material_fit.h"
#include "optim/calibration_file.h"
#include "optim/pull_test.h"

namespace morphfem {

namespace {

const char* kCalibrateUsage =
    "usage: morphfem calibrate COMMAND ...\n"
    "  pull-tests --weight-N W FILES_OR_DIRS... [--out DIR]\n"
    "        static (study: end of the linear regime; ASTM D1894: peak) and kinetic friction\n"
    "        coefficients of test-machine pull tests, statistics per surface and foot state\n"
    "  synth-pull --out DIR [--surface S --foot F --mu-linear M --mu-peak M --mu-kinetic M ...]\n"
    "        synthetic Instron-like pull-test exports with known coefficients\n"
    "  drag --out FILE.csv [--mu-static M --mu-kinetic M --stiffness K --weight-N W --travel-mm D\n"
    "        --noise-N S --seed N --surface S --foot F]\n"
    "        simulated pull test (the friction fit's model) written as an export\n"
    "  friction --weight-N W FILES_OR_DIRS... [--surface S] [--foot F] [--travel-mm 8] [--out DIR]\n"
    "        fits mu_static, mu_kinetic and the pull-spring stiffness so the simulated drag\n"
    "        test reproduces the measured curves (PETSc TAO POUNDERS); values, residuals,\n"
    "        95 % confidence intervals, overlay plot, calibration file\n"
    "  materials [--data-dir DIR] [--max-strain 2.0] [--out DIR]\n"
    "        neo-Hookean, Yeoh and Ogden fits to tensile exports with R^2, RMS and plots\n"
    "  morphing [--scene FILE] [--inflate-s 11.5] [--deflate-s 4.7] [--diameter-m 0.07]\n"
    "        [--height-m 0.012] [--fraction 0.9] [--tolerance 0.02] [--max-runs 5] [--out DIR]\n"
    "        [--set KEY=VALUE]...\n"
    "        the core valve's supply and vacuum conductances so the morph scene (default\n"
    "        examples/physical/morph_valve_vacuum_slice.yaml) turns flat -> cylinder and back in\n"
    "        the measured times; inflated diameter and flat height against the measured ones;\n"
    "        calibration file\n";

std::string plot_script() { return std::string(MORPHFEM_SOURCE_DIR) + "/scripts/plot_calibration.py"; }

bool run_plot(const std::vector<std::string>& args) {
  return run_plot_script("plot_calibration.py", args, "the calibration");
}

int rank_of(MPI_Comm comm) {
  int rank;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

// `calibrate drag`: one simulated pull test written as an export (with noise if asked).
int drag_main(const std::vector<std::string>& args, MPI_Comm comm) {
  DragParameters p;
  std::string out_file, surface = "simulated", foot = "unknown";
  double noise = 0.0;
  unsigned seed = 1;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (i + 1 >= args.size()) throw InputError("calibrate drag", "option " + a + " needs a value");
    const std::string& v = args[++i];
    if (a == "--out")
      out_file = v;
    else if (a == "--mu-static")
      p.mu_static = number_option("drag", a, v, 1e-3, 10);
    else if (a == "--mu-kinetic")
      p.mu_kinetic = number_option("drag", a, v, 1e-3, 10);
    else if (a == "--stiffness")
      p.stiffness = number_option("drag", a, v, 1, 1e7);
    else if (a == "--weight-N")
      p.weight_N = number_option("drag", a, v, 1e-3, 1e4);
    else if (a == "--travel-mm")
      p.travel = 1e-3 * number_option("drag", a, v, 0.1, 1000);
    else if (a == "--dt")
      p.dt = number_option("drag", a, v, 1e-5, 1);
    else if (a == "--eps-v")
      p.eps_v = number_option("drag", a, v, 1e-9, 1);
    else if (a == "--noise-N")
      noise = number_option("drag", a, v, 0, 1e3);
    else if (a == "--seed")
      seed = static_cast<unsigned>(number_option("drag", a, v, 0, 1e9));
    else if (a == "--surface")
      surface = v;
    else if (a == "--foot")
      foot = v;
    else
      throw InputError("calibrate drag", "unknown option '" + a + "'");
  }
  if (out_file.empty()) throw InputError("calibrate drag", "--out FILE.csv is required");
  const DragCurve c = run_drag_test(p, comm);
  if (!c.completed) throw SolveError("calibrate drag: the simulated pull test did not complete");
  PullCurve curve;
  curve.label = std::filesystem::path(out_file).stem().string();
  curve.surface = surface;
  curve.foot_state = foot;
  curve.time = c.time;
  curve.displacement = c.displacement;
  curve.force = c.force;
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  if (noise > 0)
    for (double& f : curve.force) f += noise * n01(rng);
  if (rank_of(comm) == 0) {
    write_file_atomic(out_file, pull_export_text(curve, p.weight_N, false));
    std::cout << out_file << ": " << c.force.size() << " samples, " << std::setprecision(3) << c.wall_s << " s\n";
  }
  return 0;
}

int materials_main(const std::vector<std::string>& args) {
  std::vector<std::string> pass;
  std::string dir;
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--out") {
      if (i + 1 >= args.size()) throw InputError("calibrate materials", "--out needs a directory");
      dir = args[++i];
    } else {
      pass.push_back(args[i]);
    }
  }
  const std::string default_dir = std::string(MORPHFEM_SOURCE_DIR) + "/../shared/data/materials";
  if (dir.empty()) return fit_materials_main(pass, default_dir, std::cout);
  std::filesystem::create_directories(dir);
  const std::string curves = (std::filesystem::path(dir) / "material_fit_curves.csv").string();
  std::vector<std::string> with_json = pass;
  with_json.insert(with_json.end(), {"--json", "--curves", curves});
  std::ostringstream json;
  fit_materials_main(with_json, default_dir, json);
  write_file_atomic((std::filesystem::path(dir) / "material_fit.json").string(), json.str());
  fit_materials_main(pass, default_dir, std::cout);
  const std::string png = (std::filesystem::path(dir) / "material_fit.png").string();
  if (run_plot({"materials", curves, png})) std::cout << "plot: " << png << "\n";
  // The calibration file scenes load: {calibration: materials.yaml, parameter: dragonskin10.yeoh.c1}.
  std::string data_dir = default_dir;
  double max_strain = 2.0;
  for (size_t i = 0; i + 1 < pass.size(); ++i) {
    if (pass[i] == "--data-dir") data_dir = pass[i + 1];
    if (pass[i] == "--max-strain") max_strain = number_option("materials", "--max-strain", pass[i + 1], 0.05, 20);
  }
  Calibration cal;
  cal.kind = "materials";
  cal.command = "morphfem calibrate materials";
  for (const auto& a : args) cal.command += " " + a;
  cal.created = now_utc();
  cal.group = {{"data_dir", data_dir}, {"max_strain", json_number(max_strain)}};
  std::set<std::string> seen, files;
  for (const MaterialFits& m : fit_material_directory(data_dir, max_strain)) {
    std::string slug;  // "DragonSkin10" -> "dragonskin10"
    for (char ch : m.test.material)
      if (std::isalnum(static_cast<unsigned char>(ch))) slug += static_cast<char>(std::tolower(ch));
    for (int k = 2; seen.count(slug); ++k) slug += "_" + std::to_string(k);
    seen.insert(slug);
    for (const FitResult& f : m.fits) {
      if (f.std_errors.empty()) continue;  // the linear fits (neo-Hookean, Yeoh) carry standard errors
      for (size_t j = 0; j < f.names.size(); ++j) {
        const double v = f.values[j], se = f.std_errors[j];
        cal.parameters.emplace_back(slug + "." + f.model + "." + f.names[j],
                                    CalibratedValue{v, se, v - 1.96 * se, v + 1.96 * se, "Pa"});
      }
      cal.fit[slug + "." + f.model + ".r2"] = json_number(f.r2);
      cal.fit[slug + "." + f.model + ".rms_Pa"] = json_number(f.rms);
    }
    if (files.insert(m.test.file).second) cal.data.push_back({m.test.file, sha256_file(m.test.file), m.test.material});
  }
  cal.fit["method"] = "linear least squares on the uniaxial nominal stress (fem/material_fit.h)";
  const std::string yaml = (std::filesystem::path(dir) / "materials.yaml").string();
  write_calibration_file(yaml, cal);
  std::cout << "calibration: " << yaml << "\n";
  return 0;
}

// `calibrate friction`: one group (surface, foot state) of pull tests -> fitted model.
int friction_main(const std::vector<std::string>& args, MPI_Comm comm) {
  double weight = 0;
  std::string surface, foot, dir;
  std::vector<std::string> inputs;
  FrictionFitOptions options;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (!a.empty() && a[0] == '-') {
      if (i + 1 >= args.size()) throw InputError("calibrate friction", "option " + a + " needs a value");
      const std::string& v = args[++i];
      if (a == "--weight-N")
        weight = number_option("friction", a, v, 1e-3, 1e4);
      else if (a == "--surface")
        surface = v;
      else if (a == "--foot")
        foot = v;
      else if (a == "--out")
        dir = v;
      else if (a == "--travel-mm")
        options.travel = 1e-3 * number_option("friction", a, v, 0.5, 1000);
      else if (a == "--dt")
        options.model.dt = number_option("friction", a, v, 1e-4, 0.5);
      else if (a == "--start") {
        options.start.clear();
        std::stringstream list(v);
        for (std::string item; std::getline(list, item, ',');)
          options.start.push_back(number_option("friction", a, item, 1e-6, 1e7));
        if (options.start.size() != 3)
          throw InputError("calibrate friction", "--start takes mu_static,mu_kinetic,stiffness");
      } else if (a == "--max-evals")
        options.max_evaluations = static_cast<int>(number_option("friction", a, v, 5, 1e4));
      else
        throw InputError("calibrate friction", "unknown option '" + a + "'");
    } else {
      inputs.push_back(a);
    }
  }
  if (weight <= 0) throw InputError("calibrate friction", "--weight-N W (the robot's weight [N]) is required");
  if (inputs.empty()) throw InputError("calibrate friction", "no export files or folders given");
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
  const FrictionFitResult r = fit_friction(curves, weight, options, comm);
  const LeastSquaresFit& f = r.fit;
  const bool root = rank_of(comm) == 0;
  if (root) {
    std::cout << "friction fit: " << *groups.begin() << ", " << curves.size()
              << " curve(s), travel <= " << options.travel * 1e3 << " mm, " << f.residuals.size() << " residuals, "
              << f.evaluations << " simulations, TAO POUNDERS " << f.reason << "\n";
    for (size_t j = 0; j < f.names.size(); ++j)
      std::cout << "  " << std::left << std::setw(18) << f.names[j] << std::right << std::setprecision(6)
                << std::setw(12) << f.values[j] << "  +/- " << std::setw(10) << f.std_error[j] << "  95% CI ["
                << f.ci_low[j] << ", " << f.ci_high[j] << "]  (start " << r.start[j] << ")\n";
    std::cout << "  residual RMS " << f.rms << " N\n";
  }
  if (!dir.empty() && root) {
    std::filesystem::create_directories(dir);
    Calibration cal;
    cal.kind = "friction";
    cal.command = "morphfem calibrate friction";
    for (const auto& a : args) cal.command += " " + a;
    cal.created = now_utc();
    cal.group = {{"surface", curves.front().surface}, {"foot_state", curves.front().foot_state}};
    const std::vector<std::string> units = {"-", "-", "N/m"};
    for (size_t j = 0; j < f.names.size(); ++j)
      cal.parameters.emplace_back(f.names[j],
                                  CalibratedValue{f.values[j], f.std_error[j], f.ci_low[j], f.ci_high[j], units[j]});
    cal.fit = {{"method", "PETSc TAO POUNDERS on the simulated drag test (app/drag_scene.h)"},
               {"residual_rms_N", json_number(f.rms)},
               {"residuals", std::to_string(f.residuals.size())},
               {"evaluations", std::to_string(f.evaluations)},
               {"converged", f.converged ? "true" : "false"},
               {"reason", f.reason},
               {"travel_m", json_number(options.travel)},
               {"weight_N", json_number(weight)}};
    for (const auto& c : curves) cal.data.push_back({c.file, sha256_file(c.file), c.label});
    const std::string yaml =
        (std::filesystem::path(dir) / ("friction_" + cal.group["surface"] + "_" + cal.group["foot_state"] + ".yaml"))
            .string();
    write_calibration_file(yaml, cal);
    std::cout << "calibration: " << yaml << "\n";
    // Overlay table: every data sample within the travel and the simulated curve.
    std::ostringstream csv;
    csv << std::setprecision(8) << "curve,displacement_mm,force_N\n";
    for (const auto& c : curves)
      for (size_t i = 0; i < c.displacement.size(); ++i)
        if (c.displacement[i] <= options.travel)
          csv << '"' << c.label << "\"," << c.displacement[i] * 1e3 << ',' << c.force[i] << '\n';
    for (size_t i = 0; i < r.best.displacement.size(); ++i)
      csv << "simulated," << r.best.displacement[i] * 1e3 << ',' << r.best.force[i] << '\n';
    const std::string overlay = (std::filesystem::path(dir) / "friction_overlay.csv").string();
    write_file_atomic(overlay, csv.str());
    const std::string png = (std::filesystem::path(dir) / "friction_overlay.png").string();
    if (run_plot({"friction", overlay, png})) std::cout << "plot: " << png << "\n";
  }
  return 0;
}

}  // namespace

double number_option(const std::string& command, const std::string& option, const std::string& text, double lo,
                     double hi) {
  double v;
  if (!parse_export_number(text, false, v) || v < lo || v > hi)
    throw InputError("calibrate " + command,
                     option + " '" + text + "' must be a number in [" + json_number(lo) + ", " + json_number(hi) + "]");
  return v;
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

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

int calibrate_main(const std::vector<std::string>& args, MPI_Comm comm) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    if (rank_of(comm) == 0) std::cout << kCalibrateUsage;
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (command == "pull-tests") return pull_tests_main(rest, plot_script(), std::cout);
  if (command == "synth-pull") return synth_pull_main(rest, std::cout);
  if (command == "drag") return drag_main(rest, comm);
  if (command == "materials") return materials_main(rest);
  if (command == "friction") return friction_main(rest, comm);
  if (command == "morphing") return calibrate_morphing_main(rest, comm);
  throw InputError("morphfem calibrate", "unknown command '" + command + "'\n" + kCalibrateUsage);
}

}  // namespace morphfem
