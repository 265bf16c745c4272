#include "app/search_cli.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "app/plot.h"
#include "core/errors.h"
#include "core/json.h"
#include "optim/fitness.h"
#include "optim/search_experiment.h"
#include "optim/search_method.h"

namespace morphfem {

namespace {

const char* kSearchUsage =
    "usage: morphfem search [options]\n"
    "  --experiments A,B,...     flat_open, flat_semi, flat_closed, hill_open, hill_semi, hill_closed, roll_hill\n"
    "                            (default flat_open,hill_open); 'study' = the six experiments of the study,\n"
    "                            'all' = the six and the roll_hill control experiment\n"
    "  --method M[,M...]         hill (the study's hill climber, default), cmaes (equal evaluation budget)\n"
    "  --climbers N              independent climbers per experiment (default 4; study 60)\n"
    "  --generations G           generations after the random start (default 10; study 200)\n"
    "  --seed S                  base seed; climber c draws from (S, c, generation) only (default 1)\n"
    "  --fitness NAME            registered fitness (default synthetic; see --list)\n"
    "  --fidelity LEVEL          level passed to the fitness during the search (default 0)\n"
    "  --validate-fidelity LEVEL re-evaluate every climber's final best at this level; report the rank change\n"
    "  --ranks-per-sim K         MPI ranks per simulation (sub-communicators; must divide the rank count)\n"
    "  --out DIR                 results and checkpoints (default results/search)\n"
    "  --voxel-dir DIR           the voxel study's CSVs for the comparison ('none' to skip)\n"
    "  --restart                 discard existing checkpoints (default: resume from them)\n"
    "  --no-hand-designed        skip the rolling/inching rows of the table\n"
    "  --no-plot                 do not call scripts/plot_search.py\n"
    "  --quiet                   no progress line\n"
    "  --eval-delay-ms MS        sleep before every evaluation (tests)\n"
    "  --list                    experiments, methods and fitnesses\n"
    "Runs unchanged under mpirun. A killed run, started again with the same options, resumes from its last\n"
    "checkpoint, written after every step (a generation of the hill climber, an iteration of CMA-ES), and\n"
    "reuses the evaluations of the unfinished step saved as each finished (partial_team_K.h5): only the\n"
    "evaluations that were running are redone.\n";

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

long parse_integer(const std::string& option, const std::string& text, long lo, long hi) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || v < lo || v > hi)
    throw InputError(
        option, "expected an integer in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got '" + text + "'");
  return v;
}

void print_list() {
  std::printf("experiments:\n");
  for (const auto& e : search_experiments()) std::printf("  %-12s %s\n", e.name.c_str(), e.description.c_str());
  std::printf("methods:\n");
  for (const auto& m : search_method_names()) std::printf("  %s\n", m.c_str());
  std::printf("fitnesses:\n");
  for (const auto& f : fitness_descriptions()) std::printf("  %s\n", f.c_str());
}

}  // namespace

int search_main(const std::vector<std::string>& args, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  SearchOptions o;
  const std::string default_voxel = std::string(MORPHFEM_SOURCE_DIR) + "/../shared/data/voxel-study";
  o.voxel_dir = std::filesystem::exists(default_voxel) ? default_voxel : "";
  bool plot = true;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw InputError(a, "missing value");
      return args[++i];
    };
    if (a == "--help" || a == "-h") {
      if (rank == 0) std::fputs(kSearchUsage, stdout);
      return 0;
    } else if (a == "--list") {
      if (rank == 0) print_list();
      return 0;
    } else if (a == "--experiments" || a == "--experiment") {
      const std::string v = value();
      const std::vector<std::string> study = {"flat_open", "flat_semi", "flat_closed",
                                              "hill_open", "hill_semi", "hill_closed"};
      o.experiments = v == "study" ? study : split_list(v);
      if (v == "all") {
        o.experiments = study;
        o.experiments.push_back("roll_hill");
      }
      if (o.experiments.empty()) throw InputError(a, "empty experiment list");
    } else if (a == "--method" || a == "--methods") {
      o.methods = split_list(value());
      if (o.methods.empty()) throw InputError(a, "empty method list");
    } else if (a == "--climbers") {
      o.climbers = static_cast<int>(parse_integer(a, value(), 1, 100000));
    } else if (a == "--generations") {
      o.generations = static_cast<int>(parse_integer(a, value(), 0, 10000000));
    } else if (a == "--seed") {
      o.seed = static_cast<std::uint64_t>(parse_integer(a, value(), 0, (1L << 62)));
    } else if (a == "--fitness") {
      o.fitness = value();
    } else if (a == "--fidelity") {
      o.fidelity = value();
    } else if (a == "--validate-fidelity") {
      o.validate_fidelity = value();
    } else if (a == "--ranks-per-sim") {
      o.ranks_per_sim = static_cast<int>(parse_integer(a, value(), 1, 1000000));
    } else if (a == "--eval-delay-ms") {
      o.eval_delay_ms = static_cast<int>(parse_integer(a, value(), 0, 3600000));
    } else if (a == "--out") {
      o.out_dir = value();
    } else if (a == "--voxel-dir") {
      const std::string v = value();
      o.voxel_dir = v == "none" ? "" : v;
      if (!o.voxel_dir.empty() && !std::filesystem::is_directory(o.voxel_dir))
        throw InputError(a, "no such directory: " + o.voxel_dir);
    } else if (a == "--restart") {
      o.restart = true;
    } else if (a == "--resume") {
      o.restart = false;  // the default; accepted for clarity
    } else if (a == "--no-hand-designed") {
      o.hand_designed = false;
    } else if (a == "--no-plot") {
      plot = false;
    } else if (a == "--quiet") {
      o.progress = false;
    } else if (a.rfind("--", 0) == 0) {
      throw InputError("morphfem search", "unknown option " + a + " (morphfem search --help)");
    }
    // Anything else (single-dash PETSc options and their values) passes through.
  }
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
