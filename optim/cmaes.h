// CMA-ES over the study's genome, as a stronger alternative to the hill climber at
// the same number of evaluations (runs x (generations + 1)).
//
// Each run is an independent (mu/mu_w, lambda)-CMA-ES (Hansen, "The CMA Evolution
// Strategy: A Tutorial", 2016, default parameters) in normalised coordinates of the
// free genes: x = theta / 90, p / 12000, f / 9, phi / 9. A point decodes to a genome
// by theta = clamp(round(90 x), 0, 90), p = clamp(round(12000 x), 0, 12000),
// f = wrap9(round(9 x)) (the hill climber's rounding, clipping and wrapping).
// Ranking maximises speed - 0.1 * |x - clamp(x, 0, 1)|^2 over the clipped genes
// (pulls the mean back inside the box). sigma starts at 0.1 (the hill climber's step: 9/90, 1200/12000, 0.9/9) and is
// kept >= 0.02 so the search never freezes below the integer resolution (1/9). Evaluation 0 of run r is the hill
// climber's random start of climber r (same stream), so both methods start from the same genomes; each iteration then
// samples lambda = 4 + floor(3 ln n) genomes (the last iteration is cut to the budget) from stream (seed, r, 2^32 +
// iteration).
#pragma once
#include <Eigen/Dense>

#include "optim/search_method.h"

namespace morphfem {

class CmaEs : public SearchMethod {
 public:
  explicit CmaEs(const SearchSetup& setup);
  std::string name() const override { return "cmaes"; }
  std::vector<Genome> propose() override;
  void accept(const std::vector<double>& speeds) override;
  bool done() const override { return evaluations_ >= setup_.generations + 1; }
  long steps() const override { return iteration_; }
  long evaluations() const override { return evaluations_; }
  const std::vector<std::vector<double>>& history() const override { return history_; }
  std::vector<Genome> best_genomes() const override { return best_; }
  std::vector<double> best_speeds() const override { return best_speed_; }
  void save(SearchState& state) const override;
  void restore(const SearchState& state, const std::string& where) override;

  int dimension() const { return n_; }
  int lambda() const { return lambda_; }
  // Genome of a point in normalised coordinates (fixed genes from the space).
  Genome decode(const Eigen::VectorXd& x) const;

 private:
  struct Run {
    Eigen::VectorXd mean, p_sigma, p_c;
    Eigen::MatrixXd cov;
    double sigma = 0.3;
  };
  SearchSetup setup_;
  int n_ = 0, lambda_ = 0, mu_ = 0;
  Eigen::VectorXd weights_;
  double mu_eff_ = 0, c_sigma_ = 0, d_sigma_ = 0, c_c_ = 0, c_1_ = 0, c_mu_ = 0, chi_n_ = 0;
  std::vector<int> gene_index_;  // flat genome index of each coordinate
  std::vector<double> scale_;    // gene = scale * x
  std::vector<bool> clipped_;    // theta and p are clipped, f and phi wrap
  long iteration_ = 0;           // completed steps (step 0 evaluates the starts)
  long evaluations_ = 0;         // per run
  std::vector<Run> runs_;
  std::vector<Genome> best_;
  std::vector<double> best_speed_;
  std::vector<std::vector<double>> history_;
  // Pending samples of the current step: per run, the points x and their steps y = (x - m) / sigma.
  std::vector<std::vector<Eigen::VectorXd>> pending_x_, pending_y_;
  std::vector<Genome> pending_genomes_;

  double boundary_penalty(const Eigen::VectorXd& x) const;
  Eigen::VectorXd encode(const Genome& g) const;
  void record(int run, double speed, const Genome& g, std::vector<double>& row_best);
};

}  // namespace morphfem
