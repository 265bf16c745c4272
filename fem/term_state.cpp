#include "fem/term_state.h"

#include <mpi.h>

#include "core/errors.h"

namespace morphfem {

void save_vector(Assembler& assembler, Vec v, const std::string& key, StateRecord& state) {
  const RowMatrixXd field = assembler.gather_all(v);
  if (assembler.rank() == 0) state.arrays[key].assign(field.data(), field.data() + field.size());
}

void load_vector(Assembler& assembler, const StateRecord& state, const std::string& key, Vec v,
                 const std::string& where) {
  const auto& values = state.array(key, where, 3L * assembler.mesh().n_nodes());
  assembler.scatter_all(Eigen::Map<const RowMatrixXd>(values.data(), assembler.mesh().n_nodes(), 3), v);
}

void save_rank_data(MPI_Comm comm, const std::vector<double>& local, const std::string& key, StateRecord& state) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int count = static_cast<int>(local.size());
  std::vector<int> counts(size), offsets(size, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  for (int r = 1; r < size; ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(rank == 0 ? offsets.back() + counts.back() : 0);
  MPI_Gatherv(local.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, comm);
  if (rank != 0) return;
  state.arrays[key] = std::move(all);
  state.arrays[key + ".counts"] = std::vector<double>(counts.begin(), counts.end());
}

std::vector<double> load_rank_data(MPI_Comm comm, const StateRecord& state, const std::string& key,
                                   const std::string& where) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const auto& counts = state.array(key + ".counts", where);
  if (static_cast<int>(counts.size()) != size)
    throw InputError(where, "'" + key + "' was written by " + std::to_string(counts.size()) + " ranks, this run has " +
                                std::to_string(size));
  long offset = 0, total = 0;
  for (int r = 0; r < size; ++r) {
    if (r < rank) offset += static_cast<long>(counts[r]);
    total += static_cast<long>(counts[r]);
  }
  const auto& all = state.array(key, where, total);
  return std::vector<double>(all.begin() + offset, all.begin() + offset + static_cast<long>(counts[rank]));
}

}  // namespace morphfem
