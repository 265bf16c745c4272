// `morphfem search ...`: hill-climbing experiments over shape, orientation and
// schedule (optim/), climbers spread over MPI ranks, resumable from checkpoints.
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

namespace morphfem {

// Runs the search command; returns the process exit status. Throws InputError on bad arguments.
int search_main(const std::vector<std::string>& args, MPI_Comm comm);

}  // namespace morphfem
