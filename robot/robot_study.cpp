#include "robot/robot_study.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "actuation/voxel_growth.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "core/plot.h"
#include "core/progress.h"
#include "core/strings.h"
#include "optim/fitness.h"
#include "sim/cross_section.h"
#include "sim/rank_jobs.h"
#include "sim/scene.h"

namespace morphfem {

namespace {

constexpr double kSettleStart = 1.5;  // gait start [s]: core ramp 0.5 s + 1 s of settling
constexpr double kCoreRamp = 0.5;     // [s]

std::string source_dir() { return resource_dir(); }

}  // namespace

std::vector<RobotCase> preset_cases(const std::string& preset, const std::vector<std::string>& allowed) {
  if (std::find(allowed.begin(), allowed.end(), preset) == allowed.end()) {
    throw InputError("--preset", "unknown preset '" + preset + "' (known: " + join(allowed, ", ") + ")");
  }
  if (preset == "physical") return physical_baseline_cases(source_dir());
  if (preset == "lattice-mechanics") return lattice_mechanics_cases(source_dir());
  return voxel_baseline_cases(source_dir());
}

const std::vector<RobotFidelity>& robot_fidelity_levels() {
  // Mesh size against the 1 cm skin layers and 4 mm deflated bladders; the time
  // step against the 0.81 s growth swing and the 0.42 s settle phase.
  static const std::vector<RobotFidelity> levels = {
      {"0", 0.02, 1, 0.1},
      {"1", 0.015, 1, 0.05},
      {"2", 0.01, 1, 0.025},
      {"3", 0.0075, 1, 0.0125},
  };
  return levels;
}

const RobotFidelity& find_robot_fidelity(const std::string& name) {
  // A custom level "MESH_SIZE:ORDER:MAX_STEP" (m, 1|2, s), e.g. 0.02:1:0.025.
  if (name.find(':') != std::string::npos) {
    static std::vector<RobotFidelity> custom;  // stable addresses for the returned references
    for (const auto& level : custom)
      if (level.name == name) return level;
    RobotFidelity level;
    level.name = name;
    char colon1 = 0, colon2 = 0;
    std::istringstream in(name);
    if (!(in >> level.mesh_size >> colon1 >> level.order >> colon2 >> level.max_step) || colon1 != ':' ||
        colon2 != ':' || !(in >> std::ws).eof() || !(level.mesh_size > 0) || (level.order != 1 && level.order != 2) ||
        !(level.max_step > 0))
      throw InputError("--fidelity", "a custom level is MESH_SIZE:ORDER:MAX_STEP (m, 1 or 2, s), got '" + name + "'");
    custom.reserve(64);
    if (custom.size() == custom.capacity()) throw InputError("--fidelity", "too many custom levels");
    custom.push_back(level);
    return custom.back();
  }
  for (const auto& level : robot_fidelity_levels())
    if (level.name == name) return level;
  const std::string known = join(robot_fidelity_levels(), ", ", [](const RobotFidelity& l) { return l.name; });
  throw InputError("--fidelity",
                   "unknown robot fidelity level '" + name + "' (known: " + known + ", or MESH_SIZE:ORDER:MAX_STEP)");
}

Schedule voxel_study_schedule(Schedule schedule) {
  const VoxelActuation voxel;
  // One lattice column: actuation phase (swing + 1 step) and settle phase.
  schedule.column_s = (voxel.swing_steps() + 1 + voxel.settle_steps) * voxel.step_s;
  schedule.repeats = 2;
  return schedule;
}

std::vector<RobotCase> voxel_baseline_cases(const std::string& dir) {
  const std::string templates = dir + "/examples/voxel/";
  const Schedule rolling = voxel_study_schedule(read_schedule(dir + "/examples/schedules/rolling.yaml"));
  const Schedule inching = voxel_study_schedule(read_schedule(dir + "/examples/schedules/inching.yaml"));
  auto empty = [](double orientation_deg, double core_pa) {
    ScheduleMatrix zeros(kNumRows, std::vector<int>(8, 0));
    Schedule s = voxel_study_schedule(Schedule::from_matrix(zeros, 1.237, 2, orientation_deg, core_pa));
    s.name = "empty";
    return s;
  };
  // Voxel speeds [BL/s]: ../shared/data/voxel-study/baselines.txt.
  return {
      {"roll_flat", templates + "roll_flat.yaml", rolling, 0, 0.1753136075598921},
      {"roll_hill15", templates + "roll_flat.yaml", rolling, 15, -0.5743081470776075},
      {"inch_flat", templates + "inch_flat.yaml", inching, 0, 0.06028166544377857},
      {"inch_hill15", templates + "inch_flat.yaml", inching, 15, 0.02455621751610403},
      {"empty_0deg_12kPa_flat", templates + "roll_flat.yaml", empty(0, 12000), 0, 0.000397400321504831},
      {"empty_90deg_12kPa_hill15", templates + "roll_flat.yaml", empty(90, 12000), 15, -0.026987374336082153},
      {"empty_0deg_0kPa_flat", templates + "inch_flat.yaml", empty(0, 0), 0, -9.115073925004267e-5},
      {"empty_90deg_0kPa_hill15", templates + "inch_flat.yaml", empty(90, 0), 15, -6.513284248646143e-5},
  };
}

std::vector<RobotCase> physical_baseline_cases(const std::string& dir) {
  std::vector<RobotCase> out;
  for (RobotCase c : voxel_baseline_cases(dir)) {
    const bool inflated = c.schedule.core_pressure_pa > 0;
    if (inflated && c.schedule.orientation_deg != 0) continue;
    c.template_scene = dir + (inflated ? "/examples/physical/roll_slice.yaml" : "/examples/physical/inch_flat.yaml");
    c.physical = true;
    out.push_back(c);
  }
  return out;
}

std::vector<std::string> lattice_mechanics_overrides() {
  std::string mu;  // friction per region as in the templates: skin 2.0, bladders 2/3
  for (int b = 1; b <= 8; ++b) mu += ", bladder_" + std::to_string(b) + ": 0.6667";
  return {
      "contact={lattice_floor: {point: [0, 0, -0.003], dhat: 5.0e-4, kappa: 6.0e5, eps_v: 1.0e-3, "
      "mu: {skin: 2.0" +
          mu + "}}}",
      "materials.bladder_*.mu=1388889",  // 12.5 x 111111 Pa
      "materials.bladder_*.density=15000"};
}

std::vector<RobotCase> lattice_mechanics_cases(const std::string& dir) {
  std::vector<RobotCase> out = voxel_baseline_cases(dir);
  for (auto& c : out) {
    c.overrides = lattice_mechanics_overrides();
    c.lattice_mechanics = true;
  }
  return out;
}

namespace {

// The keys every case sets last: slope, heading (the schedule's orientation), the
// end time (just after the gait's end), the output folder, then the overrides.
YAML::Node finish_case_yaml(YAML::Node root, const RobotCase& c, double gait_end_s, const std::string& output_dir) {
  root["environment"]["slope_deg"] = c.slope_deg;
  root["environment"]["heading_deg"] = c.schedule.orientation_deg;
  root["solver"]["end_time"] = gait_end_s + 1e-6;
  if (output_dir.empty())
    root.remove("output");
  else
    root["output"]["directory"] = output_dir;
  for (const std::string& assignment : c.overrides) set_scene_key(root, assignment, c.template_scene);
  return root;
}

// A physical case: the template's own schedule with the case's matrix, orientation,
// column length and repeats; an uninflated case leaves the core at 0.
YAML::Node physical_scene_yaml(const RobotCase& c, const std::string& output_dir) {
  YAML::Node root = load_scene_yaml(c.template_scene);
  YAML::Node a = root["actuation"];
  if (!a || !a.IsMap() || !a["schedule"] || !a["schedule"].IsMap() || !a["start"])
    throw InputError(c.template_scene, "a physical robot template needs 'actuation' with an inline schedule and start");
  root["name"] = c.name;
  YAML::Node sched = a["schedule"];
  YAML::Node matrix(YAML::NodeType::Sequence);
  for (int row = 0; row < kNumRows; ++row) {
    std::string text;
    for (int k = 0; k < c.schedule.columns(); ++k) text += c.schedule.active(row, k) ? '1' : '0';
    matrix.push_back(text);
  }
  sched["matrix"] = matrix;
  sched["orientation_deg"] = c.schedule.orientation_deg;
  sched["column_s"] = c.schedule.column_s;
  sched["repeats"] = c.schedule.repeats;
  if (!(c.schedule.core_pressure_pa > 0)) sched["core_pressure_pa"] = 0;
  return finish_case_yaml(root, c, a["start"].as<double>() + c.schedule.duration(), output_dir);
}

}  // namespace

YAML::Node robot_scene_yaml(const RobotCase& c, const RobotFidelity& level, const std::string& output_dir) {
  if (c.physical) return physical_scene_yaml(c, output_dir);
  YAML::Node root = load_scene_yaml(c.template_scene);
  YAML::Node a = root["actuation"];
  if (!a || !a.IsMap() || !a["growth"])
    throw InputError(c.template_scene, "a robot template needs 'actuation' with 'growth' (the voxel-study preset)");
  root["name"] = c.name;
  a["schedule"] = YAML::Load(c.schedule.to_yaml());
  a["start"] = kSettleStart;
  a["core_ramp_s"] = kCoreRamp;
  if (!std::isnan(c.mu_foot_active)) a["feet"]["mu_active"] = c.mu_foot_active;
  if (!std::isnan(c.mu_foot_inactive)) a["feet"]["mu_inactive"] = c.mu_foot_inactive;
  root["geometry"]["mesh_size"] = level.mesh_size;
  root["geometry"]["order"] = level.order;
  root["solver"]["max_step"] = level.max_step;
  return finish_case_yaml(root, c, kSettleStart + voxel_timeline(c.schedule).duration(), output_dir);
}

std::string robot_scene_text(const RobotCase& c, const RobotFidelity& level, const YAML::Node& doc) {
  YAML::Emitter out;
  out << doc;
  return "# morphfem robot case '" + c.name + "', fidelity " + level.name + " (template " + c.template_scene +
         "); run it with morphfem run\n" + out.c_str() + "\n";
}

SimulationResult run_robot_case(const RobotCase& c, const RobotFidelity& level, const std::string& output_dir,
                                MPI_Comm comm, bool progress) {
  const YAML::Node doc = robot_scene_yaml(c, level, output_dir);
  // Messages name the template; relative paths in it stay relative to it.
  Scene scene = scene_from_yaml(doc, c.template_scene);
  RunOptions options{!output_dir.empty(), progress};
  options.scene_text = scene_identity(doc);  // so that `morphfem run DIR/scene.yaml --resume` can extend it
  // Saved when the run starts: a killed case resumes with `morphfem run DIR.partial/scene.yaml --resume`.
  options.scene_file = robot_scene_text(c, level, doc);
  return run_scene(scene, comm, options);
}

double robot_speed(const Genome& genome, double slope_deg, const std::string& fidelity, MPI_Comm comm) {
  RobotCase c;
  c.name = "genome";
  c.template_scene = source_dir() + "/examples/voxel/inch_flat.yaml";
  c.schedule = voxel_study_schedule(Schedule::from_genome(genome));
  c.slope_deg = slope_deg;
  const SimulationResult r = run_robot_case(c, find_robot_fidelity(fidelity), "", comm, false);
  if (!r.stats.completed || !r.gait_complete) return -std::numeric_limits<double>::infinity();
  return r.speed_bl_per_s;
}

void register_robot_fitness() {
  register_fitness(
      "robot",
      [](const Genome& g, const Environment& env, const std::string& fidelity, MPI_Comm comm) {
        return robot_speed(g, env.slope_deg, fidelity, comm);
      },
      "finite-element robot, voxel-study preset with growth actuation (levels: morphfem robot levels)");
}

std::string case_folder(const RobotCase& c, const RobotFidelity& level) {
  return c.name + (c.physical ? "_physical" : c.lattice_mechanics ? "_lattice_L" + level.name : "_L" + level.name);
}

std::vector<CaseOutcome> run_robot_jobs(const std::vector<std::pair<RobotCase, RobotFidelity>>& jobs,
                                        const std::string& out_dir, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int n = static_cast<int>(jobs.size());
  Progress progress("robot", n, rank == 0);
  int done_here = 0;
  const std::vector<double> all = run_jobs_over_ranks(n, CaseOutcome::kFields, comm, [&](int j, double* row) {
    const auto& [c, level] = jobs[j];
    const std::string dir = out_dir.empty() ? "" : out_dir + "/" + case_folder(c, level);
    const SimulationResult r = run_robot_case(c, level, dir, PETSC_COMM_SELF, false);
    const double values[CaseOutcome::kFields] = {r.speed_bl_per_s,
                                                 r.gait_displacement_m,
                                                 r.stats.wall_s,
                                                 static_cast<double>(r.dofs),
                                                 static_cast<double>(r.stats.steps),
                                                 static_cast<double>(r.stats.newton_its),
                                                 r.stats.completed && r.gait_complete ? 1.0 : 0.0};
    std::copy(values, values + CaseOutcome::kFields, row);
    ++done_here;
    progress.update(std::min<double>(n, done_here * size), c.name + " L" + level.name);
  });
  progress.finish();
  std::vector<CaseOutcome> out(n);
  for (int j = 0; j < n; ++j) {
    const double* v = all.data() + static_cast<long>(j) * CaseOutcome::kFields;
    out[j] = {v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
  }
  return out;
}

const RobotCase& find_case(const std::vector<RobotCase>& cases, const std::string& name) {
  for (const auto& c : cases)
    if (c.name == name) return c;
  throw InputError("--case", "unknown robot case '" + name +
                                 "' (known: " + join(cases, ", ", [](const RobotCase& c) { return c.name; }) + ")");
}

Json outcome_json(const RobotCase& c, const RobotFidelity& level, const CaseOutcome& o) {
  Json j;
  j.add("case", c.name)
      .add("fidelity", level.name)
      .add("mesh_size_m", level.mesh_size)
      .add("order", level.order)
      .add("max_step_s", level.max_step)
      .add("slope_deg", c.slope_deg)
      .add("orientation_deg", c.schedule.orientation_deg)
      .add("core_pressure_pa", c.schedule.core_pressure_pa)
      .add("voxel_bl_per_s", c.voxel_bl_per_s)
      .add("speed_bl_per_s", o.speed)
      .add("displacement_m", o.displacement)
      .add("wall_s", o.wall_s)
      .add("dofs", o.dofs)
      .add("steps", o.steps)
      .add("newton_its", o.newton)
      .add("completed", o.completed > 0);
  return j;
}

}  // namespace morphfem
