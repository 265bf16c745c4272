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

// The pull test as the options set it up: the scene document, the parsed scene (its
// pull), the travel [m] and the foot states.
struct DragSetup {
  std::string path;
  YAML::Node doc;
  Scene parsed;
  double speed = 0, travel = 0;  // [m/s], [m]
  std::vector<FootState> states;
  std::string surface, out_dir;
  std::string export_path(const FootState& s) const { return out_dir + "/" + surface + "_" + s.name + "_sim.csv"; }
};

DragSetup drag_setup(const FrictionDragOptions& o) {
  DragSetup d;
  d.path = o.scene.empty() ? resource_dir() + "/examples/physical/friction_drag.yaml" : o.scene;
  d.doc = load_scene_yaml(d.path);
  for (const std::string& assignment : o.set) set_scene_key(d.doc, assignment, d.path);
  d.parsed = scene_from_yaml(d.doc, d.path);
  if (d.parsed.pulls.empty()) throw InputError(d.path, "friction-drag needs a test machine: loads.pulls");
  if (!d.parsed.dynamics)
    throw InputError(d.path, "friction-drag needs inertia (dynamics): slip after the peak is dynamic");
  const PullSpringSpec& pull = d.parsed.pulls.front();
  d.speed = pull.velocity.norm();
  d.travel = d.speed * (d.parsed.solver.t_end - pull.start);
  if (const std::string& t = o.travel_mm; !t.empty()) {
    char* end = nullptr;
    d.travel = 1e-3 * std::strtod(t.c_str(), &end);
    if (end == t.c_str() || *end != '\0' || !(d.travel > 0))
      throw InputError("--travel-mm", "expected a positive length in mm, got '" + t + "'");
  }
  if (!(d.travel > 0)) throw InputError(d.path, "solver.end_time must lie after the pull's start");
  for (const std::string& s : o.feet) d.states.push_back(foot_state(s));
  if (d.states.empty()) throw InputError("--feet", "no foot state given");
  d.surface = o.surface;
  d.out_dir = o.out_dir;
  return d;
}

// One foot state's run on this rank: its outcome row, and its export if it completed
// (a failed run leaves no export that reads like a finished test).
void run_drag_state(const DragSetup& d, const FootState& state, bool progress, double* row) {
  const PullSpringSpec& pull = d.parsed.pulls.front();
  const YAML::Node case_doc = drag_case_yaml(d.doc, d.path, d.parsed, state, d.travel, d.out_dir + "/" + state.name);
  const Scene scene = scene_from_yaml(case_doc, d.path);
  RunOptions run;
  run.progress = progress;
  const DragCurve curve = run_pull_scene(scene, PETSC_COMM_SELF, run);
  const double weight = curve.mass_kg * scene.gravity.norm();
  // The feet's coefficient in this state: the schedule's foot rows pick mu_active or mu_inactive.
  const YAML::Node feet = case_doc["actuation"]["feet"];
  const char* key = state.inflated ? "mu_active" : "mu_inactive";
  const double mu_scene = feet[key] && feet[key].IsScalar() ? feet[key].as<double>() : std::nan("");
  const SimulationResult& r = curve.result;
  double slip = r.gait_displacement_m;
  if (!r.gait_complete && r.trajectory.size() > 1) {  // the centroid's travel along the pull
    const auto &p0 = r.trajectory.front(), &p1 = r.trajectory.back();
    slip = (p1[1] - p0[1]) * pull.velocity.x() / d.speed + (p1[2] - p0[2]) * pull.velocity.y() / d.speed +
           (p1[3] - p0[3]) * pull.velocity.z() / d.speed;
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
  if (!curve.completed) return;
  PullCurve c;
  c.label = "friction_drag_" + state.name;
  c.surface = d.surface;
  c.foot_state = state.name;
  c.time = curve.time;
  c.displacement = curve.displacement;
  c.force = curve.force;
  write_file_atomic(d.export_path(state),
                    pull_export_text(c, weight, false, "morphfem (simulated, " + d.path + ")", d.speed * 6e4));
}

Json state_json(const DragSetup& d, const FootState& state, const DragOutcome& o, const PullAnalysis& a) {
  Json row;
  row.add("feet", state.name)
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
      .add("export", d.export_path(state))
      .add("results", d.out_dir + "/" + state.name);
  return row;
}

// The exports read back and analysed as the measured curves are: the table, the
// curves' CSV and the JSON rows.
struct DragReport {
  std::vector<DragOutcome> outcomes;
  std::vector<PullCurve> curves;
  std::string table, csv;
  std::vector<Json> rows;
  bool all_ok = true;
};

DragReport drag_report(const DragSetup& d, const std::vector<double>& all) {
  const int n = static_cast<int>(d.states.size());
  DragReport rep;
  rep.outcomes.resize(n);
  rep.curves.resize(n);
  rep.table =
      "feet       mu_scene  mu_linear  mu_peak  mu_kinetic  peak [N]  at [mm]  kinetic [N]  slip [mm]  wall [s]   "
      "dofs  steps  status\n";
  rep.csv = "curve,displacement_mm,force_N\n";
  char line[300];
  for (int j = 0; j < n; ++j) {
    const double* v = all.data() + static_cast<long>(j) * DragOutcome::kFields;
    rep.outcomes[j] = {v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]};
    const DragOutcome& o = rep.outcomes[j];
    const FootState& state = d.states[j];
    if (o.completed < 0.5) {
      rep.all_ok = false;
      std::snprintf(line, sizeof line, "%-9s  %8.3f  %s\n", state.name.c_str(), o.mu_scene,
                    "run FAILED (no export written; see its summary.json)");
      rep.table += line;
      continue;
    }
    const auto specimens = read_test_machine_export(d.export_path(state));
    rep.curves[j] = pull_curve_from_export(specimens.front());
    const PullAnalysis a = analyse_pull(rep.curves[j], o.weight_N);
    std::snprintf(line, sizeof line,
                  "%-9s  %8.3f  %9.3f  %7.3f  %10.3f  %8.3f  %7.2f  %11.3f  %9.2f  %8.1f  %5.0f  %5.0f  ok\n",
                  state.name.c_str(), o.mu_scene, a.mu_linear, a.mu_peak, a.mu_kinetic, a.peak_force_N, 1e3 * a.peak_m,
                  a.kinetic_force_N, 1e3 * o.slip_m, o.wall_s, o.dofs, o.steps);
    rep.table += line;
    for (size_t i = 0; i < rep.curves[j].force.size(); ++i) {
      std::snprintf(line, sizeof line, "feet %s,%.6g,%.6g\n", state.name.c_str(), 1e3 * rep.curves[j].displacement[i],
                    rep.curves[j].force[i]);
      rep.csv += line;
    }
    rep.rows.push_back(state_json(d, state, o, a));
  }
  return rep;
}

