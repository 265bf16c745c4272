#include "optim/search_experiment.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "core/errors.h"
#include "core/json.h"
#include "core/progress.h"
#include "core/strings.h"
#include "optim/checkpoint.h"
#include "optim/search_method.h"
#include "optim/search_partial.h"
#include "optim/search_stats.h"

namespace morphfem {

namespace {

constexpr long kCheckpointFormat = 1;
constexpr double kHillSlopeDeg = 15;
// The study's full experiment: six experiments x 60 climbers x (200 + 1) evaluations.
constexpr long kStudyEvaluations = 6L * 60 * 201;

GenomeSpace space(bool orientation_free, bool pressure_free, double orientation = 0, double pressure = 0) {
  GenomeSpace s;
  s.orientation_free = orientation_free;
  s.pressure_free = pressure_free;
  s.fixed_orientation_deg = orientation;
  s.fixed_core_pressure_pa = pressure;
  return s;
}

std::string format_number(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest form that reads back exactly
  return std::string(buf, r.ptr);
}

std::string fixed(double v, int digits = 4) {
  if (!std::isfinite(v)) return std::isnan(v) ? "-" : (v > 0 ? "inf" : "-inf");
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

int rank_of(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}

std::string validation_csv(const ExperimentResult& r) {
  std::string s = "climber,search_speed,validation_speed,search_rank,validation_rank\n";
  const auto rs = descending_ranks(r.best_speed), rv = descending_ranks(r.validation_speed);
  for (size_t c = 0; c < r.best_speed.size(); ++c)
    s += std::to_string(c + 1) + "," + format_number(r.best_speed[c]) + "," + format_number(r.validation_speed[c]) +
         "," + format_number(rs[c]) + "," + format_number(rv[c]) + "\n";
  return s;
}

// Voxel-study hand-designed results from baselines.txt: (matrix name, slope) -> BL/s.
std::map<std::pair<std::string, int>, double> read_voxel_baselines(const std::string& path) {
  std::map<std::pair<std::string, int>, double> out;
  std::ifstream in(path);
  if (!in) return out;
  const std::regex fitness_line(R"(fitness\(\(\s*\w+,\s*\w+,\s*(\w+)\),\s*(\d+),.*)");
  std::string line, matrix;
  int slope = -1;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_match(line, m, fitness_line)) {
      matrix = m[1];
      slope = std::stoi(m[2]);
    } else if (line.rfind("BLs=>", 0) == 0 && slope >= 0) {
      out[{matrix, slope}] = std::strtod(line.c_str() + 5, nullptr);
      slope = -1;
    }
  }
  return out;
}

struct VoxelReference {
  bool found = false;
  double mean_at_g = 0, max_at_g = 0, mean_final = 0, max_final = 0;
  int final_generation = 0;
};

VoxelReference voxel_reference(const SearchOptions& o, const ExperimentSpec& spec, int generation) {
  VoxelReference v;
  if (o.voxel_dir.empty() || spec.voxel_csv.empty()) return v;
  const std::string path = o.voxel_dir + "/" + spec.voxel_csv;
  if (!std::filesystem::exists(path)) return v;
  const auto h = read_history_csv(path);
  if (h.empty()) return v;
  const size_t g = std::min<size_t>(generation, h.size() - 1);
  v.found = true;
  v.mean_at_g = mean_of(h[g]);
  v.max_at_g = max_of(h[g]);
  v.mean_final = mean_of(h.back());
  v.max_final = max_of(h.back());
  v.final_generation = static_cast<int>(h.size() - 1);
  return v;
}

class SearchRunner {
 public:
  SearchRunner(const SearchOptions& o, MPI_Comm comm)
      : o_(o), teams_(comm, o.ranks_per_sim), fitness_(find_fitness(o.fitness)), root_(rank_of(comm) == 0) {}

  double speed(const Genome& g, const Environment& env, const std::string& fidelity, MPI_Comm team) const {
    if (o_.eval_delay_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(o_.eval_delay_ms));
    return fitness_(g, env, fidelity, team);
  }

