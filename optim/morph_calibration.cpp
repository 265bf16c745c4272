// `morphfem calibrate morphing`: the core valve's supply and vacuum conductances
// from the measured morphing times (ROBOT.md: flat -> cylinder in 11.5 s at the
// 50 kPa line, cylinder -> flat in 4.7 s at -80 kPa vacuum, both averages of 20
// cycles), with the inflated diameter (~7 cm) and the flat height (~1.2 cm) as the
// model's predictions beside their measured values. Measures and the conductance
// update: optim/morph_fit.h.
//
// The scene (default examples/physical/morph_valve_vacuum_slice.yaml) has one gas cavity,
// the core, whose supply pressure turns positive (the line) and later negative (the
// vacuum pump). Each run sets the cavity's `conductance` and `vacuum_conductance`,
// runs the scene, samples the mid-length cross-section after every step and
// updates both conductances, until both times are within the tolerance.
#include "optim/morph_calibration.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/calibration_file.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "core/plot.h"
#include "optim/morph_fit.h"
#include "robot/robot_study.h"
#include "sim/cross_section.h"
#include "sim/scene.h"
#include "sim/simulation.h"

namespace morphfem {

namespace {

struct Run {
  double C_supply = 0, C_vacuum = 0;
  MorphMeasures m;
  double wall_s = 0;
  bool completed = false;
  std::string csv;  // morph.csv of the run (robot morph's layout)
};

double relative_error(double model, double target) { return model / target - 1; }

}  // namespace

namespace {

// The scene, its core cavity and the phases of its supply table.
struct MorphSetup {
  Scene scene;
  MorphPhases phases;
  bool vacuum = false;  // the supply turns to vacuum (a deflation phase)
  Run start;            // the scene's own conductances
  GasCavitySpec& core() { return scene.gas_cavities.front(); }
};

MorphSetup morph_setup(const MorphingOptions& o) {
  MorphSetup m;
  YAML::Node doc = load_scene_yaml(o.scene);
  for (const std::string& assignment : o.sets) set_scene_key(doc, assignment, o.scene);
  m.scene = scene_from_yaml(doc, o.scene);
  if (m.scene.gas_cavities.size() != 1)
    throw InputError(o.scene, "calibrate morphing needs exactly one gas cavity, the core (loads.gas_cavities)");
  const GasCavitySpec& core = m.core();
  try {
    m.phases = morph_phases(core.supply_gauge_pressure.points(), m.scene.solver.t_end);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.scene, std::string("loads.gas_cavities.supply_pressure: ") + e.what());
  }
  m.vacuum = !std::isnan(m.phases.deflate);
  m.start.C_supply = core.conductance(m.phases.inflate);
  m.start.C_vacuum = m.vacuum ? core.conductance_at(m.phases.end) : 0.0;
  if (!(m.start.C_supply > 0 && (!m.vacuum || m.start.C_vacuum > 0)))
    throw InputError(o.scene,
                     "loads.gas_cavities.conductance (and vacuum_conductance): the starting values must be > 0");
  return m;
}

// Runs the scene with the run's conductances, sampling the mid-length cross-section
// after every step (its CSV in robot morph's layout).
void run_morph(MorphSetup& m, Run& run, const std::string& output_dir, double fraction, MPI_Comm comm,
               SimulationResult& r) {
  GasCavitySpec& core = m.core();
  core.conductance = TimeFunction::constant(run.C_supply);
  core.vacuum_conductance = TimeFunction::constant(run.C_vacuum);
  core.has_vacuum_conductance = m.vacuum;
  m.scene.output_dir = output_dir;
  std::vector<ShapeSample> samples;
  run.csv = "time_s,core_pressure_pa,width_m,length_m,thickness_m,width_over_thickness\n";
  RunOptions options;
  options.on_step = [&](double t, const Mesh& mesh, const RowMatrixXd& u, const SimulationResult& sr) {
    const Eigen::Vector3d e = cross_section_extents(mesh, u);
    samples.push_back({t, e.x(), e.z()});
    char line[200];
    std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", t, sr.cavity_pressure.at(0), e.x(), e.y(),
                  e.z(), e.x() / e.z());
    run.csv += line;
  };
  r = run_scene(m.scene, comm, options);
  run.wall_s = r.stats.wall_s;
  run.completed = r.stats.completed;
  if (run.completed) run.m = measure_morphing(samples, m.phases, fraction);
}

