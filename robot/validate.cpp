// `morphfem robot validate` (robot/studies.h): the voxel study's baselines on each
// preset, as a table and validation.json; `robot levels`.
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "core/strings.h"
#include "robot/robot_study.h"
#include "robot/studies.h"

namespace morphfem {

namespace {

using Jobs = std::vector<std::pair<RobotCase, RobotFidelity>>;

struct Presets {
  bool voxel = false, lattice = false, physical = false;
};

Presets read_presets(const std::vector<std::string>& names) {
  Presets p;
  for (const auto& name : names) {
    if (name == "voxel")
      p.voxel = true;
    else if (name == "lattice-mechanics")
      p.lattice = true;
    else if (name == "physical")
      p.physical = true;
    else
      throw InputError("--presets", "unknown preset '" + name + "' (known: voxel, lattice-mechanics, physical)");
  }
  return p;
}

// The cases of each preset with the options' scene keys: the voxel-study preset with
// --set, the lattice-mechanics preset with its own keys then --set, the physical
// templates with --set-physical then their own (round or flat) keys.
struct PresetCases {
  std::vector<RobotCase> voxel, lattice, physical;
};

PresetCases preset_cases_with_keys(const ValidateOptions& o) {
  PresetCases c;
  c.voxel = voxel_baseline_cases(resource_dir());
  for (auto& k : c.voxel) k.overrides = o.set;
  c.lattice = lattice_mechanics_cases(resource_dir());
  for (auto& k : c.lattice) k.overrides.insert(k.overrides.end(), o.set.begin(), o.set.end());
  c.physical = physical_baseline_cases(resource_dir());
  for (auto& k : c.physical) {
    k.overrides = o.set_physical;
    const auto& own = k.schedule.core_pressure_pa > 0 ? o.set_physical_round : o.set_physical_flat;
    k.overrides.insert(k.overrides.end(), own.begin(), own.end());
  }
  return c;
}

// The voxel-preset jobs, the lattice-mechanics ones, then the physical ones; each row
// of the table pairs them by name.
Jobs validation_jobs(const std::vector<std::string>& names, const Presets& p, const PresetCases& cases,
                     const RobotFidelity& level) {
  Jobs jobs;
  for (const auto& name : names)
    if (p.voxel) jobs.emplace_back(find_case(cases.voxel, name), level);
  for (const auto& name : names)
    if (p.lattice) jobs.emplace_back(find_case(cases.lattice, name), level);
  for (const auto& name : names)
    for (const auto& c : cases.physical)
      if (p.physical && c.name == name) jobs.emplace_back(c, level);
  return jobs;
}

int find_job(const Jobs& jobs, const std::string& name, bool physical, bool lattice_mechanics) {
  for (size_t j = 0; j < jobs.size(); ++j)
    if (jobs[j].first.name == name && jobs[j].first.physical == physical &&
        jobs[j].first.lattice_mechanics == lattice_mechanics)
      return static_cast<int>(j);
  return -1;
}

// A further preset's cells (speed, wall time) and its JSON row.
std::string preset_cells(const Jobs& jobs, const std::vector<CaseOutcome>& outcomes, int j, int speed_width,
                         int wall_width, const char* preset, const RobotFidelity& level, std::vector<Json>& rows) {
  const auto& o = outcomes[j];
  char buf[96];
  std::snprintf(buf, sizeof buf, "%+*.5f  %*.1f%s", speed_width, o.speed, wall_width, o.wall_s,
                o.completed > 0 ? "" : " FAILED");
  Json row = outcome_json(jobs[j].first, level, o);
  row.add("preset", preset);
  if (jobs[j].first.physical) row.add("template", jobs[j].first.template_scene);
  rows.push_back(row);
  return buf;
}

// The table, one row per case name, and the JSON rows.
std::string validation_table(const std::vector<std::string>& names, const Jobs& jobs,
                             const std::vector<CaseOutcome>& outcomes, const PresetCases& cases, bool lattice,
                             const RobotFidelity& level, std::vector<Json>& rows) {
  std::string table =
      "case                       slope  orient  core_Pa   voxel_BL/s      fem_BL/s   wall_s   dofs  "
      "steps  newton  status   phys_BL/s  phys_wall_s" +
      std::string(lattice ? "  lattmech_BL/s  lattmech_wall_s" : "") + "\n";
  for (const auto& name : names) {
    const int jv = find_job(jobs, name, false, false), jp = find_job(jobs, name, true, false),
              jl = find_job(jobs, name, false, true);
    const RobotCase& c = jv >= 0 ? jobs[jv].first : find_case(cases.voxel, name);
    std::string fem = "          -        -      -      -       -  -     ", phys = "        n/a          -";
    if (jv >= 0) {
      const auto& o = outcomes[jv];
      char buf[160];
      std::snprintf(buf, sizeof buf, "%+11.5f  %7.1f  %5.0f  %5.0f  %6.0f  %-6s", o.speed, o.wall_s, o.dofs, o.steps,
                    o.newton, o.completed > 0 ? "ok" : "FAILED");
      fem = buf;
      rows.push_back(outcome_json(c, level, o));
    }
    if (jp >= 0) phys = preset_cells(jobs, outcomes, jp, 11, 11, "physical", level, rows);
    const std::string lattmech =
        jl >= 0 ? "  " + preset_cells(jobs, outcomes, jl, 13, 15, "lattice-mechanics", level, rows) : "";
    char line[320];
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
        "12.5x stiffer and with the lattice's mass (robot/robot_study.h, lattice_mechanics_overrides); linear\n"
        "tetrahedra lock in bending and do not roll with it: use order 2 (e.g. --fidelity 0.02:2:0.05).\n";
  return table;
}

void write_validation(const ValidateOptions& o, const RobotFidelity& level, const std::string& table,
                      const std::vector<Json>& rows) {
  std::filesystem::create_directories(o.out_dir);
  std::vector<std::string> physical_assignments;  // "set-physical KEY=VALUE", ...
  for (const auto& [flag, keys] :
       {std::pair{"set-physical", &o.set_physical}, std::pair{"set-physical-round", &o.set_physical_round},
        std::pair{"set-physical-flat", &o.set_physical_flat}})
    for (const auto& assignment : *keys) physical_assignments.push_back(std::string(flag) + " " + assignment);
  Json summary;
  summary.add("fidelity", level.name)
      .add("overrides", join(o.set, "; "))
      .add("physical_overrides", join(physical_assignments, "; "))
      .add("cases", rows);
  write_file_atomic(o.out_dir + "/validation.json", summary.str(true) + "\n");
  write_file_atomic(o.out_dir + "/validation.txt", table);
}

}  // namespace

int robot_validate(const ValidateOptions& o, MPI_Comm comm) {
  const RobotFidelity& level = find_robot_fidelity(o.fidelity);
  const Presets presets = read_presets(o.presets);
  const PresetCases cases = preset_cases_with_keys(o);
  std::vector<std::string> names;
  for (const auto& c : cases.voxel) names.push_back(c.name);
  if (!o.cases.empty()) {
    names = o.cases;
    for (const auto& name : names) find_case(cases.voxel, name);  // refuses unknown names
  }
  const Jobs jobs = validation_jobs(names, presets, cases, level);
  const auto outcomes = run_robot_jobs(jobs, o.out_dir, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return 0;
  std::vector<Json> rows;
  const std::string table = validation_table(names, jobs, outcomes, cases, presets.lattice, level, rows);
  std::printf("fidelity %s: mesh %.4g m, P%d, max step %.4g s\n%s", level.name.c_str(), level.mesh_size, level.order,
              level.max_step, table.c_str());
  write_validation(o, level, table, rows);
  std::printf(
      "results: %s/validation.json, per case %s/CASE_L%s/ (physical: CASE_physical/, lattice mechanics: "
      "CASE_lattice_L%s/)\n",
      o.out_dir.c_str(), o.out_dir.c_str(), level.name.c_str(), level.name.c_str());
  return 0;
}

int robot_levels() {
  for (const auto& l : robot_fidelity_levels())
    std::printf("level %s: mesh_size %.4g m, P%d, max_step %.4g s\n", l.name.c_str(), l.mesh_size, l.order, l.max_step);
  return 0;
}

}  // namespace morphfem