  // Evaluates a batch and adds its wall time to the session's cost measurement.
  // Speeds in `known` (an interrupted step's saved evaluations) are not evaluated or counted.
  std::vector<double> evaluate(const std::vector<Genome>& genomes, const Environment& env, const std::string& fidelity,
                               const std::function<void(long)>& on_done = nullptr, const BatchSpeeds& known = {},
                               const std::function<void(std::size_t, double)>& on_result = nullptr) {
    const auto t0 = std::chrono::steady_clock::now();
    auto out = teams_.evaluate(
        genomes, [&](const Genome& g, MPI_Comm team) { return speed(g, env, fidelity, team); }, on_done, known,
        on_result);
    wall_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    evaluations_ += static_cast<long>(genomes.size() - known.size());
    return out;
  }

  ExperimentResult run(const ExperimentSpec& spec, const std::string& method_name);
  std::vector<HandDesignedResult> hand_designed(const std::vector<Environment>& envs);

 private:
  // One experiment of one method while it runs: its result so far, the method, the
  // checkpoint's metadata and state, the progress bar and this session's counters.
  struct Run {
    ExperimentResult r;
    std::unique_ptr<SearchMethod> method;
    SearchState meta, state;
    std::string checkpoint;
    double resumed_evaluations = 0;
    long evaluations_before = 0;
    double wall_before = 0;
    std::chrono::steady_clock::time_point session_start;
  };
  void open(Run& run, const ExperimentSpec& spec, const std::string& method_name);
  void save(Run& run);
  void step(Run& run, const ExperimentSpec& spec, Progress& progress);
  void validate_best(Run& run, const ExperimentSpec& spec);
  void write_results(const Run& run, const ExperimentSpec& spec) const;

 public:
  const EvaluationTeams& teams() const { return teams_; }
  double wall_s() const { return wall_s_; }
  long evaluations() const { return evaluations_; }

 private:
  const SearchOptions& o_;
  EvaluationTeams teams_;
  const FitnessFunction& fitness_;
  bool root_;
  double wall_s_ = 0;
  long evaluations_ = 0;
};

// The result's folder, the method, and the state of an earlier session's checkpoint
// (every rank reads the same file: the same state everywhere).
void SearchRunner::open(Run& run, const ExperimentSpec& spec, const std::string& method_name) {
  ExperimentResult& r = run.r;
  r.experiment = spec.name;
  r.method = method_name;
  r.climbers = o_.climbers;
  r.generations = o_.generations;
  r.dir = o_.out_dir + "/" + spec.name + "/" + method_name;
  r.csv = r.dir + "/" + spec.name + ".csv";
  run.checkpoint = r.dir + "/checkpoint.h5";

  SearchSetup setup;
  setup.space = spec.space;
  setup.runs = o_.climbers;
  setup.generations = o_.generations;
  setup.seed = o_.seed;
  run.method = make_search_method(method_name, setup);

  run.meta = search_metadata(spec, method_name, o_);
  if (root_) {
    std::filesystem::create_directories(r.dir);
    if (o_.restart) {
      std::filesystem::remove(run.checkpoint);
      remove_partial_steps(r.dir);
    }
  }
  MPI_Barrier(teams_.world());
  if (std::filesystem::exists(run.checkpoint)) {
    run.state = read_checkpoint(run.checkpoint);
    check_metadata(run.state, run.meta, run.checkpoint);
    run.method->restore(run.state, run.checkpoint);
    r.resumed = true;
  }
}

// After a step: its checkpoint, then (the checkpoint holds the whole step) its saved
// evaluations are removed, then the CSV. A CSV row thus means no partial file of that
// step is left.
void SearchRunner::save(Run& run) {
  run.state = run.meta;
  run.method->save(run.state);
  if (root_) {
    write_checkpoint(run.checkpoint, run.state);
    remove_partial_steps(run.r.dir);
    write_file_atomic(run.r.csv, history_csv(run.method->history()));
  }
}

// One step of the method (a generation, an iteration): propose, evaluate (reusing the
// evaluations of this step a killed session saved, optim/search_partial.h), accept, save.
void SearchRunner::step(Run& run, const ExperimentSpec& spec, Progress& progress) {
  ExperimentResult& r = run.r;
  SearchMethod& method = *run.method;
  const std::vector<Genome> genomes = method.propose();
  // Every rank reads the same files before any team leader rewrites its own.
  const long step = method.steps();
  const PartialSteps partial = read_partial_steps(r.dir, run.meta, step, genomes);
  MPI_Barrier(teams_.world());
  if (!partial.speeds.empty()) {
    r.evaluations_reused += static_cast<long>(partial.speeds.size());
    r.resumed = true;
    run.resumed_evaluations += static_cast<double>(partial.speeds.size());
    progress.set_resumed_from(run.resumed_evaluations);
    if (root_ && o_.progress)
      std::fprintf(stderr, "search %s/%s: %zu evaluation(s) of step %ld reused from %s/partial_team_*.h5\n",
                   spec.name.c_str(), r.method.c_str(), partial.speeds.size(), step, r.dir.c_str());
  }
  BatchSpeeds saved = partial.speeds;  // this team's partial file: the reused speeds and its own
  const std::string partial_file = partial_step_path(r.dir, teams_.team());
  auto on_result = [&](std::size_t i, double v) {
    saved[i] = v;
    write_partial_step(partial_file, run.meta, step, genomes, saved);
  };
  const double done_before =
      static_cast<double>(method.evaluations()) * o_.climbers + static_cast<double>(partial.speeds.size());
  // Progress: generation, best so far, evaluations per hour of this session, ETA (core/progress.h).
  auto on_done = [&](long k) {
    const double session = static_cast<double>(evaluations_ - run.evaluations_before + k);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - run.session_start).count();
    const auto& h = method.history();
    char info[160];
    std::snprintf(info, sizeof info, "gen %ld/%d best %s BL/s %.3g evals/h", method.evaluations(), o_.generations,
                  h.empty() ? "-" : fixed(max_of(h.back())).c_str(), elapsed > 0 ? 3600.0 * session / elapsed : 0.0);
    progress.update(done_before + k, info);
  };
  const std::vector<double> speeds = evaluate(genomes, spec.env, o_.fidelity, on_done, partial.speeds, on_result);
  method.accept(speeds);
  save(run);
  MPI_Barrier(teams_.world());  // the step's partial files are gone before any rank looks for the next step's
}

