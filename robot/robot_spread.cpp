// `morphfem robot spread` (robot_study.h): how far one run's speed can be trusted.
//
// Some gaits are chaotic: the robot tumbling down the 15 deg hill comes to rest on
// one bladder or another, and a 1 % change of the mesh or the time step moves its
// speed by a factor of two (docs/validation.md, "Rolling down the 15 deg hill"). One run per fidelity level
// is then a sample, not a measurement, and a ladder of single runs cannot say which
// level is converged. This command runs the case once per value of one scene key (the
// perturbation: the heading on the hill, the time step, the column length, ...), on
// each level, and reports per level
//   mean        m = sum(v_i) / n                     [BL/s]
//   std         s = sqrt(sum (v_i - m)^2 / (n - 1))  (sample standard deviation)
//   standard error of the mean  s / sqrt(n)
//   range, and how many runs moved forward (v > 0);
// and compares each level's mean with the finest level's (the last given): the
// relative difference, and whether the difference lies within two standard errors of
// the difference, sqrt(s_l^2 / n_l + s_f^2 / n_f), i.e. whether the ensembles can tell
// the two levels apart at all. Runs that fail are listed and left out of the statistics.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "core/command_line.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/plot.h"
#include "core/strings.h"
#include "optim/search_stats.h"
#include "robot/robot_study.h"
#include "robot/studies.h"

