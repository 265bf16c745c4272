// Partial steps (optim/search_partial.h): the evaluations of an unfinished search
// step saved as they finish. Round trip, which saved speeds a step may reuse,
// refused files, and the experiment loop reusing them instead of evaluating again.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "core/errors.h"
#include "core/state_file.h"
#include "optim/fitness.h"
#include "optim/search_experiment.h"
#include "optim/search_method.h"
#include "optim/search_partial.h"
#include "tests/support/temp_dir.h"

namespace morphfem {
namespace {

SearchOptions cmaes_options(const std::string& dir) {
  SearchOptions o;
  o.experiments = {"flat_open"};
  o.methods = {"cmaes"};
  o.climbers = 3;
  o.generations = 8;  // step 0: 3 random starts; step 1: 8 per run (cut from lambda = 13), 24 evaluations
  o.out_dir = dir;
  o.progress = false;
  o.hand_designed = false;
  return o;
}

// The batch of step 1 (the first CMA-ES iteration, after step 0's random starts) as
// the runner proposes it for these options (its setup, as SearchRunner::run builds it).
std::vector<Genome> iteration_batch(const SearchOptions& o) {
  const auto& spec = find_experiment(o.experiments[0]);
  SearchSetup setup;
  setup.space = spec.space;
  setup.runs = o.climbers;
  setup.generations = o.generations;
  setup.seed = o.seed;
  auto method = make_search_method(o.methods[0], setup);
  std::vector<double> speeds;
  for (const Genome& g : method->propose()) speeds.push_back(synthetic_speed(g, spec.env, o.fidelity));
  method->accept(speeds);
  return method->propose();
}

TEST(SearchPartial, SpeedsRoundTripBitForBitAndOnlyTheirStepAndGenomesAreReused) {
  const std::string dir = temp_dir("partial_roundtrip").string();
  const SearchOptions o = cmaes_options(dir);
  const SearchState meta = search_metadata(find_experiment("flat_open"), "cmaes", o);
  const std::vector<Genome> batch = iteration_batch(o);
  ASSERT_EQ(batch.size(), 24u);
  const double failed = -std::numeric_limits<double>::infinity();
  write_partial_step(partial_step_path(dir, 0), meta, 1, batch, {{0, 0.1 / 3}, {4, failed}});
  write_partial_step(partial_step_path(dir, 1), meta, 1, batch, {{0, 0.1 / 3}, {7, -2.5e-3}});

  const PartialSteps p = read_partial_steps(dir, meta, 1, batch);
  EXPECT_EQ(p.files.size(), 2u);
  EXPECT_EQ(p.stale, 0);
  EXPECT_EQ(p.speeds, (BatchSpeeds{{0, 0.1 / 3}, {4, failed}, {7, -2.5e-3}}));

  // Another step's leftovers (a kill between the checkpoint and the clean-up) are stale.
  const PartialSteps later = read_partial_steps(dir, meta, 2, batch);
  EXPECT_TRUE(later.speeds.empty());
  EXPECT_EQ(later.stale, 4);

  // A different genome at a saved index is not reused: its speed belongs to the other genome.
  std::vector<Genome> other = batch;
  other[4].rows[0].f = other[4].rows[0].f == 1 ? 2 : 1;
  const PartialSteps changed = read_partial_steps(dir, meta, 1, other);
  EXPECT_EQ(changed.speeds, (BatchSpeeds{{0, 0.1 / 3}, {7, -2.5e-3}}));
  EXPECT_EQ(changed.stale, 1);

  remove_partial_steps(dir);
  EXPECT_TRUE(read_partial_steps(dir, meta, 1, batch).files.empty());
}

TEST(SearchPartial, FilesOfAnotherSetupOrDisagreeingSpeedsAreRefused) {
  const std::string dir = temp_dir("partial_refused").string();
  const SearchOptions o = cmaes_options(dir);
  const SearchState meta = search_metadata(find_experiment("flat_open"), "cmaes", o);
  const std::vector<Genome> batch = iteration_batch(o);

  SearchOptions reseeded = o;
  reseeded.seed = 7;
  write_partial_step(partial_step_path(dir, 0), search_metadata(find_experiment("flat_open"), "cmaes", reseeded), 0,
                     batch, {{1, 0.5}});
  try {
    read_partial_steps(dir, meta, 0, batch);
    ADD_FAILURE() << "a partial file of another seed was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("partial_team_0.h5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("seed"), std::string::npos) << e.what();
  }

  write_partial_step(partial_step_path(dir, 0), meta, 0, batch, {{1, 0.5}});
  write_partial_step(partial_step_path(dir, 1), meta, 0, batch, {{1, 0.25}});
  EXPECT_THROW(read_partial_steps(dir, meta, 0, batch), InputError);

