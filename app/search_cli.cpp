#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "app/commands.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "core/plot.h"
#include "optim/fitness.h"
#include "optim/search_experiment.h"
#include "optim/search_method.h"
#include "robot/robot_study.h"

namespace morphfem {

namespace {

void print_list() {
  std::printf("experiments:\n");
  for (const auto& e : search_experiments()) std::printf("  %-12s %s\n", e.name.c_str(), e.description.c_str());
  std::printf("methods:\n");
  for (const auto& m : search_method_names()) std::printf("  %s\n", m.c_str());
  std::printf("fitnesses:\n");
  for (const auto& f : fitness_descriptions()) std::printf("  %s\n", f.c_str());
}

CommandLine search_command_line() {
  CommandLine cl("morphfem search", "[options] [PETSc options]",
                 "Hill climbing (the voxel study's climber) or CMA-ES over shape, orientation and schedule on a "
                 "registered fitness, experiment by experiment; a table against the voxel study, JSON, CSV per "
                 "climber, checkpoints and PNG curves.");
  cl.value("--experiments", "A,B,...",
           "flat_open, flat_semi, flat_closed, hill_open, hill_semi, hill_closed, roll_hill (default "
           "flat_open,hill_open); 'study' = the six experiments of the study, 'all' = the six and roll_hill")
      .value("--method", "M[,M...]", "hill (the study's hill climber, default), cmaes (equal evaluation budget)")
      .value("--climbers", "N", "independent climbers per experiment (default 4; study 60)")
      .value("--generations", "G", "generations after the random start (default 10; study 200)")
      .value("--seed", "S", "base seed; climber c draws from (S, c, generation) only (default 1)")
      .value("--fitness", "NAME", "registered fitness (default synthetic; see --list)")
      .value("--fidelity", "LEVEL", "level passed to the fitness during the search (default 0)")
      .value("--validate-fidelity", "LEVEL",
             "re-evaluate every climber's final best at this level; report the rank change")
      .value("--ranks-per-sim", "K", "MPI ranks per simulation (sub-communicators; must divide the rank count)")
      .value("--out", "DIR", "results and checkpoints (default results/search)")
      .value("--voxel-dir", "DIR", "the voxel study's CSVs for the comparison ('none' to skip)")
      .flag("--restart", "discard existing checkpoints (default: resume from them)")
      .flag("--resume", "resume from existing checkpoints (the default)")
      .flag("--no-hand-designed", "skip the rolling/inching rows of the table")
      .flag("--no-plot", "do not call scripts/plot_search.py")
      .flag("--quiet", "no progress line")
      .value("--eval-delay-ms", "MS", "sleep before every evaluation (tests)")
      .flag("--list", "experiments, methods and fitnesses")
      .petsc_options()
      .epilog(
          "Runs unchanged under mpirun. A killed run, started again with the same options, resumes from its last "
          "checkpoint, written after every step (a generation of the hill climber, an iteration of CMA-ES), and "
          "reuses the evaluations of the unfinished step saved as each finished (partial_team_K.h5): only the "
          "evaluations that were running are redone.");
  return cl;
}

std::vector<std::string> experiment_list(const std::string& v) {
  const std::vector<std::string> study = {"flat_open", "flat_semi", "flat_closed",
                                          "hill_open", "hill_semi", "hill_closed"};
  std::vector<std::string> out = v == "study" ? study : split_list(v);
  if (v == "all") {
    out = study;
    out.push_back("roll_hill");
  }
  if (out.empty()) throw InputError("--experiments", "empty experiment list");
  return out;
}

SearchOptions search_options(const CommandLine& cl) {
  SearchOptions o;
  const std::string default_voxel = shared_data_dir() + "/voxel-study";
  o.voxel_dir = std::filesystem::exists(default_voxel) ? default_voxel : "";
  if (cl.has("--experiments")) o.experiments = experiment_list(cl.get("--experiments", ""));
  if (cl.has("--method")) {
    o.methods = split_list(cl.get("--method", ""));
    if (o.methods.empty()) throw InputError("--method", "empty method list");
  }
  o.climbers = cl.integer("--climbers", o.climbers, 1, 100000);
  o.generations = cl.integer("--generations", o.generations, 0, 10000000);
  o.seed = static_cast<std::uint64_t>(cl.number("--seed", static_cast<double>(o.seed), 0, 1e15));
  o.fitness = cl.get("--fitness", o.fitness);
  o.fidelity = cl.get("--fidelity", o.fidelity);
  o.validate_fidelity = cl.get("--validate-fidelity", o.validate_fidelity);
  o.ranks_per_sim = cl.integer("--ranks-per-sim", o.ranks_per_sim, 1, 1000000);
  o.eval_delay_ms = cl.integer("--eval-delay-ms", o.eval_delay_ms, 0, 3600000);
  o.out_dir = cl.get("--out", o.out_dir);
  if (cl.has("--voxel-dir")) {
    const std::string v = cl.get("--voxel-dir", "");
    o.voxel_dir = v == "none" ? "" : v;
    if (!o.voxel_dir.empty() && !std::filesystem::is_directory(o.voxel_dir))
      throw InputError("--voxel-dir", "no such directory: " + o.voxel_dir);
  }
  o.restart = cl.has("--restart");
  o.hand_designed = !cl.has("--no-hand-designed");
  o.progress = !cl.has("--quiet");
  return o;
}

}  // namespace

int search_command(const std::vector<std::string>& args, MPI_Comm comm) {
  register_robot_fitness();
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  CommandLine cl = search_command_line();
  if (!cl.parse(args, rank == 0 ? std::cout : std::cerr)) return 0;
  if (cl.has("--list")) {
    if (rank == 0) print_list();
    return 0;
  }
  const SearchOptions o = search_options(cl);
  const bool plot = !cl.has("--no-plot");
  find_fitness(o.fitness);  // unknown names fail before any work

  const SearchReport report = run_search(o, comm);
  if (rank != 0) return 0;
  const std::string table = summary_markdown(report, o);
  std::fputs(table.c_str(), stdout);
  std::filesystem::create_directories(o.out_dir);
  write_file_atomic(o.out_dir + "/summary.md", table);
  const std::string json = o.out_dir + "/summary.json";
  write_file_atomic(json, summary_json(report, o));
  std::printf("\nresults: %s/<experiment>/<method>/ (CSV, checkpoint.h5, best/*.yaml), %s/summary.{md,json}\n",
              o.out_dir.c_str(), o.out_dir.c_str());
  if (plot && run_plot_script("plot_search.py", {json, o.out_dir}, "the search curves"))
    std::printf("curves: %s/curves*.png\n", o.out_dir.c_str());
  return 0;
}

}  // namespace morphfem
