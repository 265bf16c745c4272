#include "optim/checkpoint.h"

#include "core/errors.h"
#include "core/state_file.h"

namespace morphfem {

void write_checkpoint(const std::string& path, const SearchState& state) { write_state_file(path, state); }

SearchState read_checkpoint(const std::string& path) { return read_state_file(path); }

void check_metadata(const SearchState& found, const SearchState& expected, const std::string& path) {
  for (const auto& [key, value] : expected.integers) {
    const long got = found.integer(key, path);
    if (got != value)
      throw InputError(path, "checkpoint was written with " + key + " = " + std::to_string(got) + ", this run has " +
                                 std::to_string(value) + " (use --restart or another --out)");
  }
  for (const auto& [key, value] : expected.texts) {
    auto it = found.texts.find(key);
    if (it == found.texts.end()) throw InputError(path, "checkpoint has no '" + key + "'");
    if (it->second != value)
      throw InputError(path, "checkpoint was written with " + key + " = '" + it->second + "', this run has '" + value +
                                 "' (use --restart or another --out)");
  }
}

}  // namespace morphfem
