// Helpers for EnergyTerm::save_state / load_state (checkpoints of resumable runs).
// Keys hold no '/' (they name HDF5 datasets in one group): terms use "prefix.name".
// A run resumes on the same number of ranks (the partition, and so the node
// numbering and each rank's pieces, depends on it; the checkpoint records it).
#pragma once
#include <petscvec.h>

#include <string>
#include <vector>

#include "core/state_file.h"
#include "fem/assembly.h"

namespace morphfem {

// A global vector in node order (n_nodes x 3, row-major) under `key` (collective).
void save_vector(Assembler& assembler, Vec v, const std::string& key, StateRecord& state);
// Fills `v` from `key`; InputError(where) if missing or of the wrong size (collective).
void load_vector(Assembler& assembler, const StateRecord& state, const std::string& key, Vec v,
                 const std::string& where);

// Data of this rank's pieces (any layout), gathered in rank order under `key` with
// the per-rank counts under `key.counts` (collective).
void save_rank_data(MPI_Comm comm, const std::vector<double>& local, const std::string& key, StateRecord& state);
// This rank's part of `key`; InputError(where) if missing or written by another
// number of ranks (collective).
std::vector<double> load_rank_data(MPI_Comm comm, const StateRecord& state, const std::string& key,
                                   const std::string& where);

}  // namespace morphfem
