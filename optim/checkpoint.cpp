#include "optim/checkpoint.h"

#include "core/state_file.h"

namespace morphfem {

void write_checkpoint(const std::string& path, const SearchState& state) { write_state_file(path, state); }

SearchState read_checkpoint(const std::string& path) { return read_state_file(path); }

}  // namespace morphfem