// Every climber's final best re-evaluated at the validation level (kept in the
// checkpoint, so a resumed run does not redo it), and the rank correlations.
void SearchRunner::validate_best(Run& run, const ExperimentSpec& spec) {
  ExperimentResult& r = run.r;
  auto it = run.state.texts.find("validate_fidelity");
  if (it != run.state.texts.end() && it->second == o_.validate_fidelity) {
    r.validation_speed = run.state.array("validation_speeds", run.checkpoint, o_.climbers);
  } else {
    r.validation_speed = evaluate(r.best, spec.env, o_.validate_fidelity);
    run.state.texts["validate_fidelity"] = o_.validate_fidelity;
    run.state.arrays["validation_speeds"] = r.validation_speed;
    if (root_) write_checkpoint(run.checkpoint, run.state);
  }
  r.spearman = spearman_rho(r.best_speed, r.validation_speed);
  r.kendall = kendall_tau(r.best_speed, r.validation_speed);
}

// The history CSV, each climber's best as a schedule file, the validation CSV.
void SearchRunner::write_results(const Run& run, const ExperimentSpec& spec) const {
  const ExperimentResult& r = run.r;
  write_file_atomic(r.csv, history_csv(r.history));
  std::filesystem::create_directories(r.dir + "/best");
  for (int c = 0; c < o_.climbers; ++c) {
    char name[32];
    std::snprintf(name, sizeof name, "climber_%02d", c + 1);
    const std::string label = spec.name + " " + r.method + " " + name + " speed " + format_number(r.best_speed[c]) +
                              " BL/s at fidelity " + o_.fidelity;
    write_file_atomic(r.dir + "/best/" + name + ".yaml", genome_schedule_yaml(r.best[c], label));
  }
  if (!r.validation_speed.empty()) write_file_atomic(r.dir + "/validation.csv", validation_csv(r));
}

ExperimentResult SearchRunner::run(const ExperimentSpec& spec, const std::string& method_name) {
  Run run;
  open(run, spec, method_name);
  // The bar covers the whole run; its ETA extrapolates this session's rate only (a
  // resumed run starts part way, and reused evaluations of a step take no time).
  run.resumed_evaluations = static_cast<double>(run.method->evaluations()) * o_.climbers;
  const double total = static_cast<double>(o_.climbers) * (o_.generations + 1);
  Progress progress("search " + spec.name + "/" + method_name, total, o_.progress && total > run.resumed_evaluations);
  progress.set_resumed_from(run.resumed_evaluations);
  run.evaluations_before = evaluations_;
  run.wall_before = wall_s_;
  run.session_start = std::chrono::steady_clock::now();
  while (!run.method->done()) step(run, spec, progress);
  progress.finish("best " + fixed(max_of(run.method->best_speeds())) + " BL/s");

  ExperimentResult& r = run.r;
  r.evaluations_timed = evaluations_ - run.evaluations_before;
  r.evaluation_wall_s = wall_s_ - run.wall_before;
  r.history = run.method->history();
  r.best = run.method->best_genomes();
  r.best_speed = run.method->best_speeds();
  r.evaluations = static_cast<long>(r.history.size()) * o_.climbers;
  if (!o_.validate_fidelity.empty()) validate_best(run, spec);
  if (root_) write_results(run, spec);
  return r;
}

