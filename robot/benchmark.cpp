// `morphfem robot benchmark` (robot/studies.h): each hand-designed gait run on this one
// rank, with its cost (wall time, dofs, steps, Newton iterations, factorisations), its
// speed beside the reference speed of its preset and level, and where the time went
// (PETSc's log, fem/profile.h).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "fem/profile.h"
#include "robot/robot_study.h"
#include "robot/studies.h"

namespace morphfem {

namespace {

// The speed a gait gave at a level before [BL/s], which a faster build must keep: within
// `tolerance` (relative) for a regular gait, within the ensemble's spread for a chaotic
// one. Measured with `morphfem robot benchmark --presets lattice-mechanics --fidelity
// 0.02:2:0.1` (docs/benchmarks.md).
struct ReferenceSpeed {
  const char* preset;
  const char* level;
  const char* gait;
  double speed;
  double tolerance;  // relative; for a chaotic gait: the ensemble's standard deviation [BL/s]
  bool chaotic;
};

constexpr ReferenceSpeed kReferences[] = {
    {"lattice-mechanics", "0.02:2:0.1", "roll_flat", 0.17875, 0.01, false},
    {"lattice-mechanics", "0.02:2:0.1", "roll_hill15", -1.02, 0.24, true},  // three headings
    {"lattice-mechanics", "0.02:2:0.1", "inch_flat", 0.0779, 0.01, false},
    {"lattice-mechanics", "0.02:2:0.1", "inch_hill15", 0.0667, 0.01, false},
};

std::optional<ReferenceSpeed> reference_speed(const std::string& preset, const std::string& level,
                                              const std::string& gait) {
  for (const ReferenceSpeed& r : kReferences)
    if (preset == r.preset && level == r.level && gait == r.gait) return r;
  return std::nullopt;
}

struct GaitCost {
  std::string preset, gait;
  SimulationResult result;
  ProfileSnapshot spent;
  long factorisations = 0;
};

// Numeric factorisations: MUMPS's LDL^T (Cholesky events) or LU.
long numeric_factorisations(const ProfileSnapshot& s) { return s.count("MatCholFctrNum") + s.count("MatLUFactorNum"); }

// The split of a gait's wall time into disjoint parts of the solver [s]: Hessian
// assembly (SNESJacobianEval), the factorisation (symbolic and numeric), the
// triangular solves (KSPSolve), the energies the line search evaluates (LSEnergy), the
// gradients (SNESFunctionEval), output and checkpoints; the rest (mesh, setup, step
// control, max_step) is what none of them covers.
std::string time_split(const ProfileSnapshot& s, double wall_s) {
  struct Part {
    const char* label;
    double seconds;
  };
  const double factor = s.seconds("MatCholFctrSym") + s.seconds("MatCholFctrNum") + s.seconds("MatLUFactorSym") +
                        s.seconds("MatLUFactorNum");
  const Part parts[] = {{"Hessian", s.seconds("SNESJacobianEval")},
                        {"factor", factor},
                        {"solve", s.seconds("KSPSolve")},
                        {"line-search energies", s.seconds("LSEnergy")},
                        {"gradient", s.seconds("SNESFunctionEval")},
                        {"output", s.seconds("OutputStep") + s.seconds("StateFileWrite")}};
  std::string out;
  double covered = 0;
  char cell[80];
  for (const Part& p : parts) {
    covered += p.seconds;
    std::snprintf(cell, sizeof cell, "%s %.1f s (%.0f %%), ", p.label, p.seconds, 100 * p.seconds / wall_s);
    out += cell;
  }
  std::snprintf(cell, sizeof cell, "other %.1f s (%.0f %%)", wall_s - covered, 100 * (wall_s - covered) / wall_s);
  return out + cell;
}

// "+0.3 %" against a regular gait's reference, "within 1 sd" for a chaotic one, "-"
// without a reference.
std::string against_reference(const std::optional<ReferenceSpeed>& ref, double speed) {
  if (!ref) return "-";
  char out[64];
  if (ref->chaotic) {
    const double sds = std::abs(speed - ref->speed) / ref->tolerance;
    std::snprintf(out, sizeof out, "%.1f sd of %+.2f%s", sds, ref->speed, sds <= 1 ? "" : " OUTSIDE");
  } else {
    const double rel = speed / ref->speed - 1;
    std::snprintf(out, sizeof out, "%+.2f %% of %+.4f%s", 100 * rel, ref->speed,
                  std::abs(rel) <= ref->tolerance ? "" : " OUTSIDE");
  }
  return out;
}

Json gait_json(const GaitCost& g, const RobotFidelity& level, const std::optional<ReferenceSpeed>& ref) {
  const SimulationResult& r = g.result;
  Json row;
  row.add("preset", g.preset)
      .add("gait", g.gait)
      .add("fidelity", level.name)
      .add("completed", r.stats.completed && r.gait_complete)
      .add("speed_bl_per_s", r.speed_bl_per_s)
      .add("wall_s", r.stats.wall_s)
      .add("dofs", static_cast<double>(r.dofs))
      .add("steps", r.stats.steps)
      .add("newton_its", r.stats.newton_its)
      .add("step_cuts", r.stats.step_cuts)
      .add("factorisations", static_cast<double>(g.factorisations));
  if (ref) row.add("reference_bl_per_s", ref->speed).add("reference_chaotic", ref->chaotic);
  Json events;
  for (const ProfileEvent& e : g.spent.events)
    if (e.count > 0) events.add(e.name, Json().add("seconds", e.seconds).add("count", static_cast<double>(e.count)));
  row.add("events", events);
  return row;
}

}  // namespace

int robot_benchmark(const BenchmarkOptions& o, MPI_Comm comm) {
  int size = 1;
  MPI_Comm_size(comm, &size);
  if (size != 1) throw InputError("morphfem robot benchmark", "times one rank per gait: run it without mpirun");
  const RobotFidelity& level = find_robot_fidelity(o.fidelity);
  const std::vector<std::string>& gaits = o.gaits;
  std::vector<std::vector<RobotCase>> preset_sets;
  for (const auto& preset : o.presets)
    preset_sets.push_back(preset_cases(preset, {"voxel", "lattice-mechanics", "physical"}));
  const std::string out_dir = "results/robot/benchmark_L" + level.name;
  start_profiling();
  std::printf("voxel simulator (Voxelyze, 1428 voxels, 186,719 explicit steps, one thread): 136-145 s per gait\n");
  std::printf("fidelity %s: mesh %.4g m, P%d, max step %.4g s\n", level.name.c_str(), level.mesh_size, level.order,
              level.max_step);
  std::printf("%-18s %-12s %8s %6s %6s %7s %7s %10s  %s\n", "preset", "gait", "wall_s", "dofs", "steps", "newton",
              "factor", "BL/s", "against the reference");
  std::vector<Json> rows;
  for (size_t p = 0; p < o.presets.size(); ++p) {
    for (const auto& gait : gaits) {
      GaitCost g{o.presets[p], gait, {}, {}, 0};
      const RobotCase& c = find_case(preset_sets[p], gait);
      const std::string dir = out_dir + "/" + case_folder(c, level);
      const ProfileSnapshot before = profile_snapshot();
      g.result = run_robot_case(c, level, dir, PETSC_COMM_SELF, true);
      g.spent = profile_snapshot() - before;
      g.factorisations = numeric_factorisations(g.spent);
      const auto ref = reference_speed(g.preset, level.name, gait);
      const SimulationResult& r = g.result;
      std::printf("%-18s %-12s %8.1f %6ld %6d %7d %7ld %+10.5f  %s%s\n", g.preset.c_str(), gait.c_str(), r.stats.wall_s,
                  r.dofs, r.stats.steps, r.stats.newton_its, g.factorisations, r.speed_bl_per_s,
                  against_reference(ref, r.speed_bl_per_s).c_str(), r.stats.completed ? "" : "  FAILED");
      std::printf("    time: %s\n", time_split(g.spent, g.spent.wall_s).c_str());
      if (o.profile) std::fputs(profile_table(g.spent, "Newton it", r.stats.newton_its).c_str(), stdout);
      std::fflush(stdout);
      rows.push_back(gait_json(g, level, ref));
    }
  }
  std::filesystem::create_directories(out_dir);
  Json summary;
  summary.add("fidelity", level.name).add("gaits", rows);
  write_file_atomic(out_dir + "/benchmark.json", summary.str(true) + "\n");
  std::printf("results: %s/benchmark.json, per gait %s/GAIT_.../\n", out_dir.c_str(), out_dir.c_str());
  return 0;
}

}  // namespace morphfem
