// Search checkpoints: the whole SearchState in one HDF5 file (C API).
//   root attributes: every integer (int64) and text (fixed-length string)
//   root datasets:   every array (1-D, double)
// Written to PATH.tmp and renamed over PATH, so a run killed at any moment leaves
// either the previous or the new checkpoint, never a broken one. No time stamps
// are stored (object time tracking is off): equal states give identical bytes.
#pragma once
#include <string>

#include "optim/search_method.h"

namespace morphfem {

void write_checkpoint(const std::string& path, const SearchState& state);
// Throws InputError(path, ...) if the file cannot be read as a checkpoint.
SearchState read_checkpoint(const std::string& path);

}  // namespace morphfem
