// `morphfem robot friction-drag` (robot_study.h): the pull test of ROBOT.md on a robot
// scene. The test machine (Instron 3343) pulls the robot over a surface at 100 mm/min
// for 130 mm, once with the feet inflated and once deflated; the study's static
// coefficient is the force at the end of the initial linear (pre-slip) regime over the
// robot's weight, and a kinetic regime follows the slip.
//
// Here the scene (default examples/physical/friction_drag.yaml) holds the robot and the
// machine: a pull spring (loads.pulls, fem/pull_spring.h) on one face, the feet's
// friction from the actuation schedule's foot rows (mu_active inflated, mu_inactive
// deflated). For each foot state the command sets both foot rows on or off in a
// one-column schedule held for the whole pull, runs the scene and writes the load-cell
// force against crosshead travel as a test-machine export (optim/pull_test.h), the
// format `morphfem calibrate pull-tests` and `calibrate friction` read. It then reads
// the exports back and analyses them exactly as the measured curves are analysed
// (analyse_pull: mu_linear, mu_peak, mu_kinetic), so simulation and measurement are
// compared through one code path.
#include <mpi.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "core/plot.h"
#include "core/test_machine_export.h"
#include "optim/pull_test.h"
#include "robot/robot_study.h"
#include "robot/studies.h"
#include "sim/drag_scene.h"
#include "sim/rank_jobs.h"
#include "sim/scene.h"

namespace morphfem {

namespace {

struct FootState {
  std::string name;  // inflated | deflated
  bool inflated = true;
};

FootState foot_state(const std::string& text) {
  if (text == "inflated") return {"inflated", true};
  if (text == "deflated" || text == "uninflated") return {"deflated", false};
  throw InputError("--feet", "foot state '" + text + "' is neither inflated nor deflated");
}

// One foot state's scene document: the template with a one-column schedule (bladders
// off, both feet `state`) held from the actuation start to the end of the run, the run
// ending `travel` [m] after the pull starts, and its own output folder.
YAML::Node drag_case_yaml(const YAML::Node& template_doc, const std::string& path, const Scene& parsed,
                          const FootState& state, double travel, const std::string& output_dir) {
  YAML::Node root = YAML::Clone(template_doc);
  YAML::Node a = root["actuation"];
  if (!a || !a.IsMap() || !a["schedule"] || !a["schedule"].IsMap() || !a["start"] || !a["feet"])
    throw InputError(path, "friction-drag needs 'actuation' with an inline schedule, start and feet");
  const PullSpringSpec& pull = parsed.pulls.front();
  const double end_time = pull.start + travel / pull.velocity.norm();
  const double hold = end_time - a["start"].as<double>();
  if (!(hold > 0)) throw InputError(path, "the pull ends before actuation.start");
  root["name"] = "friction_drag_" + state.name;
  YAML::Node sched = a["schedule"];
  sched["name"] = "feet_" + state.name + "_hold";
  YAML::Node matrix(YAML::NodeType::Sequence);
  for (int row = 0; row < kNumRows; ++row) matrix.push_back(row >= 8 && state.inflated ? "1" : "0");
  sched["matrix"] = matrix;
  sched["column_s"] = hold;
  sched["repeats"] = 1;
  root["solver"]["end_time"] = end_time + 1e-9;
  root["output"]["directory"] = output_dir;
  return root;
}

// Linear interpolation of the curve's force at crosshead travel x [m].
double force_at(const PullCurve& c, double x) {
  if (c.displacement.empty()) return 0.0;
  auto hi = std::lower_bound(c.displacement.begin(), c.displacement.end(), x);
  if (hi == c.displacement.begin()) return c.force.front();
  if (hi == c.displacement.end()) return c.force.back();
  const size_t i = static_cast<size_t>(hi - c.displacement.begin());
  const double x0 = c.displacement[i - 1], x1 = c.displacement[i];
  return x1 > x0 ? c.force[i - 1] + (c.force[i] - c.force[i - 1]) * (x - x0) / (x1 - x0) : c.force[i];
}

struct DragOutcome {
  double completed = 0, wall_s = 0, dofs = 0, steps = 0, newton = 0, weight_N = 0, slip_m = 0, mu_scene = 0;
  static constexpr int kFields = 8;
};

}  // namespace

int robot_friction_drag(const FrictionDragOptions& o, MPI_Comm comm) {
  const std::string path = o.scene.empty() ? resource_dir() + "/examples/physical/friction_drag.yaml" : o.scene;
  YAML::Node doc = load_scene_yaml(path);
  for (const std::string& assignment : o.set) set_scene_key(doc, assignment, path);
  const Scene parsed = scene_from_yaml(doc, path);
  if (parsed.pulls.empty()) throw InputError(path, "friction-drag needs a test machine: loads.pulls");
  if (!parsed.dynamic) throw InputError(path, "friction-drag needs inertia (dynamics): slip after the peak is dynamic");
  const PullSpringSpec& pull = parsed.pulls.front();
  const double speed = pull.velocity.norm();  // [m/s]
  double travel = speed * (parsed.solver.t_end - pull.start);
  if (const std::string& t = o.travel_mm; !t.empty()) {
    char* end = nullptr;
    travel = 1e-3 * std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || !(travel > 0))
      throw InputError("--travel-mm", "expected a positive length in mm, got '" + t + "'");
  }
  if (!(travel > 0)) throw InputError(path, "solver.end_time must lie after the pull's start");
  std::vector<FootState> states;
  for (const std::string& s : o.feet) states.push_back(foot_state(s));
  if (states.empty()) throw InputError("--feet", "no foot state given");
  const std::string& surface = o.surface;
  const std::string& out_dir = o.out_dir;

  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int n = static_cast<int>(states.size());
  auto export_path = [&](const FootState& s) { return out_dir + "/" + surface + "_" + s.name + "_sim.csv"; };
  if (rank == 0) std::filesystem::create_directories(out_dir);
  MPI_Barrier(comm);

