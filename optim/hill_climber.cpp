#include "optim/hill_climber.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/errors.h"

namespace morphfem {

HillClimber::HillClimber(const SearchSetup& setup) : setup_(setup) {}

std::vector<Genome> HillClimber::propose() {
  pending_.clear();
  if (done()) return pending_;
  const int g = generation_ + 1;
  for (int c = 0; c < setup_.runs; ++c) {
    RandomStream rng(setup_.seed, static_cast<std::uint64_t>(c + 1), static_cast<std::uint64_t>(g));
    pending_.push_back(g == 0 ? random_genome(setup_.space, rng) : mutate_genome(current_[c], setup_.space, rng));
  }
  return pending_;
}

void HillClimber::accept(const std::vector<double>& speeds) {
  if (speeds.size() != pending_.size() || pending_.empty())
    throw std::logic_error("HillClimber::accept: speeds do not match the proposed genomes");
  const double kFailed = -std::numeric_limits<double>::infinity();
  if (generation_ < 0) {
    current_ = pending_;
    speed_.resize(pending_.size());
    for (size_t c = 0; c < speeds.size(); ++c) speed_[c] = std::isnan(speeds[c]) ? kFailed : speeds[c];
  } else {
    for (size_t c = 0; c < speeds.size(); ++c)
      if (!std::isnan(speeds[c]) && keep_child(speeds[c], speed_[c])) {
        current_[c] = pending_[c];
        speed_[c] = speeds[c];
      }
  }
  history_.push_back(speed_);
  pending_.clear();
  ++generation_;
}

void HillClimber::save(SearchState& state) const {
  state.integers["generation"] = generation_;
  state.arrays["genomes"] = genomes_to_array(current_);
  state.arrays["speeds"] = speed_;
  state.arrays["history"] = history_to_array(history_);
}

void HillClimber::restore(const SearchState& state, const std::string& where) {
  const long g = state.integer("generation", where);
  if (g < 0 || g > setup_.generations)
    throw InputError(where, "checkpoint generation " + std::to_string(g) + " outside 0.." +
                                std::to_string(setup_.generations) + " (asked for fewer generations than it holds?)");
  current_ = genomes_from_array(state.array("genomes", where, long(setup_.runs) * kGenomeLength), where);
  speed_ = state.array("speeds", where, setup_.runs);
  history_ = history_from_array(state.array("history", where, (g + 1) * setup_.runs), setup_.runs, where);
  generation_ = static_cast<int>(g);
  pending_.clear();
}

}  // namespace morphfem