void print_runs(const std::vector<Run>& runs, bool vacuum) {
  std::fputs(
      "  run  C_supply [mol/(s Pa)]  C_vacuum [mol/(s Pa)]  inflate [s]  deflate [s]  diameter [cm]  flat height "
      "[cm]  settled  wall [s]\n",
      stdout);
  for (size_t j = 0; j < runs.size(); ++j) {
    const Run& x = runs[j];
    const std::string deflate_settled = !vacuum ? "-" : x.m.deflate_settled ? "yes" : "no";
    std::printf("  %3zu  %21.4e  %21.4e  %11.3f  %11.3f  %13.2f  %16.2f  %3s/%-3s  %8.1f\n", j + 1, x.C_supply,
                x.C_vacuum, x.m.inflate_time, x.m.deflate_time, 100 * x.m.inflated_diameter, 100 * x.m.flat_height,
                x.m.inflate_settled ? "yes" : "no", deflate_settled.c_str(), x.wall_s);
  }
  std::fflush(stdout);
}

// Runs until both times are within the tolerance (or max_runs): each run's
// conductances come from the secant update of the previous ones. Returns whether
// the times converged; `runs` holds every run.
bool fit_conductances(MorphSetup& m, const MorphingOptions& o, MPI_Comm comm, int rank, std::vector<Run>& runs) {
  std::vector<std::pair<double, double>> supply_history, vacuum_history;  // (C, t)
  Run next = m.start;
  for (int k = 0; k < o.max_runs; ++k) {
    Run run = next;
    SimulationResult r;
    run_morph(m, run, o.out + "/run_" + std::to_string(k + 1), o.fraction, comm, r);
    runs.push_back(run);
    if (!run.completed) {
      if (rank == 0) std::printf("run %d failed: %s\n", k + 1, r.stats.failure.c_str());
      return false;
    }
    if (!r.output_dir.empty() && rank == 0) write_file_atomic(r.output_dir + "/morph.csv", run.csv);
    if (rank == 0) print_runs(runs, m.vacuum);
    const auto positive = [](double t) { return std::isfinite(t) && t > 0; };
    if (!positive(run.m.inflate_time) || (m.vacuum && !positive(run.m.deflate_time))) {
      if (rank == 0) std::printf("the run did not change shape in every phase: no update possible\n");
      return false;
    }
    if (std::abs(relative_error(run.m.inflate_time, o.inflate_s)) <= o.tolerance &&
        (!m.vacuum || std::abs(relative_error(run.m.deflate_time, o.deflate_s)) <= o.tolerance))
      return true;
    supply_history.emplace_back(run.C_supply, run.m.inflate_time);
    next.C_supply = next_conductance(supply_history, o.inflate_s);
    if (m.vacuum) {
      vacuum_history.emplace_back(run.C_vacuum, run.m.deflate_time);
      next.C_vacuum = next_conductance(vacuum_history, o.deflate_s);
    }
  }
  return false;
}

// The measured quantities beside the model's: the two fitted times and the two
// predicted sizes.
void print_comparison(const MorphingOptions& o, const MorphMeasures& m, bool vacuum, bool converged, size_t n_runs) {
  struct Row {
    const char* name;
    double target, model;
    const char* unit;
    double scale;
    const char* role;
  };
  const Row rows[] = {{"flat -> cylinder time", o.inflate_s, m.inflate_time, "s", 1, "fitted (supply conductance)"},
                      {"cylinder -> flat time", o.deflate_s, m.deflate_time, "s", 1, "fitted (vacuum conductance)"},
                      {"inflated diameter", o.diameter_m, m.inflated_diameter, "cm", 100, "predicted"},
                      {"flat height", o.height_m, m.flat_height, "cm", 100, "predicted"}};
  std::printf("\n  %-22s  %9s  %9s  %8s  %s\n", "quantity", "measured", "model", "error", "");
  bool within_10 = true;
  for (const Row& row : rows) {
    const double e = relative_error(row.model, row.target);
    if (std::isnan(row.model)) {
      within_10 = false;
      std::printf("  %-22s  %7.3g %-2s  not simulated (the scene has no vacuum phase)\n", row.name,
                  row.scale * row.target, row.unit);
      continue;
    }
    within_10 = within_10 && std::abs(e) <= 0.10;
    std::printf("  %-22s  %7.3g %-2s %7.3g %-2s  %+7.1f %%  %s\n", row.name, row.scale * row.target, row.unit,
                row.scale * row.model, row.unit, 100 * e, row.role);
  }
  std::printf("  inflated width %.2f cm, height %.2f cm; height before inflating %.2f cm\n", 100 * m.inflated_width,
              100 * m.inflated_height, 100 * m.start_height);
  if (!m.inflate_settled || (vacuum && !m.deflate_settled))
    std::printf("  warning: a phase had not settled at its end (lengthen it in the scene's supply table)\n");
  std::printf("  times %s after %zu runs; all four within 10 %%: %s\n", converged ? "converged" : "NOT converged",
              n_runs, within_10 ? "yes" : "no");
}

