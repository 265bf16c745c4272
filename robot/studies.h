// The robot's studies, one per `morphfem robot` command (app/robot_cli.cpp parses the
// command line into these options): each runs its cases (spread over the MPI ranks,
// one rank per case), prints a table on rank 0, writes a JSON summary (and CSV, PNG
// where it has them) under `out_dir`, and returns the exit status. Bad options
// (unknown case, preset or level) throw InputError before any case runs.
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

namespace morphfem {

// The voxel study's baselines: voxel speed beside the finite-element speed of each
// preset ("voxel", "lattice-mechanics", "physical"), wall time, dofs, steps.
struct ValidateOptions {
  std::string fidelity = "0";
  std::vector<std::string> cases;  // empty: all eight baselines
  std::vector<std::string> presets = {"voxel", "physical"};
  std::string out_dir = "results/robot/validate";
  std::vector<std::string> set;                 // scene keys set last on the voxel-study presets
  std::vector<std::string> set_physical;        // ... on both physical templates
  std::vector<std::string> set_physical_round;  // ... on the inflated (rolling) one
  std::vector<std::string> set_physical_flat;   // ... on the flat (inching) one
};
int robot_validate(const ValidateOptions& options, MPI_Comm comm);

// One case on several fidelity levels: speed against wall time, and the cheapest
// level within 5 % of the finest.
struct LadderOptions {
  std::string case_name;
  std::vector<std::string> levels = {"0", "1", "2"};
  std::string preset = "voxel";  // voxel | lattice-mechanics
  std::string out_dir = "results/robot/ladder";
  std::vector<std::string> set;
};
int robot_ladder(const LadderOptions& options, MPI_Comm comm);

// One case run once per value of one scene key (a perturbation ensemble) on each level:
// the speeds' mean, standard deviation and range (robot/robot_spread.cpp).
struct SpreadOptions {
  std::string case_name;
  std::string vary;                 // KEY=V1,V2,...
  std::vector<std::string> levels;  // empty: "0" (voxel presets) or the templates' own (physical)
  std::string preset = "voxel";     // voxel | lattice-mechanics | physical
  std::string out_dir;              // empty: results/robot/spread_CASE
  std::vector<std::string> set;
};
int robot_spread(const SpreadOptions& options, MPI_Comm comm);

// Shape change under core pressure: the mid-length cross-section's width and
// thickness against the core pressure.
struct MorphOptions {
  std::string scene;    // empty: examples/voxel/morph.yaml
  std::string out_dir;  // empty: the scene's output.directory, else results/robot/morph
  std::vector<std::string> set;
};
int robot_morph(const MorphOptions& options, MPI_Comm comm);

// Inching on flat ground against the feet's mean friction, beside the voxel study's
// friction sweep.
struct FrictionSweepOptions {
  std::string fidelity = "0";
  std::string points = "6";  // "all" or the number of rows picked evenly
  std::string out_dir = "results/robot/friction_sweep";
};
int robot_friction_sweep(const FrictionSweepOptions& options, MPI_Comm comm);

// The test-machine pull test on a robot scene with its feet in each state
// (robot/robot_drag.cpp).
struct FrictionDragOptions {
  std::string scene;  // empty: examples/physical/friction_drag.yaml
  std::vector<std::string> feet = {"inflated", "deflated"};
  std::string travel_mm;  // empty: the scene's
  std::string surface = "wood";
  std::string out_dir = "results/robot/friction_drag";
  std::vector<std::string> set;
};
int robot_friction_drag(const FrictionDragOptions& options, MPI_Comm comm);

// Each hand-designed gait on this one rank: wall time, dofs, steps, Newton iterations,
// factorisations, the speed against its preset's reference at that level, and the
// split of the time (Hessian, factorisation, solves, line search, gradient, output);
// with `profile`, every logged event (fem/profile.h). benchmark.json holds it all.
struct BenchmarkOptions {
  std::string fidelity = "0";
  std::vector<std::string> presets = {"voxel", "physical"};
  std::vector<std::string> gaits = {"roll_flat", "roll_hill15", "inch_flat", "inch_hill15"};
  bool profile = false;
};
int robot_benchmark(const BenchmarkOptions& options, MPI_Comm comm);

// The scene file of one case, as `robot validate` runs it (the template with the case's
// schedule, slope, fidelity level, the preset's keys and `set`), written to out_file
// (or standard output if empty) for `morphfem run`: the gait examples are these files.
struct SceneFileOptions {
  std::string case_name;
  std::string preset = "voxel";  // voxel | lattice-mechanics | physical
  std::string fidelity = "0";    // ignored by the physical preset (the template's own)
  std::string output_dir;        // the scene's output.directory (empty: results/CASE)
  std::string out_file;
  std::vector<std::string> set;
};
int robot_scene_file(const SceneFileOptions& options);

// The fidelity levels, one line each.
int robot_levels();

}  // namespace morphfem