  // One foot state per rank (round robin), each on its own rank.
  const std::vector<double> all = run_jobs_over_ranks(n, DragOutcome::kFields, comm, [&](int j, double* row) {
    const FootState& state = states[j];
    const YAML::Node case_doc = drag_case_yaml(doc, path, parsed, state, travel, out_dir + "/" + state.name);
    const Scene scene = scene_from_yaml(case_doc, path);
    RunOptions run;
    run.progress = rank == 0;
    const DragCurve curve = run_pull_scene(scene, PETSC_COMM_SELF, run);
    const double weight = curve.mass_kg * scene.gravity.norm();
    // The feet's coefficient in this state: the schedule's foot rows pick mu_active or mu_inactive.
    const YAML::Node feet = case_doc["actuation"]["feet"];
    const char* key = state.inflated ? "mu_active" : "mu_inactive";
    const double mu_scene = feet[key] && feet[key].IsScalar() ? feet[key].as<double>() : std::nan("");
    const SimulationResult& r = curve.result;
    double slip = r.gait_displacement_m;
    if (!r.gait_complete && r.trajectory.size() > 1) {
      const auto &p0 = r.trajectory.front(), &p1 = r.trajectory.back();
      slip = (p1[1] - p0[1]) * pull.velocity.x() / speed + (p1[2] - p0[2]) * pull.velocity.y() / speed +
             (p1[3] - p0[3]) * pull.velocity.z() / speed;
    }
    const double values[DragOutcome::kFields] = {curve.completed ? 1.0 : 0.0,
                                                 curve.wall_s,
                                                 static_cast<double>(r.dofs),
                                                 static_cast<double>(r.stats.steps),
                                                 static_cast<double>(r.stats.newton_its),
                                                 weight,
                                                 slip,
                                                 mu_scene};
    std::copy(values, values + DragOutcome::kFields, row);
    if (curve.completed) {  // a failed run leaves no export that reads like a finished test
      PullCurve c;
      c.label = "friction_drag_" + state.name;
      c.surface = surface;
      c.foot_state = state.name;
      c.time = curve.time;
      c.displacement = curve.displacement;
      c.force = curve.force;
      write_file_atomic(export_path(state),
                        pull_export_text(c, weight, false, "morphfem (simulated, " + path + ")", speed * 6e4));
    }
  });
  if (rank != 0) return 0;