// The calibration file scenes load, the runs' table, the last run's shape and its plot.
void write_morph_calibration(const MorphingOptions& o, MorphSetup& setup, const std::vector<Run>& runs,
                             bool converged) {
  const Run& best = runs.back();
  const MorphMeasures& m = best.m;
  std::filesystem::create_directories(o.out);
  Calibration cal;
  cal.kind = "morphing";
  cal.command = "morphfem calibrate morphing";
  cal.command += o.command_arguments;
  cal.created = now_utc();
  // The scene as a path relative to the repository when it is in it (files that travel).
  const std::string source = resource_dir() + "/";
  const std::string scene_name = o.scene.rfind(source, 0) == 0 ? o.scene.substr(source.size()) : o.scene;
  cal.group = {{"scene", scene_name}, {"cavity", setup.core().wall.name}};
  // The published times are means of 20 cycles without a spread: no standard error.
  cal.parameters.emplace_back("conductance_supply",
                              CalibratedValue{best.C_supply, 0.0, best.C_supply, best.C_supply, "mol/(s Pa)"});
  if (setup.vacuum)
    cal.parameters.emplace_back("conductance_vacuum",
                                CalibratedValue{best.C_vacuum, 0.0, best.C_vacuum, best.C_vacuum, "mol/(s Pa)"});
  cal.fit = {{"method", "log-log secant on the valve conductances (optim/morph_fit.h)"},
             {"runs", std::to_string(runs.size())},
             {"converged", converged ? "true" : "false"},
             {"uncertainty", "none stated: the published times are 20-cycle means without a spread"},
             {"fraction_of_height_change", json_number(o.fraction)},
             {"inflate_time_s", json_number(m.inflate_time)},
             {"inflate_target_s", json_number(o.inflate_s)},
             {"deflate_time_s", json_number(m.deflate_time)},
             {"deflate_target_s", json_number(o.deflate_s)},
             {"inflated_diameter_m", json_number(m.inflated_diameter)},
             {"diameter_target_m", json_number(o.diameter_m)},
             {"flat_height_m", json_number(m.flat_height)},
             {"height_target_m", json_number(o.height_m)},
             {"targets", "ROBOT.md (Measured data: morphing)"}};
  const std::string yaml = o.out + "/morphing.yaml";
  write_calibration_file(yaml, cal);
  std::string table = "run,conductance_supply,conductance_vacuum,inflate_s,deflate_s,diameter_m,flat_height_m,wall_s\n";
  for (size_t j = 0; j < runs.size(); ++j) {
    const Run& x = runs[j];
    table += std::to_string(j + 1) + "," + json_number(x.C_supply) + "," + json_number(x.C_vacuum) + "," +
             json_number(x.m.inflate_time) + "," + json_number(x.m.deflate_time) + "," +
             json_number(x.m.inflated_diameter) + "," + json_number(x.m.flat_height) + "," + json_number(x.wall_s) +
             "\n";
  }
  write_file_atomic(o.out + "/morphing_runs.csv", table);
  write_file_atomic(o.out + "/morph.csv", best.csv);
  run_plot_script("plot_morph.py", {o.out + "/morph.csv"}, "the morphing fit");
  std::printf("calibration: %s\nruns: %s/morphing_runs.csv; last run: %s/morph.csv, %s/morph.png\n", yaml.c_str(),
              o.out.c_str(), o.out.c_str(), o.out.c_str());
}

}  // namespace

int calibrate_morphing(const MorphingOptions& options, MPI_Comm comm) {
  MorphingOptions o = options;
  if (o.scene.empty()) o.scene = resource_dir() + "/examples/physical/morph_valve_vacuum_slice.yaml";
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  MorphSetup setup = morph_setup(o);
  if (rank == 0)
    std::printf(
        "morphing fit: %s\n  phases: line from t = %.3f s, vacuum from t = %.3f s (nan: none), end %.3f s; times to "
        "%.0f %% of the height change\n  targets: inflate %.3g s, deflate %.3g s (tolerance %.1f %%); diameter %.3g "
        "cm, flat height "
        "%.3g cm (predictions)\n",
        o.scene.c_str(), setup.phases.inflate, setup.phases.deflate, setup.phases.end, 100 * o.fraction, o.inflate_s,
        o.deflate_s, 100 * o.tolerance, 100 * o.diameter_m, 100 * o.height_m);
  std::vector<Run> runs;
  const bool converged = fit_conductances(setup, o, comm, rank, runs);
  if (runs.empty() || !runs.back().completed) return 3;
  if (rank != 0) return converged ? 0 : 4;
  print_comparison(o, runs.back().m, setup.vacuum, converged, runs.size());
  write_morph_calibration(o, setup, runs, converged);
  return converged ? 0 : 4;
}

}  // namespace morphfem
