// The evaluations of an unfinished search step, saved as each one finishes, so a
// killed search redoes only the evaluations that were running. A step (one
// propose/accept of a method) can be long: a CMA-ES iteration is lambda
// evaluations per run, at the robot budget (11 per run, lambda 13) the whole
// search, and the step checkpoint (checkpoint.h5) is written only after it.
//
// Files: DIR/partial_team_K.h5, one per evaluation team, written only by team K's
// leader (core/state_file.h: atomic rename, so a kill leaves the old or the new
// file). Each holds the checkpoint metadata, the step number, the batch size, and
// for each saved evaluation its index in the batch, its 22 genes and its speed
// (double, bit for bit). A team's file also repeats every speed reused at the
// start of the step, so rewriting it never drops an earlier session's results.
// The files are removed once the step's checkpoint is written.
#pragma once
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "optim/search_method.h"

namespace morphfem {

using BatchSpeeds = std::map<std::size_t, double>;  // index in the batch -> speed

std::string partial_step_path(const std::string& dir, int team);

// Writes `speeds` (indices into `batch`) of step `step` to `path`.
void write_partial_step(const std::string& path, const SearchState& meta, long step, const std::vector<Genome>& batch,
                        const BatchSpeeds& speeds);

struct PartialSteps {
  BatchSpeeds speeds;              // reusable: this step, the same genome at the same index
  long stale = 0;                  // saved evaluations of another step or another genome (ignored)
  std::vector<std::string> files;  // every partial file found
};

// Reads every partial file in `dir` and keeps the speeds that belong to step `step`
// of `batch`. Throws InputError(file, ...) if a file is unreadable, was written by
// another setup (metadata as checkpoint.h5: use --restart), or if two files give
// the same evaluation different speeds.
PartialSteps read_partial_steps(const std::string& dir, const SearchState& meta, long step,
                                const std::vector<Genome>& batch);

void remove_partial_steps(const std::string& dir);

}  // namespace morphfem
