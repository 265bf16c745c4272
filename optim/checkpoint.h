// Search checkpoints: the whole SearchState in one state file (core/state_file.h:
// atomic, byte-identical for equal states).
#pragma once
#include <string>

#include "optim/search_method.h"

namespace morphfem {

void write_checkpoint(const std::string& path, const SearchState& state);
// Throws InputError(path, ...) if the file cannot be read as a checkpoint.
SearchState read_checkpoint(const std::string& path);
// Throws InputError(path, ...) unless `found` holds every integer and text of
// `expected` (the metadata a checkpoint shares with the run that resumes it) with
// the same value.
void check_metadata(const SearchState& found, const SearchState& expected, const std::string& path);

}  // namespace morphfem