  // Read the exports back and analyse them as the measured curves are analysed.
  std::vector<DragOutcome> outcomes(n);
  std::vector<PullCurve> curves(n);
  std::vector<PullAnalysis> analyses(n);
  bool all_ok = true;
  std::string table =
      "feet       mu_scene  mu_linear  mu_peak  mu_kinetic  peak [N]  at [mm]  kinetic [N]  slip [mm]  wall [s]   "
      "dofs  steps  status\n";
  std::string csv = "curve,displacement_mm,force_N\n";
  std::vector<Json> rows;
  char line[300];
  for (int j = 0; j < n; ++j) {
    const double* v = all.data() + static_cast<long>(j) * DragOutcome::kFields;
    outcomes[j] = {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]};
    const DragOutcome& o = outcomes[j];
    if (o.completed < 0.5) {
      all_ok = false;
      std::snprintf(line, sizeof line, "%-9s  %8.3f  %s\n", states[j].name.c_str(), o.mu_scene,
                    "run FAILED (no export written; see its summary.json)");
      table += line;
      continue;
    }
    const auto specimens = read_test_machine_export(export_path(states[j]));
    curves[j] = pull_curve_from_export(specimens.front());
    analyses[j] = analyse_pull(curves[j], o.weight_N);
    const PullAnalysis& a = analyses[j];
    std::snprintf(line, sizeof line,
                  "%-9s  %8.3f  %9.3f  %7.3f  %10.3f  %8.3f  %7.2f  %11.3f  %9.2f  %8.1f  %5.0f  %5.0f  ok\n",
                  states[j].name.c_str(), o.mu_scene, a.mu_linear, a.mu_peak, a.mu_kinetic, a.peak_force_N,
                  1e3 * a.peak_m, a.kinetic_force_N, 1e3 * o.slip_m, o.wall_s, o.dofs, o.steps);
    table += line;
    for (size_t i = 0; i < curves[j].force.size(); ++i) {
      std::snprintf(line, sizeof line, "feet %s,%.6g,%.6g\n", states[j].name.c_str(), 1e3 * curves[j].displacement[i],
                    curves[j].force[i]);
      csv += line;
    }
    Json row;
    row.add("feet", states[j].name)
        .add("mu_scene", o.mu_scene)
        .add("mu_linear", a.mu_linear)
        .add("mu_peak", a.mu_peak)
        .add("mu_kinetic", a.mu_kinetic)
        .add("slope_N_per_m", a.slope_N_per_m)
        .add("linear_end_mm", 1e3 * a.linear_end_m)
        .add("peak_force_N", a.peak_force_N)
        .add("peak_mm", 1e3 * a.peak_m)
        .add("kinetic_force_N", a.kinetic_force_N)
        .add("slip_mm", 1e3 * o.slip_m)
        .add("weight_N", o.weight_N)
        .add("wall_s", o.wall_s)
        .add("dofs", o.dofs)
        .add("steps", o.steps)
        .add("newton_its", o.newton)
        .add("export", export_path(states[j]))
        .add("results", out_dir + "/" + states[j].name);
    rows.push_back(row);
  }
  std::printf("friction drag: %s, pulled %.0f mm at %.0f mm/min over %s, robot weight %.3f N\n", path.c_str(),
              1e3 * travel, speed * 6e4, surface.c_str(), outcomes.front().weight_N);
  std::fputs(table.c_str(), stdout);

  // The curves as the machine prints them: load against extension, fine through the
  // pre-slip rise and the peak, then every 10 mm.
  std::vector<double> at;
  for (double x = 0; x <= std::min(6.0, 1e3 * travel) + 1e-9; x += 0.5) at.push_back(x);
  for (double x = 10; x <= 1e3 * travel + 1e-9; x += 10) at.push_back(x);
  std::string head = "extension [mm]";
  for (int j = 0; j < n; ++j)
    if (outcomes[j].completed > 0.5) head += "  load " + states[j].name + " [N]";
  std::printf("%s\n", head.c_str());
  for (double x : at) {
    std::printf("%14.1f", x);
    for (int j = 0; j < n; ++j)
      if (outcomes[j].completed > 0.5)
        std::printf("  %*.4f", static_cast<int>(9 + states[j].name.size()), force_at(curves[j], 1e-3 * x));
    std::printf("\n");
  }

  Json summary;
  summary.add("scene", path)
      .add("surface", surface)
      .add("travel_mm", 1e3 * travel)
      .add("speed_mm_per_min", speed * 6e4);
  summary.add("states", rows);
  write_file_atomic(out_dir + "/friction_drag.json", summary.str(true) + "\n");
  write_file_atomic(out_dir + "/friction_drag_curves.csv", csv);
  run_plot_script("plot_calibration.py",
                  {"curves", out_dir + "/friction_drag_curves.csv", out_dir + "/friction_drag.png"}, "the pull curves");
  std::printf("results: %s/friction_drag.json, exports %s/%s_*_sim.csv, %s/friction_drag.png, runs in %s/STATE/\n",
              out_dir.c_str(), out_dir.c_str(), surface.c_str(), out_dir.c_str(), out_dir.c_str());
  return all_ok ? 0 : 3;
}

}  // namespace morphfem
