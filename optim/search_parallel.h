// Spreading evaluations over MPI ranks. The ranks of `world` form teams of
// `ranks_per_sim` consecutive ranks (MPI_Comm_split); each team evaluates one
// genome at a time with its own sub-communicator. Genome i of a batch goes to
// team i mod teams (round-robin). After a batch every rank holds every speed, in
// batch order, exactly as the evaluating team computed it (gathered with MPI_MAX
// over -inf fill: bit-exact), so results do not depend on the rank count.
// Speeds already known (the saved evaluations of an interrupted step) are passed
// in and not evaluated again; the remaining genomes are dealt round-robin.
#pragma once
#include <mpi.h>

#include <cstddef>
#include <functional>
#include <map>
#include <vector>

#include "optim/fitness.h"

namespace morphfem {

class EvaluationTeams {
 public:
  // Throws InputError if ranks_per_sim < 1 or does not divide the number of ranks.
  EvaluationTeams(MPI_Comm world, int ranks_per_sim);
  ~EvaluationTeams();
  EvaluationTeams(const EvaluationTeams&) = delete;
  EvaluationTeams& operator=(const EvaluationTeams&) = delete;

  int teams() const { return teams_; }
  int team() const { return team_; }
  bool world_root() const { return world_rank_ == 0; }
  MPI_Comm world() const { return world_; }
  MPI_Comm team_comm() const { return team_comm_; }

  // Evaluates speed(genome, team communicator) for every genome; NaN becomes -inf.
  // A SolveError counts as a failed evaluation (-inf); any other exception propagates
  // with a single team and aborts the MPI job with several (a lone team cannot unwind).
  // `on_done(k)` is called on world rank 0 after each of its own team's evaluations
  // with an estimate of the batch evaluations done so far (for progress lines).
  // `known[i]` is returned as the speed of genome i without evaluating it; the other
  // genomes go round-robin to the teams in batch order. `on_result(i, speed)` is called
  // on each team leader right after its team has evaluated genome i (to save it at once).
  std::vector<double> evaluate(const std::vector<Genome>& genomes,
                               const std::function<double(const Genome&, MPI_Comm)>& speed,
                               const std::function<void(long)>& on_done = nullptr,
                               const std::map<std::size_t, double>& known = {},
                               const std::function<void(std::size_t, double)>& on_result = nullptr) const;

 private:
  MPI_Comm world_;
  MPI_Comm team_comm_ = MPI_COMM_NULL;
  int world_rank_ = 0, teams_ = 1, team_ = 0, team_rank_ = 0;
};

}  // namespace morphfem
