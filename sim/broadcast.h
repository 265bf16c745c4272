// Broadcasts from rank 0 of the small pieces the model layer sends around: a mesh's
// matrices and lists, error messages and directory names. Collective.
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

namespace morphfem {

template <class Matrix>
void bcast_matrix(Matrix& m, MPI_Datatype type, MPI_Comm comm) {
  long dims[2] = {static_cast<long>(m.rows()), static_cast<long>(m.cols())};
  MPI_Bcast(dims, 2, MPI_LONG, 0, comm);
  m.resize(dims[0], dims[1]);
  MPI_Bcast(m.data(), static_cast<int>(m.size()), type, 0, comm);
}

inline void bcast_ints(std::vector<int>& v, MPI_Comm comm) {
  long n = static_cast<long>(v.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, comm);
  v.resize(n);
  MPI_Bcast(v.data(), static_cast<int>(n), MPI_INT, 0, comm);
}

inline void bcast_string(std::string& s, MPI_Comm comm) {
  long n = static_cast<long>(s.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, comm);
  s.resize(n);
  MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, comm);
}

}  // namespace morphfem