namespace morphfem {

std::pair<std::string, std::vector<std::string>> parse_variation(const std::string& spec) {
  const size_t eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--vary", "'" + spec + "' is not KEY=V1,V2,... (e.g. environment.heading_deg=-1,0,1)");
  const std::string key = spec.substr(0, eq);
  const std::vector<std::string> values = split_list(spec.substr(eq + 1));
  if (values.size() < 2)
    throw InputError("--vary " + key,
                     "needs at least two values to measure a spread, got " + std::to_string(values.size()));
  std::set<std::string> seen;
  for (const auto& v : values)
    if (!seen.insert(v).second)
      throw InputError("--vary " + key, "value '" + v + "' is given twice (the same run twice adds nothing)");
  return {key, values};
}

SpreadStats spread_stats(const std::vector<CaseOutcome>& runs) {
  SpreadStats s;
  std::vector<double> v;
  for (const auto& o : runs) {
    if (o.completed > 0)
      v.push_back(o.speed);
    else
      ++s.failed;
  }
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  s.mean = mean_of(v);
  s.std = v.size() > 1 ? sample_std(v) : NAN;
  std::sort(v.begin(), v.end());
  s.min = v.front();
  s.max = v.back();
  const size_t h = v.size() / 2;
  s.median = v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
  s.forward = static_cast<int>(std::count_if(v.begin(), v.end(), [](double x) { return x > 0; }));
  return s;
}

std::vector<std::pair<RobotCase, RobotFidelity>> spread_jobs(const RobotCase& base,
                                                             const std::vector<std::string>& sets,
                                                             const std::string& key,
                                                             const std::vector<std::string>& values,
                                                             const std::vector<RobotFidelity>& levels) {
  std::vector<std::pair<RobotCase, RobotFidelity>> jobs;
  for (const auto& level : levels)
    for (size_t k = 0; k < values.size(); ++k) {
      RobotCase c = base;  // its own folder, CASE_vK_L<level>
      c.name = base.name + "_v" + std::to_string(k);
      c.overrides.insert(c.overrides.end(), sets.begin(), sets.end());
      c.overrides.push_back(key + "=" + values[k]);
      jobs.emplace_back(c, level);
    }
  return jobs;
}

namespace {

// The levels the ensemble runs on: the physical templates carry their own mesh and
// time step (a level would be ignored), the voxel-study presets the given levels.
std::vector<RobotFidelity> spread_levels(const SpreadOptions& o) {
  std::vector<RobotFidelity> levels;
  if (o.preset == "physical") {
    if (!o.levels.empty())
      throw InputError("--levels",
                       "the physical preset runs its template's own mesh and time step: vary them with "
                       "--vary or --set (e.g. --vary solver.max_step=...)");
    RobotFidelity own;
    own.name = "template";
    levels.push_back(own);
  } else {
    for (const auto& l : o.levels.empty() ? std::vector<std::string>{"0"} : o.levels)
      levels.push_back(find_robot_fidelity(l));
  }
  return levels;
}

// The ensemble's runs and statistics, level by level: the table and the JSON rows.
struct SpreadReport {
  std::string table;
  std::vector<Json> level_rows;
  std::vector<SpreadStats> stats;
};

struct Ensemble {
  const RobotCase& base;
  std::string key;
  std::vector<std::string> values;
  std::vector<RobotFidelity> levels;
  std::vector<std::pair<RobotCase, RobotFidelity>> jobs;
  bool physical = false;
};

// One level's runs: a table line per run, their JSON rows, the level's statistics.
Json level_runs(const Ensemble& e, size_t l, const std::vector<CaseOutcome>& outcomes, int width,
                SpreadReport& report) {
  const size_t n = e.values.size();
  const std::vector<CaseOutcome> mine(outcomes.begin() + static_cast<long>(l * n),
                                      outcomes.begin() + static_cast<long>((l + 1) * n));
  std::vector<Json> runs;
  double wall = 0;
  char line[400];
  for (size_t k = 0; k < n; ++k) {
    const CaseOutcome& o = mine[k];
    wall += o.wall_s;
    std::snprintf(line, sizeof line, "%-6s %-*s  %+10.5f  %+14.4f  %7.1f  %5.0f  %5.0f  %6.0f  %s\n",
                  e.levels[l].name.c_str(), width, e.values[k].c_str(), o.speed, o.displacement, o.wall_s, o.dofs,
                  o.steps, o.newton, o.completed > 0 ? "ok" : "FAILED");
    report.table += line;
    Json r = outcome_json(e.base, e.levels[l], o);
    const RobotCase& c = e.jobs[l * n + k].first;
    r.add("value", e.values[k]).add("folder", c.name + (e.physical ? "_physical" : "_L" + e.levels[l].name));
    runs.push_back(r);
  }
  report.stats.push_back(spread_stats(mine));
  const SpreadStats& s = report.stats.back();
  Json j;
  j.add("level", e.levels[l].name)
      .add("mesh_size_m", e.levels[l].mesh_size)
      .add("order", e.levels[l].order)
      .add("max_step_s", e.levels[l].max_step)
      .add("n", s.n)
      .add("failed", s.failed)
      .add("forward", s.forward)
      .add("mean_bl_per_s", s.mean)
      .add("std_bl_per_s", s.std)
      .add("standard_error_bl_per_s", s.standard_error())
      .add("median_bl_per_s", s.median)
      .add("min_bl_per_s", s.min)
      .add("max_bl_per_s", s.max)
      .add("wall_s_total", wall)
      .add("runs", runs);
  return j;
}

// Each level's statistics against the finest level's; returns the cheapest level whose
// mean is within 5 % of the finest's ("none" if no level is).
std::string compare_levels(const Ensemble& e, SpreadReport& report) {
  const SpreadStats& finest = report.stats.back();
  report.table +=
      "\nlevel   n  failed  forward       mean        std   std_err     median        min        max  mean_vs_finest  "
      "within_2_se\n";
  std::string pick = "none";
  char line[400];
  for (size_t l = 0; l < e.levels.size(); ++l) {
    const SpreadStats& s = report.stats[l];
    const double rel = std::abs(s.mean - finest.mean) / std::max(std::abs(finest.mean), 1e-12);
    const double se_diff = std::sqrt(std::pow(s.standard_error(), 2) + std::pow(finest.standard_error(), 2));
    const bool within = std::abs(s.mean - finest.mean) <= 2 * se_diff;
    if (pick == "none" && s.failed == 0 && s.n > 0 && rel <= 0.05) pick = e.levels[l].name;
    std::snprintf(line, sizeof line, "%-6s %2d  %6d  %7d  %+9.5f  %9.5f  %8.5f  %+9.5f  %+9.5f  %+9.5f  %14.3f  %s\n",
                  e.levels[l].name.c_str(), s.n, s.failed, s.forward, s.mean, s.std, s.standard_error(), s.median,
                  s.min, s.max, rel,
                  l + 1 == e.levels.size() ? "-" : (std::isfinite(se_diff) ? (within ? "yes" : "no") : "n/a"));
    report.table += line;
    report.level_rows[l].add("mean_vs_finest", rel).add("mean_within_2_standard_errors_of_finest", within);
  }
  return pick;
}

}  // namespace

int robot_spread(const SpreadOptions& o, MPI_Comm comm) {
  const std::string& name = o.case_name;
  if (name.empty() || o.vary.empty())
    throw InputError("morphfem robot spread", "needs --case NAME and --vary KEY=V1,V2,...");
  const auto [key, values] = parse_variation(o.vary);
  const auto cases = preset_cases(o.preset, {"voxel", "lattice-mechanics", "physical"});
  Ensemble e{find_case(cases, name), key, values, spread_levels(o), {}, o.preset == "physical"};
  const std::string out_dir = o.out_dir.empty() ? "results/robot/spread_" + name : o.out_dir;
  e.jobs = spread_jobs(e.base, o.set, key, values, e.levels);
  const std::vector<CaseOutcome> outcomes = run_robot_jobs(e.jobs, out_dir, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return 0;

  // The value column is as wide as the key or the longest value.
  int width = static_cast<int>(key.size());
  for (const auto& v : values) width = std::max(width, static_cast<int>(v.size()));
  char line[400];
  std::snprintf(line, sizeof line, "level  %-*s    fem_BL/s  displacement_m   wall_s   dofs  steps  newton  status\n",
                width, key.c_str());
  SpreadReport report;
  report.table = line;
  for (size_t l = 0; l < e.levels.size(); ++l) report.level_rows.push_back(level_runs(e, l, outcomes, width, report));
  const std::string pick = compare_levels(e, report);
  std::printf("case %s (%s preset), %s varied over %zu values\n%s", name.c_str(), o.preset.c_str(), key.c_str(),
              values.size(), report.table.c_str());
  if (e.levels.size() > 1)
    std::printf("cheapest level whose mean is within 5 %% of the finest's (%s): %s\n", e.levels.back().name.c_str(),
                pick.c_str());
  std::filesystem::create_directories(out_dir);
  Json summary;
  summary.add("case", name)
      .add("preset", o.preset)
      .add("varied_key", key)
      .add("overrides", join(o.set, "; "))
      .add("within_5_percent_of_finest", pick)
      .add("levels", report.level_rows);
  const std::string json = out_dir + "/" + name + "_spread.json";
  write_file_atomic(json, summary.str(true) + "\n");
  write_file_atomic(out_dir + "/" + name + "_spread.txt", report.table);
  run_plot_script("plot_spread.py", {json}, "the spread");
  std::printf("results: %s, %s/%s_spread.png, per run %s/%s_vK_%s/\n", json.c_str(), out_dir.c_str(), name.c_str(),
              out_dir.c_str(), name.c_str(), e.physical ? "physical" : "LLEVEL");
  return 0;
}

}  // namespace morphfem