  // An index outside the batch (a damaged file) is refused with the file named.
  SearchState bad = read_state_file(partial_step_path(dir, 0));
  bad.arrays["index"] = {static_cast<double>(batch.size())};
  write_state_file(partial_step_path(dir, 1), bad);
  EXPECT_THROW(read_partial_steps(dir, meta, 0, batch), InputError);
}

// The synthetic fitness, interrupted like a killed process: the evaluation number
// `interrupt_at` (0-based, counted over the whole process) throws instead.
long evaluation_count = 0, interrupt_at = -1;
SearchOptions interruptible_options(const std::string& dir) {
  register_fitness("test_interruptible",
                   [](const Genome& g, const Environment& env, const std::string& fidelity, MPI_Comm) {
                     if (evaluation_count++ == interrupt_at) throw std::runtime_error("interrupted");
                     return synthetic_speed(g, env, fidelity);
                   });
  SearchOptions o = cmaes_options(dir);
  o.fitness = "test_interruptible";
  return o;
}

// Runs `o` until evaluation `at` of the run throws, as a killed session stops.
void run_interrupted(const SearchOptions& o, long at) {
  evaluation_count = 0;
  interrupt_at = at;
  EXPECT_THROW(run_search(o, MPI_COMM_SELF), std::runtime_error);
  interrupt_at = -1;
}

TEST(SearchPartial, AResumedStepReusesTheSavedEvaluationsAndEndsAsUninterrupted) {
  const SearchOptions whole = interruptible_options(temp_dir("partial_whole").string());
  const SearchReport reference = run_search(whole, MPI_COMM_SELF);
  ASSERT_EQ(reference.results.size(), 1u);
  EXPECT_EQ(reference.results[0].evaluations_timed, 27);
  EXPECT_EQ(reference.results[0].evaluations_reused, 0);
  EXPECT_FALSE(std::filesystem::exists(partial_step_path(reference.results[0].dir, 0)));  // removed after the step

  // Interrupted in step 1 after its evaluations 0..9 (step 0 has the 3 random starts):
  // step 0's checkpoint and the 10 saved speeds are on disk.
  const SearchOptions resumed = interruptible_options(temp_dir("partial_resumed").string());
  const std::string dir = resumed.out_dir + "/flat_open/cmaes";
  run_interrupted(resumed, 3 + 10);
  ASSERT_TRUE(std::filesystem::exists(dir + "/checkpoint.h5"));
  const SearchState partial = read_state_file(partial_step_path(dir, 0));
  EXPECT_EQ(partial.integer("step", "partial"), 1);
  EXPECT_EQ(partial.array("speed", "partial").size(), 10u);

  const SearchReport r = run_search(resumed, MPI_COMM_SELF);
  EXPECT_EQ(r.results[0].evaluations_reused, 10);
  EXPECT_EQ(r.results[0].evaluations_timed, 14);
  EXPECT_TRUE(r.results[0].resumed);
  EXPECT_EQ(r.results[0].history, reference.results[0].history);
  EXPECT_EQ(r.results[0].best_speed, reference.results[0].best_speed);
  EXPECT_EQ(read_state_file(dir + "/checkpoint.h5").arrays,
            read_state_file(reference.results[0].dir + "/checkpoint.h5").arrays);
  EXPECT_FALSE(std::filesystem::exists(partial_step_path(dir, 0)));

  // A saved speed is taken as it is, not recomputed: a planted value shows up as a best.
  const SearchOptions planted = interruptible_options(temp_dir("partial_planted").string());
  const std::string planted_dir = planted.out_dir + "/flat_open/cmaes";
  run_interrupted(planted, 3 + 4);
  const std::vector<Genome> batch = iteration_batch(planted);
  const SearchState meta = search_metadata(find_experiment("flat_open"), "cmaes", planted);
  const PartialSteps saved = read_partial_steps(planted_dir, meta, 1, batch);
  ASSERT_EQ(saved.speeds.size(), 4u);  // the genomes the runner proposed are the ones computed here
  BatchSpeeds changed = saved.speeds;
  changed[2] = 1e6;
  write_partial_step(partial_step_path(planted_dir, 0), meta, 1, batch, changed);
  const SearchReport p = run_search(planted, MPI_COMM_SELF);
  double best = -1;
  for (double v : p.results[0].best_speed) best = std::max(best, v);
  EXPECT_EQ(best, 1e6);
  EXPECT_EQ(p.results[0].evaluations_timed, 20);
}

}  // namespace
}  // namespace morphfem
