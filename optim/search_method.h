// One interface for the search methods (hill climber, CMA-ES): the experiment
// loop asks a method for genomes, evaluates them (spread over MPI ranks), hands
// the speeds back and checkpoints the method's state after every step. Every
// method runs `runs` independent searches (the study's climbers) of `generations`
// + 1 evaluations each, so their best-so-far curves share one layout:
// history[g][run] = best speed of `run` after its evaluation number g (0-based).
// Methods are registered by name (make_search_method).
#pragma once
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/state_file.h"
#include "optim/genome.h"

namespace morphfem {

// Everything a checkpoint holds, for any method: named integers, texts and
// double arrays. A method's save() fills it, restore() reads it back exactly.
using SearchState = StateRecord;

struct SearchSetup {
  GenomeSpace space;
  int runs = 4;            // independent searches (climbers)
  int generations = 10;    // evaluations per run = generations + 1 (generation 0 = the random start)
  std::uint64_t seed = 1;  // run r (1-based id) draws from streams (seed, r, counter) only
};

class SearchMethod {
 public:
  virtual ~SearchMethod() = default;
  virtual std::string name() const = 0;
  // Genomes to evaluate next, in a fixed order (the same on every rank); empty when done.
  virtual std::vector<Genome> propose() = 0;
  // Speeds of the proposed genomes, in the same order (-inf for failed evaluations).
  virtual void accept(const std::vector<double>& speeds) = 0;
  virtual bool done() const = 0;
  // Completed steps (one step = one propose/accept), and evaluations done per run.
  virtual long steps() const = 0;
  virtual long evaluations() const = 0;
  // Best so far: history[g][run] for every completed evaluation index g.
  virtual const std::vector<std::vector<double>>& history() const = 0;
  virtual std::vector<Genome> best_genomes() const = 0;
  virtual std::vector<double> best_speeds() const = 0;
  virtual void save(SearchState& state) const = 0;
  // Throws InputError(where, ...) if the state does not fit this setup.
  virtual void restore(const SearchState& state, const std::string& where) = 0;
};

// "hill" (the study's hill climber) or "cmaes"; throws InputError for unknown names.
std::unique_ptr<SearchMethod> make_search_method(const std::string& name, const SearchSetup& setup);
std::vector<std::string> search_method_names();

// The study's keep-if-better rule: the child replaces the parent only if it travels
// strictly farther (a tie or a failed child keeps the parent).
inline bool keep_child(double child_speed, double parent_speed) { return child_speed > parent_speed; }

// Helpers shared by the methods' save/restore: genomes as flat arrays.
std::vector<double> genomes_to_array(const std::vector<Genome>& genomes);
std::vector<Genome> genomes_from_array(const std::vector<double>& a, const std::string& where);
std::vector<double> history_to_array(const std::vector<std::vector<double>>& history);
std::vector<std::vector<double>> history_from_array(const std::vector<double>& a, int runs, const std::string& where);

}  // namespace morphfem