// The curves as the machine prints them: load against extension, fine through the
// pre-slip rise and the peak, then every 10 mm.
void print_machine_table(const DragSetup& d, const DragReport& rep) {
  std::vector<double> at;
  for (double x = 0; x <= std::min(6.0, 1e3 * d.travel) + 1e-9; x += 0.5) at.push_back(x);
  for (double x = 10; x <= 1e3 * d.travel + 1e-9; x += 10) at.push_back(x);
  const int n = static_cast<int>(d.states.size());
  std::string head = "extension [mm]";
  for (int j = 0; j < n; ++j)
    if (rep.outcomes[j].completed > 0.5) head += "  load " + d.states[j].name + " [N]";
  std::printf("%s\n", head.c_str());
  for (double x : at) {
    std::printf("%14.1f", x);
    for (int j = 0; j < n; ++j)
      if (rep.outcomes[j].completed > 0.5)
        std::printf("  %*.4f", static_cast<int>(9 + d.states[j].name.size()), force_at(rep.curves[j], 1e-3 * x));
    std::printf("\n");
  }
}

void write_drag_results(const DragSetup& d, const DragReport& rep) {
  Json summary;
  summary.add("scene", d.path)
      .add("surface", d.surface)
      .add("travel_mm", 1e3 * d.travel)
      .add("speed_mm_per_min", d.speed * 6e4);
  summary.add("states", rep.rows);
  write_file_atomic(d.out_dir + "/friction_drag.json", summary.str(true) + "\n");
  write_file_atomic(d.out_dir + "/friction_drag_curves.csv", rep.csv);
  run_plot_script("plot_calibration.py",
                  {"curves", d.out_dir + "/friction_drag_curves.csv", d.out_dir + "/friction_drag.png"},
                  "the pull curves");
  std::printf("results: %s/friction_drag.json, exports %s/%s_*_sim.csv, %s/friction_drag.png, runs in %s/STATE/\n",
              d.out_dir.c_str(), d.out_dir.c_str(), d.surface.c_str(), d.out_dir.c_str(), d.out_dir.c_str());
}

}  // namespace

int robot_friction_drag(const FrictionDragOptions& o, MPI_Comm comm) {
  const DragSetup d = drag_setup(o);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank == 0) std::filesystem::create_directories(d.out_dir);
  MPI_Barrier(comm);
  // One foot state per rank (round robin), each on its own rank.
  const int n = static_cast<int>(d.states.size());
  const std::vector<double> all = run_jobs_over_ranks(
      n, DragOutcome::kFields, comm, [&](int j, double* row) { run_drag_state(d, d.states[j], rank == 0, row); });
  if (rank != 0) return 0;
  const DragReport rep = drag_report(d, all);
  std::printf("friction drag: %s, pulled %.0f mm at %.0f mm/min over %s, robot weight %.3f N\n", d.path.c_str(),
              1e3 * d.travel, d.speed * 6e4, d.surface.c_str(), rep.outcomes.front().weight_N);
  std::fputs(rep.table.c_str(), stdout);
  print_machine_table(d, rep);
  write_drag_results(d, rep);
  return rep.all_ok ? 0 : 3;
}

}  // namespace morphfem