std::vector<HandDesignedResult> SearchRunner::hand_designed(const std::vector<Environment>& envs) {
  std::vector<HandDesignedResult> out;
  std::vector<Genome> genomes;
  for (const auto& env : envs)
    for (const auto& [name, genome] :
         {std::pair{"rolling", rolling_genome()}, std::pair{"inching", inching_genome()}}) {
      HandDesignedResult h;
      h.name = name;
      h.genome = genome;
      h.environment = env.name;
      out.push_back(h);
    }
  // One batch per environment so the teams share the work.
  for (const auto& env : envs) {
    std::vector<Genome> batch;
    for (const auto& h : out)
      if (h.environment == env.name) batch.push_back(h.genome);
    const auto speeds = evaluate(batch, env, o_.fidelity);
    const auto validation = o_.validate_fidelity.empty() ? std::vector<double>(batch.size(), std::nan(""))
                                                         : evaluate(batch, env, o_.validate_fidelity);
    size_t k = 0;
    for (auto& h : out)
      if (h.environment == env.name) h.speed = speeds[k], h.validation_speed = validation[k], ++k;
  }
  return out;
}

}  // namespace

const std::vector<ExperimentSpec>& search_experiments() {
  static const std::vector<ExperimentSpec> list = [] {
    const Environment flat{"flat", 0}, hill{"hill", kHillSlopeDeg};
    return std::vector<ExperimentSpec>{
        {"flat_open", "flat ground; orientation, shape and control free", flat, space(true, true), "flat_open.csv"},
        {"flat_semi", "flat ground; shape and control free, orientation 0 deg", flat, space(false, true, 0),
         "flat_semi.csv"},
        {"flat_closed", "flat ground; control only: inflated robot (12 kPa) at 0 deg", flat,
         space(false, false, 0, kMaxCorePressurePa), "flat_closed.csv"},
        {"hill_open", "15 deg hill; orientation, shape and control free", hill, space(true, true), "hill_open.csv"},
        {"hill_semi", "15 deg hill; shape and control free, orientation 90 deg", hill, space(false, true, 90),
         "hill_semi.csv"},
        {"hill_closed", "15 deg hill; control only: flat robot (0 Pa) at 90 deg", hill, space(false, false, 90, 0),
         "hill_closed.csv"},
        {"roll_hill", "15 deg hill; control only: inflated robot (12 kPa) width-wise (0 deg)", hill,
         space(false, false, 0, kMaxCorePressurePa), ""},
    };
  }();
  return list;
}

const ExperimentSpec& find_experiment(const std::string& name) {
  for (const auto& e : search_experiments())
    if (e.name == name) return e;
  const std::string known = join(search_experiments(), ", ", [](const ExperimentSpec& e) { return e.name; });
  throw InputError("--experiments", "unknown experiment '" + name + "' (known: " + known + ")");
}

std::string history_csv(const std::vector<std::vector<double>>& history) {
  std::string s = "g";
  const size_t n = history.empty() ? 0 : history[0].size();
  for (size_t c = 0; c < n; ++c) s += ",f_" + std::to_string(c + 1);
  s += "\n";
  for (size_t g = 0; g < history.size(); ++g) {
    s += std::to_string(g);
    for (double v : history[g]) s += "," + format_number(v);
    s += "\n";
  }
  return s;
}

std::vector<std::vector<double>> read_history_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("g,", 0) != 0)
    throw InputError(path + ":1", "expected the header g,f_1,...,f_N");
  const size_t columns = std::count(line.begin(), line.end(), ',');
  std::vector<std::vector<double>> h;
  int number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line == "\r") continue;
    std::stringstream ss(line);
    std::string cell;
    std::vector<double> row;
    std::getline(ss, cell, ',');  // generation index
    while (std::getline(ss, cell, ',')) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (end == cell.c_str()) throw InputError(path + ":" + std::to_string(number), "'" + cell + "' is not a number");
      row.push_back(v);
    }
    if (row.size() != columns)
      throw InputError(path + ":" + std::to_string(number),
                       "expected " + std::to_string(columns) + " values, got " + std::to_string(row.size()));
    h.push_back(row);
  }
  return h;
}

