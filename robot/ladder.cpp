// `morphfem robot ladder` (robot/studies.h): one case on several fidelity levels.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/json.h"
#include "core/strings.h"
#include "robot/robot_study.h"
#include "robot/studies.h"

namespace morphfem {

int robot_ladder(const LadderOptions& o, MPI_Comm comm) {
  if (o.case_name.empty()) throw InputError("morphfem robot ladder", "needs --case NAME");
  RobotCase c = find_case(preset_cases(o.preset, {"voxel", "lattice-mechanics"}), o.case_name);
  c.overrides.insert(c.overrides.end(), o.set.begin(), o.set.end());  // after the preset's
  std::vector<std::pair<RobotCase, RobotFidelity>> jobs;
  for (const auto& l : o.levels) jobs.emplace_back(c, find_robot_fidelity(l));
  if (jobs.empty()) throw InputError("--levels", "no level given");
  const auto outcomes = run_robot_jobs(jobs, o.out_dir, comm);
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
    const auto& out = outcomes[j];
    const double rel = std::abs(out.speed - finest) / std::max(std::abs(finest), 1e-12);
    if (pick == "none" && out.completed > 0 && rel <= 0.05) pick = l.name;
    std::snprintf(line, sizeof line, "%-13s %5s  %6.4f  %d  %10.4g  %+10.5f  %9.2e  %7.1f  %5.0f  %5.0f%s\n",
                  c.name.c_str(), l.name.c_str(), l.mesh_size, l.order, l.max_step, out.speed, rel, out.wall_s,
                  out.dofs, out.steps, out.completed > 0 ? "" : "  FAILED");
    table += line;
    rows.push_back(outcome_json(c, l, out));
  }
  std::printf("%scheapest level within 5 %% of the finest (%s): %s\n", table.c_str(), jobs.back().second.name.c_str(),
              pick.c_str());
  std::filesystem::create_directories(o.out_dir);
  Json summary;
  summary.add("case", c.name)
      .add("preset", o.preset)
      .add("overrides", join(o.set, "; "))
      .add("within_5_percent_of_finest", pick)
      .add("levels", rows);
  write_file_atomic(o.out_dir + "/" + c.name + "_ladder.json", summary.str(true) + "\n");
  return 0;
}

}  // namespace morphfem
