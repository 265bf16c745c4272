#include "app/robot_study.h"

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
#include "app/plot.h"
#include "app/rank_jobs.h"
#include "app/scene.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/progress.h"
#include "core/strings.h"
#include "optim/fitness.h"

namespace morphfem {

namespace {

constexpr double kSettleStart = 1.5;  // gait start [s]: core ramp 0.5 s + 1 s of settling
constexpr double kCoreRamp = 0.5;     // [s]

std::string source_dir() { return MORPHFEM_SOURCE_DIR; }

const char* kRobotUsage =
    "usage: morphfem robot COMMAND [options]\n"
    "  validate [--fidelity L] [--cases A,B,...] [--presets voxel,lattice-mechanics,physical] [--out DIR]\n"
    "           [--set KEY=VALUE ...] [--set-physical KEY=VALUE ...] [--set-physical-round KEY=VALUE ...]\n"
    "           [--set-physical-flat KEY=VALUE ...]\n"
    "        the voxel study's baselines (hand-designed rolling and inching, flat and\n"
    "        15 deg hill, four empty schedules): voxel speed beside the finite-element\n"
    "        speed (voxel-study preset, growth actuation; --set keys, level L), wall time,\n"
    "        dofs, steps, and beside the physical laminate with pressure actuation (inflated:\n"
    "        examples/physical/roll_slice.yaml, flat: examples/physical/inch_flat.yaml;\n"
    "        --set-physical keys apply to both, --set-physical-round / -flat to one); preset\n"
    "        lattice-mechanics (not by default): the voxel-study preset with the lattice's floor\n"
    "        spheres, bladder stiffness and mass, as a further column (needs order 2)\n"
    "  ladder --case NAME [--levels 0,1,2] [--preset voxel|lattice-mechanics] [--out DIR] [--set KEY=VALUE ...]\n"
    "        one case on several fidelity levels: speed against wall time, and the\n"
    "        cheapest level within 5 % of the finest\n"
    "  spread --case NAME --vary KEY=V1,V2,... [--levels 0,...] [--preset voxel|lattice-mechanics|physical]\n"
    "         [--out DIR] [--set KEY=VALUE ...]\n"
    "        one case run once per value of one scene key (a perturbation ensemble, e.g.\n"
    "        --vary environment.heading_deg=-1,-0.5,0,0.5,1), on each level: every speed, their\n"
    "        mean, standard deviation and range, and whether the levels' means agree; JSON, PNG\n"
    "  morph [--scene FILE] [--out DIR] [--set KEY=VALUE ...]\n"
    "        shape change under core pressure (default examples/voxel/morph.yaml): width /\n"
    "        thickness of the mid-length cross-section against core pressure, table, CSV, PNG\n"
    "  friction-sweep [--fidelity L] [--points all|N] [--out DIR]\n"
    "        inching on flat ground against the feet's mean friction (the voxel study's\n"
    "        sfrict_results.csv: active - inactive = 2.0), beside the voxel points, PNG\n"
    "  friction-drag [--scene FILE] [--feet inflated,deflated] [--travel-mm D] [--surface wood]\n"
    "                [--out DIR] [--set KEY=VALUE ...]\n"
    "        the test-machine pull test (default examples/physical/friction_drag.yaml): the robot\n"
    "        pulled at the scene's speed with its feet inflated and deflated; force against\n"
    "        crosshead travel as exports `calibrate pull-tests` reads, their coefficients, PNG\n"
    "        (foot states spread over the MPI ranks)\n"
    "  benchmark [--fidelity L] [--presets voxel,lattice-mechanics,physical]\n"
    "        wall time of each hand-designed gait (19.8 s) on one rank, beside the voxel\n"
    "        simulator's 136-145 s on this machine (physical: the templates' own meshes)\n"
    "  levels    the fidelity levels\n"
    "--set KEY=VALUE (repeatable) sets a scene key last, e.g. --set geometry.order=2 or\n"
    "  --set 'materials.bladder_*.density=15000' (a key ending in '*': every key with that prefix)\n"
    "Cases are spread over the MPI ranks (one rank per case): mpirun -n 2 morphfem robot validate\n";

}  // namespace

std::string option(const std::vector<std::string>& args, const std::string& name, const std::string& fallback) {
  for (size_t i = 0; i + 1 < args.size(); ++i)
    if (args[i] == name) return args[i + 1];
  return fallback;
}

// Every value of a repeatable option (--set A --set B).
std::vector<std::string> options(const std::vector<std::string>& args, const std::string& name) {
  std::vector<std::string> out;
  for (size_t i = 1; i + 1 < args.size(); i += 2)
    if (args[i] == name) out.push_back(args[i + 1]);
  return out;
}

std::string joined_options(const std::vector<std::string>& args, const std::string& name) {
  return join(options(args, name), "; ");
}

std::vector<RobotCase> preset_cases(const std::string& preset, const std::vector<std::string>& allowed) {
  if (std::find(allowed.begin(), allowed.end(), preset) == allowed.end()) {
    throw InputError("--preset", "unknown preset '" + preset + "' (known: " + join(allowed, ", ") + ")");
  }
  if (preset == "physical") return physical_baseline_cases(source_dir());
  if (preset == "lattice-mechanics") return lattice_mechanics_cases(source_dir());
  return voxel_baseline_cases(source_dir());
}

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream s(list);
  for (std::string item; std::getline(s, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

void check_options(const std::vector<std::string>& args, const std::vector<std::string>& allowed) {
  for (size_t i = 1; i < args.size(); i += 2) {
    if (std::find(allowed.begin(), allowed.end(), args[i]) == allowed.end())
      throw InputError("morphfem robot " + args[0], "unknown option '" + args[i] + "'\n" + kRobotUsage);
    if (i + 1 >= args.size()) throw InputError("morphfem robot " + args[0], "option " + args[i] + " needs a value");
  }
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

void set_path(YAML::Node node, const std::vector<std::string>& path, size_t i, const YAML::Node& value,
              const std::string& where, const std::string& key) {
  if (!node.IsMap())
    throw InputError(where,
                     "--set " + key + ": " + (i == 0 ? "the scene" : "'" + path[i - 1] + "'") + " is not a mapping");
  if (!path[i].empty() && path[i].back() == '*') {  // every key starting with the prefix
    if (i + 1 == path.size()) throw InputError(where, "--set " + key + ": '*' cannot be in the last key");
    const std::string prefix = path[i].substr(0, path[i].size() - 1);
    int matched = 0;
    for (auto kv : node)
      if (kv.first.as<std::string>().rfind(prefix, 0) == 0) {
        set_path(kv.second, path, i + 1, value, where, key);
        ++matched;
      }
    if (matched == 0) throw InputError(where, "--set " + key + ": no key matches '" + path[i] + "'");
    return;
  }
  if (i + 1 == path.size()) {
    node[path[i]] = value;
    return;
  }
  if (!node[path[i]]) throw InputError(where, "--set " + key + ": no key '" + path[i] + "' in the scene");
  set_path(node[path[i]], path, i + 1, value, where, key);
}

}  // namespace

void set_scene_key(YAML::Node root, const std::string& assignment, const std::string& where) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == assignment.size())
    throw InputError(where, "--set '" + assignment + "': expected KEY=VALUE (e.g. geometry.order=2)");
  const std::string key = assignment.substr(0, eq);
  std::vector<std::string> path;
  std::stringstream s(key);
  for (std::string part; std::getline(s, part, '.');) {
    if (part.empty()) throw InputError(where, "--set " + key + ": empty key in the path");
    path.push_back(part);
  }
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    throw InputError(where, "--set " + key + ": the value is not YAML: " + e.what());
  }
  set_path(root, path, 0, value, where, key);
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

SimulationResult run_robot_case(const RobotCase& c, const RobotFidelity& level, const std::string& output_dir,
                                MPI_Comm comm, bool progress) {
  const YAML::Node doc = robot_scene_yaml(c, level, output_dir);
  // Messages name the template; relative paths in it stay relative to it.
  Scene scene = scene_from_yaml(doc, c.template_scene);
  RunOptions options{!output_dir.empty(), progress};
  options.scene_text = scene_identity(doc);  // so that `morphfem run DIR/scene.yaml --resume` can extend it
  // Saved when the run starts: a killed case resumes with `morphfem run DIR.partial/scene.yaml --resume`.
  YAML::Emitter out;
  out << doc;
  options.scene_file = "# morphfem robot case '" + c.name + "', fidelity " + level.name + " (template " +
                       c.template_scene + "); run it with morphfem run\n" + out.c_str() + "\n";
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
    const std::string dir = out_dir.empty() ? ""
                                            : out_dir + "/" + c.name +
                                                  (c.physical            ? "_physical"
                                                   : c.lattice_mechanics ? "_lattice_L" + level.name
                                                                         : "_L" + level.name);
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

namespace {

int validate(const std::vector<std::string>& args, MPI_Comm comm) {
  check_options(args, {"--fidelity", "--cases", "--out", "--set", "--set-physical", "--set-physical-round",
                       "--set-physical-flat", "--presets"});
  const RobotFidelity& level = find_robot_fidelity(option(args, "--fidelity", "0"));
  const std::string out_dir = option(args, "--out", "results/robot/validate");
  bool voxel = false, lattice = false, physical = false;
  for (const auto& p : split(option(args, "--presets", "voxel,physical"))) {
    if (p == "voxel")
      voxel = true;
    else if (p == "lattice-mechanics")
      lattice = true;
    else if (p == "physical")
      physical = true;
    else
      throw InputError("--presets", "unknown preset '" + p + "' (known: voxel, lattice-mechanics, physical)");
  }
  auto all_cases = voxel_baseline_cases(source_dir());
  for (auto& c : all_cases) c.overrides = options(args, "--set");
  auto lattice_cases = lattice_mechanics_cases(source_dir());
  for (auto& c : lattice_cases)  // the lattice's mechanics, then --set
    for (const auto& assignment : options(args, "--set")) c.overrides.push_back(assignment);
  auto physical_cases = physical_baseline_cases(source_dir());
  for (auto& c : physical_cases) {  // both templates, then the inflated (round) or the flat one
    c.overrides = options(args, "--set-physical");
    const auto own = options(args, c.schedule.core_pressure_pa > 0 ? "--set-physical-round" : "--set-physical-flat");
    c.overrides.insert(c.overrides.end(), own.begin(), own.end());
  }
  std::vector<std::string> names;
  const std::string wanted = option(args, "--cases", "");
  for (const auto& c : all_cases) names.push_back(c.name);
  if (!wanted.empty()) {
    names = split(wanted);
    for (const auto& name : names) find_case(all_cases, name);  // refuses unknown names
  }
  // The voxel-preset jobs, the lattice-mechanics ones, then the physical ones; each row of
  // the table pairs them by name.
  std::vector<std::pair<RobotCase, RobotFidelity>> jobs;
  for (const auto& name : names)
    if (voxel) jobs.emplace_back(find_case(all_cases, name), level);
  for (const auto& name : names)
    if (lattice) jobs.emplace_back(find_case(lattice_cases, name), level);
  for (const auto& name : names)
    for (const auto& c : physical_cases)
      if (physical && c.name == name) jobs.emplace_back(c, level);
  const auto outcomes = run_robot_jobs(jobs, out_dir, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return 0;
  std::string table =
      "case                       slope  orient  core_Pa   voxel_BL/s      fem_BL/s   wall_s   dofs  "
      "steps  newton  status   phys_BL/s  phys_wall_s" +
      std::string(lattice ? "  lattmech_BL/s  lattmech_wall_s" : "") + "\n";
  std::vector<Json> rows;
  char line[320];
  auto find_job = [&](const std::string& name, bool phys, bool lattice_mechanics) -> int {
    for (size_t j = 0; j < jobs.size(); ++j)
      if (jobs[j].first.name == name && jobs[j].first.physical == phys &&
          jobs[j].first.lattice_mechanics == lattice_mechanics)
        return static_cast<int>(j);
    return -1;
  };
  for (const auto& name : names) {
    const int jv = find_job(name, false, false), jp = find_job(name, true, false), jl = find_job(name, false, true);
    const RobotCase& c = jv >= 0 ? jobs[jv].first : find_case(all_cases, name);
    std::string fem = "          -        -      -      -       -  -     ", phys = "        n/a          -";
    if (jv >= 0) {
      const auto& o = outcomes[jv];
      char buf[160];
      std::snprintf(buf, sizeof buf, "%+11.5f  %7.1f  %5.0f  %5.0f  %6.0f  %-6s", o.speed, o.wall_s, o.dofs, o.steps,
                    o.newton, o.completed > 0 ? "ok" : "FAILED");
      fem = buf;
      rows.push_back(outcome_json(c, level, o));
    }
    // A further preset's cells (speed, wall time) and its JSON row.
    auto preset_cells = [&](int j, int speed_width, int wall_width, const char* preset) {
      const auto& o = outcomes[j];
      char buf[96];
      std::snprintf(buf, sizeof buf, "%+*.5f  %*.1f%s", speed_width, o.speed, wall_width, o.wall_s,
                    o.completed > 0 ? "" : " FAILED");
      Json row = outcome_json(jobs[j].first, level, o);
      row.add("preset", preset);
      if (jobs[j].first.physical) row.add("template", jobs[j].first.template_scene);
      rows.push_back(row);
      return std::string(buf);
    };
    if (jp >= 0) phys = preset_cells(jp, 11, 11, "physical");
    const std::string lattmech = jl >= 0 ? "  " + preset_cells(jl, 13, 15, "lattice-mechanics") : "";
    std::snprintf(line, sizeof line, "%-26s %5.1f  %6.1f  %7.0f  %+11.5f  %s  %s%s\n", c.name.c_str(), c.slope_deg,
                  c.schedule.orientation_deg, c.schedule.core_pressure_pa, c.voxel_bl_per_s, fem.c_str(), phys.c_str(),
                  lattmech.c_str());
    table += line;
  }
  table +=
      "phys: the physical laminate with pressure actuation: inflated cases on its plane-strain rolling slice\n"
      "(examples/physical/roll_slice.yaml, core at the 50 kPa line pressure), flat ones on the full-length body\n"
      "(examples/physical/inch_flat.yaml); n/a: the inflated body heading along itself has no physical scene.\n";
  if (lattice)
    table +=
        "lattmech: the voxel-study preset with the lattice's own mechanics: a floor sphere per voxel, bladders\n"
        "12.5x stiffer and with the lattice's mass (app/robot_study.h, lattice_mechanics_overrides); linear\n"
        "tetrahedra lock in bending and do not roll with it: use order 2 (e.g. --fidelity 0.02:2:0.05).\n";
  std::printf("fidelity %s: mesh %.4g m, P%d, max step %.4g s\n%s", level.name.c_str(), level.mesh_size, level.order,
              level.max_step, table.c_str());
  std::filesystem::create_directories(out_dir);
  Json summary;
  const std::string overrides = joined_options(args, "--set");  // the --set assignments, as given
  std::vector<std::string> physical_assignments;                // "set-physical KEY=VALUE", ...
  for (const char* flag : {"--set-physical", "--set-physical-round", "--set-physical-flat"})
    for (const auto& assignment : options(args, flag))
      physical_assignments.push_back(std::string(flag + 2) + " " + assignment);
  const std::string physical_overrides = join(physical_assignments, "; ");
  summary.add("fidelity", level.name)
      .add("overrides", overrides)
      .add("physical_overrides", physical_overrides)
      .add("cases", rows);
  write_file_atomic(out_dir + "/validation.json", summary.str(true) + "\n");
  write_file_atomic(out_dir + "/validation.txt", table);
  std::printf(
      "results: %s/validation.json, per case %s/CASE_L%s/ (physical: CASE_physical/, lattice mechanics: "
      "CASE_lattice_L%s/)\n",
      out_dir.c_str(), out_dir.c_str(), level.name.c_str(), level.name.c_str());
  return 0;
}

int ladder(const std::vector<std::string>& args, MPI_Comm comm) {
  check_options(args, {"--case", "--levels", "--out", "--preset", "--set"});
  const std::string name = option(args, "--case", "");
  if (name.empty()) throw InputError("morphfem robot ladder", "needs --case NAME");
  const std::string preset = option(args, "--preset", "voxel");
  RobotCase c = find_case(preset_cases(preset, {"voxel", "lattice-mechanics"}), name);
  for (const auto& assignment : options(args, "--set")) c.overrides.push_back(assignment);  // after the preset's
  const std::string out_dir = option(args, "--out", "results/robot/ladder");
  std::vector<std::pair<RobotCase, RobotFidelity>> jobs;
  for (const auto& l : split(option(args, "--levels", "0,1,2"))) jobs.emplace_back(c, find_robot_fidelity(l));
  const auto outcomes = run_robot_jobs(jobs, out_dir, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return 0;
  const double finest = outcomes.back().speed;
  std::string table = "case          level  mesh_m   P  max_step_s   fem_BL/s   vs_finest   wall_s   dofs  steps\n";
  std::string pick = "none";
  std::vector<Json> rows;
  char line[256];
  for (size_t j = 0; j < jobs.size(); ++j) {
    const auto& l = jobs[j].second;
    const auto& o = outcomes[j];
    const double rel = std::abs(o.speed - finest) / std::max(std::abs(finest), 1e-12);
    if (pick == "none" && o.completed > 0 && rel <= 0.05) pick = l.name;
    std::snprintf(line, sizeof line, "%-13s %5s  %6.4f  %d  %10.4g  %+10.5f  %9.2e  %7.1f  %5.0f  %5.0f%s\n",
                  c.name.c_str(), l.name.c_str(), l.mesh_size, l.order, l.max_step, o.speed, rel, o.wall_s, o.dofs,
                  o.steps, o.completed > 0 ? "" : "  FAILED");
    table += line;
    rows.push_back(outcome_json(c, l, o));
  }
  std::printf("%scheapest level within 5 %% of the finest (%s): %s\n", table.c_str(), jobs.back().second.name.c_str(),
              pick.c_str());
  std::filesystem::create_directories(out_dir);
  Json summary;
  summary.add("case", c.name)
      .add("preset", preset)
      .add("overrides", joined_options(args, "--set"))
      .add("within_5_percent_of_finest", pick)
      .add("levels", rows);
  write_file_atomic(out_dir + "/" + c.name + "_ladder.json", summary.str(true) + "\n");
  return 0;
}

// The voxel study's friction sweep: rows (low, high, distance, time, BLs).
std::vector<std::array<double, 3>> read_sfrict(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot read the voxel study's friction sweep");
  std::vector<std::array<double, 3>> rows;  // low, high, BL/s
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 || line.empty()) continue;  // header
    std::array<double, 5> v{};
    std::stringstream s(line);
    std::string cell;
    for (int i = 0; i < 5; ++i) {
      if (!std::getline(s, cell, ',')) throw InputError(path + ":" + std::to_string(number), "expected 5 columns");
      try {
        v[i] = std::stod(cell);
      } catch (const std::exception&) {
        throw InputError(path + ":" + std::to_string(number), "not a number: '" + cell + "'");
      }
    }
    rows.push_back({v[0], v[1], v[4]});
  }
  if (rows.empty()) throw InputError(path, "no data rows");
  return rows;
}

int friction_sweep(const std::vector<std::string>& args, MPI_Comm comm) {
  check_options(args, {"--fidelity", "--points", "--out"});
  const RobotFidelity& level = find_robot_fidelity(option(args, "--fidelity", "0"));
  const std::string out_dir = option(args, "--out", "results/robot/friction_sweep");
  const std::string data = source_dir() + "/../shared/data/voxel-study/sfrict_results.csv";
  auto rows = read_sfrict(data);
  const std::string points = option(args, "--points", "6");
  if (points != "all") {  // every k-th row, first and last included
    const int n = std::stoi(points);
    if (n < 2) throw InputError("--points", "needs at least 2 points (or 'all')");
    std::vector<std::array<double, 3>> picked;
    for (int i = 0; i < n; ++i)
      picked.push_back(rows[static_cast<size_t>(std::lround(i * (rows.size() - 1.0) / (n - 1)))]);
    rows = picked;
  }
  RobotCase inch;
  for (const auto& c : voxel_baseline_cases(source_dir()))
    if (c.name == "inch_flat") inch = c;
  std::vector<std::pair<RobotCase, RobotFidelity>> jobs;
  for (const auto& [low, high, voxel] : rows) {
    RobotCase c = inch;
    char name[64];
    std::snprintf(name, sizeof name, "inch_flat_mu%.2f_%.2f", low, high);
    c.name = name;
    c.mu_foot_inactive = std::max(low, 1e-4);  // the study's inactive value at the first point
    c.mu_foot_active = high;
    c.voxel_bl_per_s = voxel;
    jobs.emplace_back(c, level);
  }
  const auto outcomes = run_robot_jobs(jobs, out_dir, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return 0;
  std::string table = "  mu_low  mu_high  mean_mu   voxel_BL/s     fem_BL/s   wall_s  status\n";
  std::vector<Json> out_rows;
  char line[200];
  for (size_t j = 0; j < jobs.size(); ++j) {
    const RobotCase& c = jobs[j].first;
    const auto& o = outcomes[j];
    std::snprintf(line, sizeof line, "%8.2f  %7.2f  %7.2f  %+11.5f  %+11.5f  %7.1f  %s\n", rows[j][0], rows[j][1],
                  0.5 * (rows[j][0] + rows[j][1]), c.voxel_bl_per_s, o.speed, o.wall_s,
                  o.completed > 0 ? "ok" : "FAILED");
    table += line;
    Json r = outcome_json(c, level, o);
    r.add("mu_low", rows[j][0]).add("mu_high", rows[j][1]);
    out_rows.push_back(r);
  }
  std::printf("inching on flat ground against the feet's mean friction, fidelity %s\n%s", level.name.c_str(),
              table.c_str());
  std::filesystem::create_directories(out_dir);
  Json summary;
  summary.add("fidelity", level.name).add("points", out_rows);
  write_file_atomic(out_dir + "/friction_sweep.json", summary.str(true) + "\n");
  run_plot_script("plot_friction_sweep.py", {out_dir + "/friction_sweep.json", data}, "the friction sweep");
  std::printf("results: %s/friction_sweep.json, %s/friction_sweep.png\n", out_dir.c_str(), out_dir.c_str());
  return 0;
}

int benchmark(const std::vector<std::string>& args, MPI_Comm comm) {
  check_options(args, {"--fidelity", "--presets"});
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (size != 1) throw InputError("morphfem robot benchmark", "times one rank per gait: run it without mpirun");
  const std::string level = option(args, "--fidelity", "0");
  std::printf("voxel simulator (Voxelyze, 1428 voxels, 186,719 explicit steps, one thread): 136-145 s per gait\n");
  return validate(
      {"validate", "--fidelity", level, "--cases", "roll_flat,roll_hill15,inch_flat,inch_hill15", "--presets",
       option(args, "--presets", "voxel,physical"), "--out", "results/robot/benchmark_L" + level},
      comm);
}

int morph(const std::vector<std::string>& args, MPI_Comm comm) {
  check_options(args, {"--scene", "--out", "--set"});
  const std::string path = option(args, "--scene", source_dir() + "/examples/voxel/morph.yaml");
  YAML::Node doc = load_scene_yaml(path);
  for (const std::string& assignment : options(args, "--set")) set_scene_key(doc, assignment, path);
  Scene scene = scene_from_yaml(doc, path);
  if (scene.cavities.empty() && scene.gas_cavities.empty())
    throw InputError(path, "morph needs a pressurised core (loads.cavities or loads.gas_cavities)");
  const std::string out_dir =
      option(args, "--out", scene.output_dir.empty() ? "results/robot/morph" : scene.output_dir);
  scene.output_dir = out_dir;
  struct Sample {
    double t, p, width, length, thickness;
  };
  std::vector<Sample> samples;
  RunOptions options;
  options.on_step = [&](double t, const Mesh& mesh, const RowMatrixXd& u, const SimulationResult& r) {
    const Eigen::Vector3d e = cross_section_extents(mesh, u);
    samples.push_back({t, r.cavity_pressure.at(0), e.x(), e.y(), e.z()});
  };
  const SimulationResult r = run_scene(scene, comm, options);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return r.stats.completed ? 0 : 3;
  std::string csv = "time_s,core_pressure_pa,width_m,length_m,thickness_m,width_over_thickness\n";
  std::string table = "    t [s]  core [Pa]  width [cm]  thickness [cm]  width/thickness\n";
  char line[200];
  double last_p = -1;
  for (size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", s.t, s.p, s.width, s.length, s.thickness,
                  s.width / s.thickness);
    csv += line;
    // The table: the first sample, every 1 kPa change of pressure, the last sample.
    if (i == 0 || i + 1 == samples.size() || std::abs(s.p - last_p) >= 999.0) {
      std::snprintf(line, sizeof line, "%9.3f  %9.0f  %10.2f  %14.2f  %15.2f\n", s.t, s.p, 100 * s.width,
                    100 * s.thickness, s.width / s.thickness);
      table += line;
      last_p = s.p;
    }
  }
  std::fputs(table.c_str(), stdout);
  if (!r.stats.completed) std::printf("run failed: %s\n", r.stats.failure.c_str());
  if (!r.output_dir.empty()) {
    write_file_atomic(r.output_dir + "/morph.csv", csv);
    run_plot_script("plot_morph.py", {r.output_dir + "/morph.csv"}, "the shape change");
    std::printf("results: %s/morph.csv, %s/morph.png\n", r.output_dir.c_str(), r.output_dir.c_str());
  }
  return r.stats.completed ? 0 : 3;
}

}  // namespace

Eigen::Vector3d cross_section_extents(const Mesh& mesh, const RowMatrixXd& u) {
  const double y0 = mesh.X.col(1).minCoeff(), y1 = mesh.X.col(1).maxCoeff(), mid = 0.5 * (y0 + y1);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  double ylo = 1e300, yhi = -1e300;
  for (int n = 0; n < mesh.n_nodes(); ++n) {
    const Eigen::Vector3d x = mesh.X.row(n).transpose() + u.row(n).transpose();
    ylo = std::min(ylo, x.y());
    yhi = std::max(yhi, x.y());
    if (std::abs(mesh.X(n, 1) - mid) > 0.1 * (y1 - y0)) continue;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return {hi.x() - lo.x(), yhi - ylo, hi.z() - lo.z()};
}

int robot_main(const std::vector<std::string>& args, MPI_Comm comm) {
  if (args.empty() || args[0] == "--help" || args[0] == "-h") {
    std::fputs(kRobotUsage, stdout);
    return args.empty() ? 2 : 0;
  }
  if (args[0] == "validate") return validate(args, comm);
  if (args[0] == "ladder") return ladder(args, comm);
  if (args[0] == "morph") return morph(args, comm);
  if (args[0] == "friction-sweep") return friction_sweep(args, comm);
  if (args[0] == "benchmark") return benchmark(args, comm);
  if (args[0] == "friction-drag") return robot_friction_drag(args, comm);
  if (args[0] == "spread") return robot_spread(args, comm);
  if (args[0] == "levels") {
    for (const auto& l : robot_fidelity_levels())
      std::printf("level %s: mesh_size %.4g m, P%d, max_step %.4g s\n", l.name.c_str(), l.mesh_size, l.order,
                  l.max_step);
    return 0;
  }
  throw InputError("morphfem robot", "unknown command '" + args[0] + "'\n" + kRobotUsage);
}

}  // namespace morphfem