SearchState search_metadata(const ExperimentSpec& spec, const std::string& method, const SearchOptions& o) {
  SearchState s;
  s.integers["format"] = kCheckpointFormat;
  s.integers["seed"] = static_cast<long>(o.seed);
  s.integers["climbers"] = o.climbers;
  s.texts["experiment"] = spec.name;
  s.texts["method"] = method;
  s.texts["fitness"] = o.fitness;
  s.texts["fidelity"] = o.fidelity;
  return s;
}

SearchReport run_search(const SearchOptions& o, MPI_Comm comm) {
  if (o.climbers < 1) throw InputError("--climbers", "must be >= 1");
  if (o.generations < 0) throw InputError("--generations", "must be >= 0");
  if (o.eval_delay_ms < 0) throw InputError("--eval-delay-ms", "must be >= 0");
  std::vector<const ExperimentSpec*> specs;
  for (const auto& name : o.experiments) specs.push_back(&find_experiment(name));
  for (const auto& m : o.methods) make_search_method(m, SearchSetup{});  // validates the names
  SearchRunner runner(o, comm);
  SearchReport report;
  MPI_Comm_size(comm, &report.ranks);
  report.teams = runner.teams().teams();
  for (const auto* spec : specs)
    for (const auto& m : o.methods) report.results.push_back(runner.run(*spec, m));
  if (o.hand_designed) {
    std::vector<Environment> envs;
    for (const auto* spec : specs) {
      bool seen = false;
      for (const auto& e : envs) seen = seen || e.name == spec->env.name;
      if (!seen) envs.push_back(spec->env);
    }
    report.hand_designed = runner.hand_designed(envs);
  }
  // Seconds per evaluation of one team: the teams work side by side.
  if (runner.evaluations() > 0) report.seconds_per_evaluation = runner.wall_s() * report.teams / runner.evaluations();
  return report;
}

