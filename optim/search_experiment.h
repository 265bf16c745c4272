// The study's search experiments and the loop that runs them: climbers spread over
// MPI ranks, a checkpoint after every step and each of its evaluations saved as it
// finishes, resume from both, results in
// the voxel study's layout, re-evaluation at a validation fidelity, and the
// summary table beside the voxel study's numbers.
//
// Experiments (ROBOT.md; fixed values as in the study's worker_semi.jl /
// worker_closed.jl / worker_roll_hill.jl, jpp46/NATURE_MI2020):
//   flat_open    0 deg   orientation, pressure and rows free
//   flat_semi    0 deg   orientation fixed at 0 deg (rolling direction along the heading)
//   flat_closed  0 deg   orientation 0 deg, core 12000 Pa (the inflated cylinder)
//   hill_open   15 deg   all free
//   hill_semi   15 deg   orientation fixed at 90 deg (body length uphill)
//   hill_closed 15 deg   orientation 90 deg, core 0 Pa (the flat inchworm)
//   roll_hill   15 deg   control experiment: inflated robot (12000 Pa) width-wise (0 deg) on the hill
//
// Output (DIR = --out):
//   DIR/<experiment>/<method>/<experiment>.csv   best speed so far, "g,f_1,...,f_N", rows g = 0..G
//   DIR/<experiment>/<method>/checkpoint.h5      full state after the last completed step
//   DIR/<experiment>/<method>/partial_team_K.h5  evaluations of the unfinished step so far
//                                                (optim/search_partial.h; gone when it completes)
//   DIR/<experiment>/<method>/best/climber_NN.yaml   final best genome as a schedule file
//   DIR/<experiment>/<method>/validation.csv     search vs validation speed per climber (if asked)
//   DIR/summary.md, DIR/summary.json             the table; summary.json also drives the plots
#pragma once
#include <mpi.h>

#include <cstdint>
#include <string>
#include <vector>

#include "optim/fitness.h"
#include "optim/genome.h"
#include "optim/search_method.h"
#include "optim/search_parallel.h"

namespace morphfem {

struct ExperimentSpec {
  std::string name;
  std::string description;
  Environment env;
  GenomeSpace space;
  std::string voxel_csv;  // file of the voxel study with the same experiment ("" if none)
};

const std::vector<ExperimentSpec>& search_experiments();
// Throws InputError naming the known experiments.
const ExperimentSpec& find_experiment(const std::string& name);

struct SearchOptions {
  std::vector<std::string> experiments = {"flat_open", "hill_open"};
  std::vector<std::string> methods = {"hill"};
  int climbers = 4;
  int generations = 10;
  std::uint64_t seed = 1;
  std::string fitness = "synthetic";
  std::string fidelity = "0";
  std::string validate_fidelity;  // "" = no validation
  int ranks_per_sim = 1;
  int eval_delay_ms = 0;  // sleep before every evaluation (tests of kill/resume)
  std::string out_dir = "results/search";
  std::string voxel_dir;  // the voxel study's CSVs ("" = no comparison)
  bool restart = false;   // ignore (delete) existing checkpoints
  bool progress = true;
  bool hand_designed = true;  // evaluate the study's rolling and inching schedules for the table
};

struct ExperimentResult {
  std::string experiment, method, dir, csv;
  int climbers = 0, generations = 0;
  std::vector<std::vector<double>> history;  // [g][climber]
  std::vector<Genome> best;
  std::vector<double> best_speed;
  std::vector<double> validation_speed;  // empty without validation
  double spearman = 0, kendall = 0;
  long evaluations = 0;          // all climbers, whole run
  long evaluations_timed = 0;    // evaluated in this session
  long evaluations_reused = 0;   // saved by a killed session part way through a step (optim/search_partial.h)
  double evaluation_wall_s = 0;  // wall time of this session's evaluations
  bool resumed = false;
};

struct HandDesignedResult {
  std::string name;  // "rolling" / "inching"
  Genome genome;
  std::string environment;
  double speed = 0, validation_speed = 0;
};

struct SearchReport {
  std::vector<ExperimentResult> results;
  std::vector<HandDesignedResult> hand_designed;
  int ranks = 1, teams = 1;
  // Measured cost: wall seconds per evaluation of one team (ranks_per_sim ranks).
  double seconds_per_evaluation = 0;
};

// The metadata a checkpoint (and a partial step file) shares with the run that
// resumes it: format, seed, climbers, experiment, method, fitness, fidelity.
SearchState search_metadata(const ExperimentSpec& spec, const std::string& method, const SearchOptions& options);

// Runs every (experiment, method) of `options` on all ranks of `comm`; rank 0
// writes the files. Throws InputError for bad options or a mismatched checkpoint.
SearchReport run_search(const SearchOptions& options, MPI_Comm comm);

// "g,f_1,...,f_N" then one row per generation; numbers in shortest round-trip form.
std::string history_csv(const std::vector<std::vector<double>>& history);
// Reads a file in that layout (the voxel study's CSVs); throws InputError with file:line.
std::vector<std::vector<double>> read_history_csv(const std::string& path);

// The table (markdown) and the machine-readable summary.
std::string summary_markdown(const SearchReport& report, const SearchOptions& options);
std::string summary_json(const SearchReport& report, const SearchOptions& options);

}  // namespace morphfem
