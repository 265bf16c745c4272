// Search: genome mutation/wrapping/rounding, genome -> schedule rows, keep-if-better,
// determinism by seed, checkpoint round trips, CMA-ES at equal budget, statistics,
// and the experiment loop end to end (in process, on the synthetic fitness).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "actuation/schedule.h"
#include "core/errors.h"
#include "core/paths.h"
#include "optim/checkpoint.h"
#include "optim/cmaes.h"
#include "optim/fitness.h"
#include "optim/genome.h"
#include "optim/hill_climber.h"
#include "optim/search_experiment.h"
#include "optim/search_parallel.h"
#include "optim/search_stats.h"
#include "tests/support/temp_dir.h"

namespace morphfem {
namespace {

Genome middle_genome() {
  Genome g;
  g.orientation_deg = 45;
  g.core_pressure_pa = 6000;
  for (auto& r : g.rows) r = {4, 4};
  return g;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Step statistics of n mutations of one parent: mean and standard deviation of each gene's change.
struct StepStats {
  double mean = 0, std = 0;
};
StepStats stats(const std::vector<double>& x) {
  StepStats s;
  for (double v : x) s.mean += v;
  s.mean /= x.size();
  for (double v : x) s.std += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(s.std / (x.size() - 1));
  return s;
}

TEST(SearchGenome, MutationStepsHaveTheStudysStandardDeviations) {
  const int n = 40000;
  const Genome parent = middle_genome();
  std::vector<double> d_theta, d_p, d_f, d_phi;
  for (int i = 0; i < n; ++i) {
    RandomStream rng(7, 1, i);
    const Genome c = mutate_genome(parent, GenomeSpace{}, rng);
    d_theta.push_back(c.orientation_deg - parent.orientation_deg);
    d_p.push_back(c.core_pressure_pa - parent.core_pressure_pa);
    d_f.push_back(c.rows[3].f - parent.rows[3].f);
    d_phi.push_back(c.rows[7].phi - parent.rows[7].phi);
  }
  // Rounding a N(0, s^2) step to integers adds variance 1/12: std = sqrt(s^2 + 1/12).
  // Far from the bounds (45 +/- 5 std, 6000 +/- 5 std, 4 +/- 4.4 std) nothing is clipped
  // or wrapped, except the f/phi tails beyond 4.5 (probability 6e-7, negligible).
  const struct {
    const std::vector<double>* x;
    double step;
  } genes[] = {{&d_theta, 9.0}, {&d_p, 1200.0}, {&d_f, 0.9}, {&d_phi, 0.9}};
  for (const auto& g : genes) {
    const StepStats s = stats(*g.x);
    const double expected_std = std::sqrt(g.step * g.step + 1.0 / 12);
    EXPECT_NEAR(s.mean, 0.0, 4 * expected_std / std::sqrt(n)) << "step " << g.step;
    // Standard error of a sample std is about std / sqrt(2n) = 0.35 %; allow 5 of them.
    EXPECT_NEAR(s.std / expected_std, 1.0, 5 / std::sqrt(2.0 * n)) << "step " << g.step;
  }
}

TEST(SearchGenome, RowGenesWrapAndOrientationAndPressureClip) {
  EXPECT_EQ(wrap_gene(-1), 8);
  EXPECT_EQ(wrap_gene(9), 0);
  EXPECT_EQ(wrap_gene(-9), 0);
  EXPECT_EQ(wrap_gene(17), 8);
  EXPECT_EQ(wrap_gene(4), 4);
  EXPECT_EQ(clamp_round(-3.2, 0, 90), 0);
  EXPECT_EQ(clamp_round(93.7, 0, 90), 90);
  EXPECT_EQ(clamp_round(12.5, 0, 90), 12);  // ties to even
  EXPECT_EQ(clamp_round(13.5, 0, 90), 14);

  Genome parent;  // theta = 0, p = 0, all rows (0, 0): at the lower bounds
  const int n = 40000;
  int theta_zero = 0, p_zero = 0, f_eight = 0, f_one = 0;
  for (int i = 0; i < n; ++i) {
    RandomStream rng(3, 2, i);
    const Genome c = mutate_genome(parent, GenomeSpace{}, rng);
    for (const auto& r : c.rows) {
      ASSERT_GE(r.f, 0);
      ASSERT_LE(r.f, 8);
      ASSERT_GE(r.phi, 0);
      ASSERT_LE(r.phi, 8);
    }
    ASSERT_GE(c.orientation_deg, 0);
    ASSERT_GE(c.core_pressure_pa, 0);
    ASSERT_EQ(c.orientation_deg, std::floor(c.orientation_deg));
    ASSERT_EQ(c.core_pressure_pa, std::floor(c.core_pressure_pa));
    theta_zero += c.orientation_deg == 0;
    p_zero += c.core_pressure_pa == 0;
    f_eight += c.rows[0].f == 8;
    f_one += c.rows[0].f == 1;
  }
  // Clipping: P(round(0 + 9 z) <= 0) = P(z < 0.5 / 9) = Phi(0.0556) = 0.5222; pressure Phi(0.5/1200) = 0.5002.
  // Wrapping: f = 8 from round(0.9 z) = -1, P(-1.5 < 0.9 z < -0.5) = Phi(-0.5556) - Phi(-1.6667) = 0.2415,
  // the mirror image of f = 1.
  const double tol = 5 * 0.5 / std::sqrt(n);  // 5 standard errors of a proportion
  EXPECT_NEAR(theta_zero / double(n), 0.5222, tol);
  EXPECT_NEAR(p_zero / double(n), 0.5002, tol);
  EXPECT_NEAR(f_eight / double(n), 0.2415, tol);
  EXPECT_NEAR(f_one / double(n), 0.2415, tol);
}

TEST(SearchGenome, FixedGenesNeverChange) {
  GenomeSpace semi;
  semi.orientation_free = false;
  semi.fixed_orientation_deg = 90;
  GenomeSpace closed = semi;
  closed.pressure_free = false;
  closed.fixed_core_pressure_pa = 12000;
  for (int i = 0; i < 200; ++i) {
    RandomStream a(1, 1, i), b(1, 1, i);
    Genome gs = random_genome(semi, a), gc = random_genome(closed, b);
    EXPECT_EQ(gs.orientation_deg, 90);
    EXPECT_EQ(gc.orientation_deg, 90);
    EXPECT_EQ(gc.core_pressure_pa, 12000);
    for (int k = 1; k < 5; ++k) {
      RandomStream m(1, 1, 1000 + i * 10 + k);
      gs = mutate_genome(gs, semi, m);
      gc = mutate_genome(gc, closed, m);
      EXPECT_EQ(gs.orientation_deg, 90);
      EXPECT_EQ(gc.orientation_deg, 90);
      EXPECT_EQ(gc.core_pressure_pa, 12000);
    }
  }
}

TEST(SearchGenome, RandomGenomeCoversTheWholeRangeUniformly) {
  std::array<int, 9> f_counts{};
  int theta_max = 0, theta_min = 0;
  const int n = 18000;
  for (int i = 0; i < n; ++i) {
    RandomStream rng(11, 5, i);
    const Genome g = random_genome(GenomeSpace{}, rng);
    ++f_counts[g.rows[2].f];
    theta_max += g.orientation_deg == 90;
    theta_min += g.orientation_deg == 0;
  }
  for (int c : f_counts) EXPECT_NEAR(c / double(n), 1.0 / 9, 5 * std::sqrt(1.0 / 9 * 8 / 9 / n));
  EXPECT_GT(theta_max, 0);
  EXPECT_GT(theta_min, 0);
}

TEST(SearchGenome, ScheduleRowsFollowActuationScheduleAndRoundTripThroughTheReader) {
  RandomStream rng(5, 1, 0);
  const Genome g = random_genome(GenomeSpace{}, rng);
  const Schedule direct = Schedule::from_genome(g, 1.237, 2);
  const Schedule read = parse_schedule(genome_schedule_yaml(g, "test"), "generated.yaml");
  ASSERT_TRUE(read.genome.has_value());
  EXPECT_TRUE(*read.genome == g);
  EXPECT_EQ(read.matrix, direct.matrix);
  EXPECT_EQ(read.matrix, genome_matrix(g));
  EXPECT_EQ(read.orientation_deg, g.orientation_deg);
  EXPECT_EQ(read.core_pressure_pa, g.core_pressure_pa);
  EXPECT_EQ(read.repeats, 2);
  EXPECT_DOUBLE_EQ(read.duration(), 16 * 1.237);
  for (int r = 0; r < kNumRows; ++r) EXPECT_EQ(read.matrix[r], genome_row(g.rows[r].f, g.rows[r].phi));
}

TEST(SearchGenome, HandDesignedGenomesGiveTheStudysMatrices) {
  // Rolling: bladder b (1..8) alone in column 9 - b, feet never active.
  const ScheduleMatrix roll = genome_matrix(rolling_genome());
  for (int b = 1; b <= 8; ++b)
    for (int col = 1; col <= 8; ++col) EXPECT_EQ(roll[b - 1][col - 1], col == 9 - b ? 1 : 0) << b << " " << col;
  for (int row : {8, 9})
    for (int v : roll[row]) EXPECT_EQ(v, 0);
  // Inching: bladders 1-4 and foot B on odd columns, foot A on even columns, bladders 5-8 never.
  const ScheduleMatrix inch = genome_matrix(inching_genome());
  for (int col = 1; col <= 8; ++col) {
    const int odd = col % 2;
    for (int b = 1; b <= 4; ++b) EXPECT_EQ(inch[b - 1][col - 1], odd);
    for (int b = 5; b <= 8; ++b) EXPECT_EQ(inch[b - 1][col - 1], 0);
    EXPECT_EQ(inch[8][col - 1], 1 - odd);
    EXPECT_EQ(inch[9][col - 1], odd);
  }
  EXPECT_EQ(rolling_genome().orientation_deg, 0);
  EXPECT_EQ(rolling_genome().core_pressure_pa, 12000);
  EXPECT_EQ(inching_genome().orientation_deg, 90);
  EXPECT_EQ(inching_genome().core_pressure_pa, 0);
}

TEST(SearchHillClimber, KeepsAChildOnlyIfStrictlyFaster) {
  EXPECT_TRUE(keep_child(0.11, 0.1));
  EXPECT_FALSE(keep_child(0.1, 0.1));
  EXPECT_FALSE(keep_child(0.09, 0.1));
  EXPECT_FALSE(keep_child(std::nan(""), 0.1));
  EXPECT_TRUE(keep_child(-1.0, -std::numeric_limits<double>::infinity()));

  // A flat landscape: no child is ever strictly better, so every climber keeps its start.
  SearchSetup setup;
  setup.runs = 3;
  setup.generations = 6;
  HillClimber flat(setup);
  std::vector<Genome> starts;
  while (!flat.done()) {
    const auto genomes = flat.propose();
    if (starts.empty()) starts = genomes;
    flat.accept(std::vector<double>(genomes.size(), 0.5));
  }
  for (int c = 0; c < 3; ++c) EXPECT_TRUE(flat.best_genomes()[c] == starts[c]);

  // The synthetic landscape: the kept genome is always the best evaluated so far.
  const Environment env{"flat", 0};
  HillClimber climber(setup);
  std::vector<double> best_seen(3, -std::numeric_limits<double>::infinity());
  while (!climber.done()) {
    const auto genomes = climber.propose();
    std::vector<double> speeds;
    for (const auto& g : genomes) speeds.push_back(synthetic_speed(g, env, "exact"));
    for (int c = 0; c < 3; ++c) best_seen[c] = std::max(best_seen[c], speeds[c]);
    climber.accept(speeds);
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(climber.best_speeds()[c], best_seen[c]);
      EXPECT_EQ(synthetic_speed(climber.best_genomes()[c], env, "exact"), climber.best_speeds()[c]);
    }
  }
  ASSERT_EQ(climber.history().size(), 7u);
  for (size_t g = 1; g < climber.history().size(); ++g)
    for (int c = 0; c < 3; ++c) EXPECT_GE(climber.history()[g][c], climber.history()[g - 1][c]);
}

std::vector<std::vector<double>> run_method(const std::string& name, SearchSetup setup, const Environment& env) {
  auto m = make_search_method(name, setup);
  while (!m->done()) {
    const auto genomes = m->propose();
    std::vector<double> speeds;
    for (const auto& g : genomes) speeds.push_back(synthetic_speed(g, env, "exact"));
    m->accept(speeds);
  }
  return m->history();
}

TEST(SearchHillClimber, DeterministicBySeedAndIndependentOfTheOtherClimbers) {
  const Environment env{"hill", 15};
  SearchSetup setup;
  setup.runs = 5;
  setup.generations = 20;
  for (const std::string method : {"hill", "cmaes"}) {
    const auto a = run_method(method, setup, env), b = run_method(method, setup, env);
    EXPECT_EQ(a, b) << method;
    SearchSetup other = setup;
    other.seed = 2;
    EXPECT_NE(run_method(method, other, env), a) << method;
    // Climbers 1..3 of a three-climber run are climbers 1..3 of the five-climber run: no
    // climber's draws depend on how many there are (or on which rank evaluates them).
    SearchSetup fewer = setup;
    fewer.runs = 3;
    const auto c = run_method(method, fewer, env);
    ASSERT_EQ(c.size(), a.size());
    for (size_t g = 0; g < a.size(); ++g)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(c[g][k], a[g][k]) << method << " g " << g;
  }
}

TEST(SearchCheckpoint, StateRoundTripsExactlyThroughHdf5) {
  SearchState s;
  s.integers["generation"] = 12;
  s.integers["seed"] = (1L << 40) + 3;
  s.texts["experiment"] = "flat_open";
  s.texts["fidelity"] = "";
  s.arrays["history"] = {0.1, -0.0, 1e-300, -std::numeric_limits<double>::infinity(), 0.30000000000000004};
  s.arrays["empty"] = {};
  const std::string path = temp_dir("checkpoint").string() + "/state.h5";
  write_checkpoint(path, s);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const SearchState r = read_checkpoint(path);
  EXPECT_EQ(r.integers, s.integers);
  EXPECT_EQ(r.texts, s.texts);
  ASSERT_EQ(r.arrays.size(), s.arrays.size());
  for (const auto& [k, v] : s.arrays) {
    ASSERT_EQ(r.arrays.at(k).size(), v.size()) << k;
    for (size_t i = 0; i < v.size(); ++i) EXPECT_EQ(std::signbit(r.arrays.at(k)[i]), std::signbit(v[i]));
    EXPECT_EQ(r.arrays.at(k), v) << k;
  }
  // Equal states give identical bytes (no time stamps in the file).
  const std::string again = temp_dir("checkpoint_again").string() + "/state.h5";
  write_checkpoint(again, s);
  EXPECT_EQ(read_text(path), read_text(again));
  // Not a checkpoint: a located InputError.
  std::ofstream(path + ".bad") << "not hdf5";
  EXPECT_THROW(read_checkpoint(path + ".bad"), InputError);
}

TEST(SearchCheckpoint, RestoredMethodsContinueExactlyAsUninterrupted) {
  const Environment env{"flat", 0};
  SearchSetup setup;
  setup.runs = 3;
  setup.generations = 40;
  const std::string dir = temp_dir("restore").string();
  for (const std::string name : {"hill", "cmaes"}) {
    const auto whole = run_method(name, setup, env);
    auto first = make_search_method(name, setup);
    for (int step = 0; step < 3; ++step) {
      const auto genomes = first->propose();
      std::vector<double> speeds;
      for (const auto& g : genomes) speeds.push_back(synthetic_speed(g, env, "exact"));
      first->accept(speeds);
    }
    SearchState s;
    first->save(s);
    write_checkpoint(dir + "/" + name + ".h5", s);
    auto second = make_search_method(name, setup);
    second->restore(read_checkpoint(dir + "/" + name + ".h5"), name);
    while (!second->done()) {
      const auto genomes = second->propose();
      std::vector<double> speeds;
      for (const auto& g : genomes) speeds.push_back(synthetic_speed(g, env, "exact"));
      second->accept(speeds);
    }
    EXPECT_EQ(second->history(), whole) << name;
  }
}

TEST(SearchCmaEs, SameBudgetAndStartsAsTheHillClimber) {
  const Environment env{"flat", 0};
  SearchSetup setup;
  setup.runs = 4;
  setup.generations = 60;
  const auto hill = run_method("hill", setup, env), cma = run_method("cmaes", setup, env);
  ASSERT_EQ(cma.size(), hill.size());  // generations + 1 evaluations per run each
  EXPECT_EQ(cma[0], hill[0]);          // the same random starts
  for (size_t g = 1; g < cma.size(); ++g)
    for (int r = 0; r < 4; ++r) EXPECT_GE(cma[g][r], cma[g - 1][r]);
  CmaEs c(setup);
  EXPECT_EQ(c.dimension(), 22);
  EXPECT_EQ(c.lambda(), 4 + static_cast<int>(std::floor(3 * std::log(22.0))));
  // Decoding rounds, clips theta and p, and wraps the row genes.
  Eigen::VectorXd x = Eigen::VectorXd::Constant(22, 0.5);
  x[0] = -0.2;      // theta -> 0
  x[1] = 1.3;       // p -> 12000
  x[2] = -1.0 / 9;  // f_1 = -1 -> 8
  x[3] = 10.2 / 9;  // phi_1 = 10 -> 1
  const Genome g = c.decode(x);
  EXPECT_EQ(g.orientation_deg, 0);
  EXPECT_EQ(g.core_pressure_pa, 12000);
  EXPECT_EQ(g.rows[0].f, 8);
  EXPECT_EQ(g.rows[0].phi, 1);
  EXPECT_EQ(g.rows[1].f, 4);  // round(4.5) = 4 (ties to even)
}

TEST(SearchFitness, SyntheticHasItsDocumentedOptimumAndConvergesWithFidelity) {
  for (const Environment& env : {Environment{"flat", 0}, Environment{"hill", 15}}) {
    const Genome best = synthetic_optimum(env);
    const double v_max = env.slope_deg > 0 ? 0.03 : 0.2;
    EXPECT_DOUBLE_EQ(synthetic_speed(best, env, "exact"), v_max);
    for (int i = 0; i < 500; ++i) {
      RandomStream rng(9, 1, i);
      const Genome g = random_genome(GenomeSpace{}, rng);
      const double exact = synthetic_speed(g, env, "exact");
      EXPECT_LE(exact, v_max);
      for (int level : {0, 3, 10})
        EXPECT_LE(std::abs(synthetic_speed(g, env, std::to_string(level)) - exact), 0.02 * std::ldexp(1.0, -level));
    }
  }
  EXPECT_THROW(synthetic_speed(Genome{}, Environment{}, "coarse"), InputError);
  EXPECT_THROW(find_fitness("no-such-fitness"), InputError);
  EXPECT_TRUE(has_fitness("synthetic"));
  register_fitness("test_constant",
                   [](const Genome&, const Environment&, const std::string&, MPI_Comm) { return 0.25; });
  EXPECT_EQ(find_fitness("test_constant")(Genome{}, Environment{}, "0", MPI_COMM_SELF), 0.25);
}

TEST(SearchParallel, FailedEvaluationsCountAsMinusInfinity) {
  EvaluationTeams teams(MPI_COMM_SELF, 1);
  std::vector<Genome> genomes(3);
  genomes[1].orientation_deg = 10;
  genomes[2].orientation_deg = 20;
  testing::internal::CaptureStderr();
  const auto speeds = teams.evaluate(genomes, [](const Genome& g, MPI_Comm) {
    if (g.orientation_deg == 10) return std::nan("");
    if (g.orientation_deg == 20) throw SolveError("no convergence");
    return 0.5;
  });
  EXPECT_NE(testing::internal::GetCapturedStderr().find("no convergence"), std::string::npos);
  const double failed = -std::numeric_limits<double>::infinity();
  EXPECT_EQ(speeds, (std::vector<double>{0.5, failed, failed}));
  EXPECT_THROW(EvaluationTeams(MPI_COMM_SELF, 2), InputError);
}

TEST(SearchStats, RankCorrelationsOfSmallExamples) {
  const std::vector<double> a = {1, 2, 3, 4}, b = {1, 3, 2, 4}, reversed = {4, 3, 2, 1};
  // One discordant pair of six: tau = (5 - 1) / 6; rank differences (0, 1, 1, 0): rho = 1 - 6 * 2 / (4 * 15).
  EXPECT_NEAR(kendall_tau(a, b), 4.0 / 6.0, 1e-15);
  EXPECT_NEAR(spearman_rho(a, b), 0.8, 1e-15);
  EXPECT_NEAR(spearman_rho(a, a), 1.0, 1e-15);
  EXPECT_NEAR(kendall_tau(a, reversed), -1.0, 1e-15);
  EXPECT_EQ(descending_ranks({3, 1, 3, 2}), (std::vector<double>{1.5, 4, 1.5, 3}));
  EXPECT_NEAR(sample_std({1, 2, 3, 4}), std::sqrt(5.0 / 3.0), 1e-15);
}

TEST(SearchExperiment, HistoryCsvRoundTripsAndReadsTheVoxelStudy) {
  const std::vector<std::vector<double>> h = {{0.1, -0.2}, {0.30000000000000004, 1e-17}};
  const std::string path = temp_dir("csv").string() + "/h.csv";
  std::ofstream(path) << history_csv(h);
  EXPECT_EQ(read_history_csv(path), h);
  EXPECT_EQ(history_csv(h).substr(0, 9), "g,f_1,f_2");
  std::ofstream(path) << "g,f_1\n0,abc\n";
  EXPECT_THROW(read_history_csv(path), InputError);
  const std::string voxel = shared_data_dir() + "/voxel-study/flat_open.csv";
  if (!std::filesystem::exists(voxel)) GTEST_SKIP() << "no voxel study data";
  const auto v = read_history_csv(voxel);
  ASSERT_EQ(v.size(), 201u);
  ASSERT_EQ(v[200].size(), 60u);
  EXPECT_NEAR(mean_of(v[200]), 0.0791, 5e-5);  // the published table (data/voxel-study/README.md)
  EXPECT_NEAR(max_of(v[200]), 0.1888, 5e-5);
}

TEST(SearchExperiment, RunsEndToEndAndExtendsAFinishedRunExactly) {
  SearchOptions o;
  o.experiments = {"flat_semi", "hill_closed"};
  o.methods = {"hill", "cmaes"};
  o.climbers = 3;
  o.generations = 8;
  o.out_dir = temp_dir("experiment").string();
  o.progress = false;
  o.validate_fidelity = "exact";
  const SearchReport report = run_search(o, MPI_COMM_SELF);
  ASSERT_EQ(report.results.size(), 4u);
  for (const auto& r : report.results) {
    const auto h = read_history_csv(r.csv);
    EXPECT_EQ(h, r.history);
    ASSERT_EQ(h.size(), 9u);
    ASSERT_EQ(h[0].size(), 3u);
    const auto& spec = find_experiment(r.experiment);
    for (int c = 0; c < 3; ++c) {
      char name[32];
      std::snprintf(name, sizeof name, "/best/climber_%02d.yaml", c + 1);
      const Schedule s = read_schedule(r.dir + name);
      ASSERT_TRUE(s.genome.has_value());
      EXPECT_TRUE(*s.genome == r.best[c]);
      EXPECT_EQ(synthetic_speed(*s.genome, spec.env, "0"), r.best_speed[c]);
      EXPECT_EQ(synthetic_speed(*s.genome, spec.env, "exact"), r.validation_speed[c]);
      if (!spec.space.orientation_free) {
        EXPECT_EQ(s.orientation_deg, spec.space.fixed_orientation_deg);
      }
      if (!spec.space.pressure_free) {
        EXPECT_EQ(s.core_pressure_pa, spec.space.fixed_core_pressure_pa);
      }
    }
  }
  EXPECT_EQ(report.hand_designed.size(), 4u);  // rolling and inching on flat and hill
  const std::string table = summary_markdown(report, o);
  EXPECT_NE(table.find("| flat_semi | hill |"), std::string::npos);
  EXPECT_NE(table.find("Spearman"), std::string::npos);

  // Asking for more generations resumes from the finished checkpoint and gives the
  // hill climber's longer run exactly (its draws depend on (seed, climber, generation) only).
  SearchOptions longer = o;
  longer.methods = {"hill"};
  longer.generations = 12;
  longer.validate_fidelity.clear();
  const SearchReport extended = run_search(longer, MPI_COMM_SELF);
  SearchOptions fresh = longer;
  fresh.out_dir = temp_dir("experiment_fresh").string();
  const SearchReport direct = run_search(fresh, MPI_COMM_SELF);
  for (size_t i = 0; i < extended.results.size(); ++i) {
    EXPECT_TRUE(extended.results[i].resumed);
    EXPECT_EQ(extended.results[i].history, direct.results[i].history);
  }
  // A checkpoint from another setup is refused with a clear error.
  SearchOptions other = longer;
  other.seed = 99;
  EXPECT_THROW(run_search(other, MPI_COMM_SELF), InputError);
}

}  // namespace
}  // namespace morphfem