std::string summary_markdown(const SearchReport& report, const SearchOptions& o) {
  std::ostringstream t;
  t << "# Search results\n\nfitness `" << o.fitness << "` at fidelity `" << o.fidelity << "`, seed " << o.seed << ", "
    << o.climbers << " climbers x " << o.generations << " generations; speeds in BL/s, best so far at the "
    << "last generation (mean and max over climbers).\n\n";
  t << "| experiment | method | evaluations | mean | std | max | voxel mean (same g) | voxel max (same g) | "
       "voxel mean (final) | voxel max (final) |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : report.results) {
    const auto& last = r.history.back();
    const VoxelReference v = voxel_reference(o, find_experiment(r.experiment), r.generations);
    t << "| " << r.experiment << " | " << r.method << " | " << r.evaluations << " | " << fixed(mean_of(last)) << " | "
      << fixed(sample_std(last)) << " | " << fixed(max_of(last)) << " | " << (v.found ? fixed(v.mean_at_g) : "-")
      << " | " << (v.found ? fixed(v.max_at_g) : "-") << " | "
      << (v.found ? fixed(v.mean_final) + " (g=" + std::to_string(v.final_generation) + ")" : "-") << " | "
      << (v.found ? fixed(v.max_final) : "-") << " |\n";
  }
  if (!report.hand_designed.empty()) {
    const auto voxel = o.voxel_dir.empty() ? std::map<std::pair<std::string, int>, double>{}
                                           : read_voxel_baselines(o.voxel_dir + "/baselines.txt");
    t << "\nHand-designed schedules (one evaluation each):\n\n| schedule | environment | speed | voxel study |"
      << (o.validate_fidelity.empty() ? "" : " validation speed |") << "\n|---|---|---|---|"
      << (o.validate_fidelity.empty() ? "" : "---|") << "\n";
    for (const auto& h : report.hand_designed) {
      const std::string matrix = h.name == "rolling" ? "roll_matrix" : "inch_matrix";
      const int slope = h.environment == "hill" ? static_cast<int>(kHillSlopeDeg) : 0;
      auto it = voxel.find({matrix, slope});
      t << "| hand-designed " << h.name << (h.name == "rolling" ? " (0 deg, 12 kPa)" : " (90 deg, 0 kPa)") << " | "
        << h.environment << " | " << fixed(h.speed) << " | " << (it != voxel.end() ? fixed(it->second) : "-") << " |"
        << (o.validate_fidelity.empty() ? "" : " " + fixed(h.validation_speed) + " |") << "\n";
    }
  }
  bool any_validation = false;
  for (const auto& r : report.results) any_validation = any_validation || !r.validation_speed.empty();
  if (any_validation) {
    t << "\nMulti-fidelity: every climber's final best re-evaluated at fidelity `" << o.validate_fidelity
      << "`; rank change of the climbers between the two levels.\n\n"
      << "| experiment | method | search mean | search max | validation mean | validation max | best climber "
         "(search -> validation) | Spearman rho | Kendall tau |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& r : report.results) {
      if (r.validation_speed.empty()) continue;
      const auto arg_max = [](const std::vector<double>& x) {
        return std::max_element(x.begin(), x.end()) - x.begin() + 1;
      };
      t << "| " << r.experiment << " | " << r.method << " | " << fixed(mean_of(r.best_speed)) << " | "
        << fixed(max_of(r.best_speed)) << " | " << fixed(mean_of(r.validation_speed)) << " | "
        << fixed(max_of(r.validation_speed)) << " | " << arg_max(r.best_speed) << " -> " << arg_max(r.validation_speed)
        << " | " << fixed(r.spearman, 3) << " | " << fixed(r.kendall, 3) << " |\n";
    }
  }
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const double rank_s = report.seconds_per_evaluation * o.ranks_per_sim;  // rank-seconds per evaluation
  t << "\nCost: ";
  if (report.seconds_per_evaluation > 0) {
    char per_eval[32];
    std::snprintf(per_eval, sizeof per_eval, "%.3g", report.seconds_per_evaluation);
    t << per_eval << " s wall per evaluation (" << o.ranks_per_sim << " rank(s) per simulation, " << report.ranks
      << " rank(s)) at fidelity `" << o.fidelity
      << "`. The study's full experiment (6 x 60 x 201 = " << kStudyEvaluations << " evaluations) projects to "
      << format_seconds(kStudyEvaluations * rank_s / cores) << " on this machine (" << cores << " cores) and "
      << format_seconds(kStudyEvaluations * rank_s / 64) << " on a 64-core node (perfect scaling over climbers).\n";
  } else {
    t << "no evaluations in this session (all results came from checkpoints).\n";
  }
  return t.str();
}

std::string summary_json(const SearchReport& report, const SearchOptions& o) {
  std::vector<Json> experiments;
  for (const auto& r : report.results) {
    const auto& spec = find_experiment(r.experiment);
    const auto& last = r.history.back();
    Json e;
    e.add("experiment", r.experiment)
        .add("method", r.method)
        .add("description", spec.description)
        .add("slope_deg", spec.env.slope_deg)
        .add("climbers", r.climbers)
        .add("generations", r.generations)
        .add("evaluations", r.evaluations)
        .add("csv", r.csv)
        .add("voxel_csv", o.voxel_dir.empty() || spec.voxel_csv.empty() ? "" : o.voxel_dir + "/" + spec.voxel_csv)
        .add("mean", mean_of(last))
        .add("std", sample_std(last))
        .add("max", max_of(last))
        .add("best_speeds", r.best_speed)
        .add("resumed", r.resumed)
        .add("evaluation_wall_s", r.evaluation_wall_s)
        .add("evaluations_timed", r.evaluations_timed)
        .add("evaluations_reused", r.evaluations_reused);
    if (!r.validation_speed.empty())
      e.add("validation_speeds", r.validation_speed).add("spearman", r.spearman).add("kendall", r.kendall);
    experiments.push_back(e);
  }
  std::vector<Json> hand;
  for (const auto& h : report.hand_designed)
    hand.push_back(Json().add("name", h.name).add("environment", h.environment).add("speed", h.speed));
  Json j;
  j.add("fitness", o.fitness)
      .add("fidelity", o.fidelity)
      .add("validate_fidelity", o.validate_fidelity)
      .add("seed", static_cast<long>(o.seed))
      .add("ranks", report.ranks)
      .add("ranks_per_sim", o.ranks_per_sim)
      .add("seconds_per_evaluation", report.seconds_per_evaluation)
      .add("experiments", experiments)
      .add("hand_designed", hand);
  return j.str(true) + "\n";
}

}  // namespace morphfem
