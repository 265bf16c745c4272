// The study's hill climber (ROBOT.md): every climber starts from a random genome
// (generation 0), then in each generation mutates its genome once and keeps the
// child if it travels strictly farther. Climber c (1-based id) draws its start from
// stream (seed, c, 0) and its generation-g mutation from stream (seed, c, g), so a
// run does not depend on how climbers are spread over ranks.
#pragma once
#include "optim/search_method.h"

namespace morphfem {

class HillClimber : public SearchMethod {
 public:
  explicit HillClimber(const SearchSetup& setup);
  std::string name() const override { return "hill"; }
  std::vector<Genome> propose() override;
  void accept(const std::vector<double>& speeds) override;
  bool done() const override { return generation_ >= setup_.generations; }
  long steps() const override { return generation_ + 1; }
  long evaluations() const override { return generation_ + 1; }
  const std::vector<std::vector<double>>& history() const override { return history_; }
  std::vector<Genome> best_genomes() const override { return current_; }
  std::vector<double> best_speeds() const override { return speed_; }
  void save(SearchState& state) const override;
  void restore(const SearchState& state, const std::string& where) override;

  // Last completed generation (-1 before generation 0 is evaluated).
  int generation() const { return generation_; }

 private:
  SearchSetup setup_;
  int generation_ = -1;
  std::vector<Genome> current_;  // each climber's genome (its best so far)
  std::vector<double> speed_;    // its speed, BL/s
  std::vector<Genome> pending_;  // proposed, not yet accepted
  std::vector<std::vector<double>> history_;
};

}  // namespace morphfem
