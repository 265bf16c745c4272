// Independent runs spread over the ranks of an MPI communicator: job j runs on rank
// j mod size (round robin, one rank per job; the job runs its scene on
// PETSC_COMM_SELF), writes a row of `fields` numbers, and every rank gets every row
// back (one MPI_Allreduce of the disjoint rows). Used by the commands that run several
// scenes at once (robot validate / ladder / friction-sweep, robot friction-drag).
#pragma once
#include <mpi.h>

#include <functional>
#include <vector>

namespace morphfem {

// Rows of all jobs, job after job: row j is out[j * fields .. (j + 1) * fields).
// run(j, row) fills row j (zero-initialised); rows of jobs that did not run stay 0.
inline std::vector<double> run_jobs_over_ranks(int jobs, int fields, MPI_Comm comm,
                                               const std::function<void(int job, double* row)>& run) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const size_t n = static_cast<size_t>(jobs) * static_cast<size_t>(fields);
  std::vector<double> mine(n, 0.0), all(n, 0.0);
  for (int j = rank; j < jobs; j += size) run(j, mine.data() + static_cast<size_t>(j) * fields);
  MPI_Allreduce(mine.data(), all.data(), static_cast<int>(n), MPI_DOUBLE, MPI_SUM, comm);
  return all;
}

}  // namespace morphfem
