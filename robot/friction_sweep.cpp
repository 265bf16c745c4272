// `morphfem robot friction-sweep` (robot/studies.h): inching on flat ground against the
// feet's mean friction, beside the voxel study's sweep (sfrict_results.csv).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "core/plot.h"
#include "robot/robot_study.h"
#include "robot/studies.h"

namespace morphfem {

namespace {

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

}  // namespace

int robot_friction_sweep(const FrictionSweepOptions& o, MPI_Comm comm) {
  const RobotFidelity& level = find_robot_fidelity(o.fidelity);
  const std::string& out_dir = o.out_dir;
  const std::string data = shared_data_dir() + "/voxel-study/sfrict_results.csv";
  auto rows = read_sfrict(data);
  if (o.points != "all") {  // every k-th row, first and last included
    const int n = std::atoi(o.points.c_str());
    if (n < 2 || std::to_string(n) != o.points)
      throw InputError("--points", "'" + o.points + "': needs a whole number of at least 2 points (or 'all')");
    std::vector<std::array<double, 3>> picked;
    for (int i = 0; i < n; ++i)
      picked.push_back(rows[static_cast<size_t>(std::lround(i * (rows.size() - 1.0) / (n - 1)))]);
    rows = picked;
  }
  RobotCase inch;
  for (const auto& c : voxel_baseline_cases(resource_dir()))
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

}  // namespace morphfem
