// State records: named integers, texts and double arrays in one HDF5 file (C API).
//   root attributes: every integer (int64) and text (fixed-length string)
//   root datasets:   every array (1-D, double)
// Used for checkpoints (search experiments, resumable simulation runs). Written to
// PATH.tmp and renamed over PATH, so a run killed at any moment leaves either the
// previous or the new file, never a broken one. No time stamps are stored (object
// time tracking is off): equal records give identical bytes.
#pragma once
#include <mpi.h>

#include <map>
#include <string>
#include <vector>

namespace morphfem {

struct StateRecord {
  std::map<std::string, long> integers;
  std::map<std::string, std::string> texts;
  std::map<std::string, std::vector<double>> arrays;

  // Throw InputError(where, ...) if the entry is missing or has the wrong length (expected_size >= 0).
  long integer(const std::string& key, const std::string& where) const;
  const std::string& text(const std::string& key, const std::string& where) const;
  const std::vector<double>& array(const std::string& key, const std::string& where, long expected_size = -1) const;
  // A one-value array (a scalar state variable).
  double number(const std::string& key, const std::string& where) const;
  void set_number(const std::string& key, double value) { arrays[key] = {value}; }
};

void write_state_file(const std::string& path, const StateRecord& record);
// Throws InputError(path, ...) if the file cannot be read as a state record.
StateRecord read_state_file(const std::string& path);
// Sends rank `root`'s record to every rank of `comm` (collective).
void broadcast_state(StateRecord& record, MPI_Comm comm, int root = 0);

}  // namespace morphfem
