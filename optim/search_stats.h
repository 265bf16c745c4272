// Small statistics for search results: mean, sample standard deviation, and rank
// correlations (how a ranking of climbers changes between two fidelity levels).
#pragma once
#include <vector>

namespace morphfem {

double mean_of(const std::vector<double>& x);
// Sample standard deviation sqrt(sum (x - mean)^2 / (n - 1)); 0 for n < 2.
double sample_std(const std::vector<double>& x);
double max_of(const std::vector<double>& x);
// Ranks 1..n (ties get the average of their ranks), rank 1 = largest value.
std::vector<double> descending_ranks(const std::vector<double>& x);
// Spearman's rho: Pearson correlation of the (tie-averaged) ranks; NaN if undefined.
double spearman_rho(const std::vector<double>& a, const std::vector<double>& b);
// Kendall's tau-b: (concordant - discordant) / sqrt((n0 - n1)(n0 - n2)); NaN if undefined.
double kendall_tau(const std::vector<double>& a, const std::vector<double>& b);

}  // namespace morphfem
