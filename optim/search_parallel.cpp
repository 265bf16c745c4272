#include "optim/search_parallel.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "core/errors.h"

namespace morphfem {

EvaluationTeams::EvaluationTeams(MPI_Comm world, int ranks_per_sim) : world_(world) {
  int size = 1;
  MPI_Comm_rank(world, &world_rank_);
  MPI_Comm_size(world, &size);
  if (ranks_per_sim < 1 || size % ranks_per_sim != 0)
    throw InputError("--ranks-per-sim", "must be >= 1 and divide the number of MPI ranks (" + std::to_string(size) +
                                            "), got " + std::to_string(ranks_per_sim));
  teams_ = size / ranks_per_sim;
  team_ = world_rank_ / ranks_per_sim;
  MPI_Comm_split(world, team_, world_rank_, &team_comm_);
  MPI_Comm_rank(team_comm_, &team_rank_);
}

EvaluationTeams::~EvaluationTeams() {
  if (team_comm_ != MPI_COMM_NULL) MPI_Comm_free(&team_comm_);
}

std::vector<double> EvaluationTeams::evaluate(const std::vector<Genome>& genomes,
                                              const std::function<double(const Genome&, MPI_Comm)>& speed,
                                              const std::function<void(long)>& on_done,
                                              const std::map<std::size_t, double>& known,
                                              const std::function<void(std::size_t, double)>& on_result) const {
  const double kFailed = -std::numeric_limits<double>::infinity();
  std::vector<double> local(genomes.size(), kFailed), all(genomes.size(), kFailed);
  std::vector<std::size_t> pending;
  for (std::size_t i = 0; i < genomes.size(); ++i) {
    auto it = known.find(i);
    if (it == known.end())
      pending.push_back(i);
    else
      local[i] = it->second;  // the same value on every rank: the reduction keeps it exactly
  }
  long mine = 0;
  for (std::size_t j = team_; j < pending.size(); j += teams_) {
    const std::size_t i = pending[j];
    double v = kFailed;
    try {
      v = speed(genomes[i], team_comm_);
    } catch (const SolveError& e) {  // a simulation that failed after all step cuts: never kept
      if (team_rank_ == 0) std::fprintf(stderr, "search: evaluation %zu failed: %s\n", i, e.what());
    } catch (const std::exception& e) {
      // With one team every rank meets the same error and unwinds together; with several,
      // the other teams would wait forever in the gather below.
      if (teams_ == 1) throw;
      std::fprintf(stderr, "search: evaluation %zu on team %d: %s\n", i, team_, e.what());
      MPI_Abort(world_, 4);
    }
    // Only the team leader contributes, so a team's ranks need not agree bit for bit.
    if (team_rank_ == 0) {
      local[i] = std::isnan(v) ? kFailed : v;
      if (on_result) on_result(i, local[i]);
    }
    ++mine;
    if (on_done && world_rank_ == 0) on_done(std::min<long>(pending.size(), mine * teams_));
  }
  // max(-inf, x) = x exactly: every entry ends up as its team leader's value.
  MPI_Allreduce(local.data(), all.data(), static_cast<int>(all.size()), MPI_DOUBLE, MPI_MAX, world_);
  return all;
}

}  // namespace morphfem
