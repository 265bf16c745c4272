#include "optim/cmaes.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "core/errors.h"

namespace morphfem {

namespace {
constexpr double kInitialSigma = 0.1;  // the hill climber's mutation step in normalised units (9/90, 1200/12000, 0.9/9)
constexpr double kMinSigma = 0.02;
constexpr double kMaxSigma = 2.0;
constexpr double kBoundaryPenalty = 0.1;  // BL/s per squared normalised excess
constexpr std::uint64_t kCmaStreamOffset = std::uint64_t(1) << 32;
const double kFailed = -std::numeric_limits<double>::infinity();

double finite_or_failed(double v) { return std::isnan(v) ? kFailed : v; }
}  // namespace

CmaEs::CmaEs(const SearchSetup& setup) : setup_(setup) {
  if (setup_.space.orientation_free)
    gene_index_.push_back(0), scale_.push_back(kMaxOrientationDeg), clipped_.push_back(true);
  if (setup_.space.pressure_free)
    gene_index_.push_back(1), scale_.push_back(kMaxCorePressurePa), clipped_.push_back(true);
  for (int i = 2; i < kGenomeLength; ++i)
    gene_index_.push_back(i), scale_.push_back(kGeneLevels), clipped_.push_back(false);
  n_ = static_cast<int>(gene_index_.size());
  const double n = n_;
  // Default strategy parameters (Hansen 2016, Table 1).
  lambda_ = 4 + static_cast<int>(std::floor(3 * std::log(n)));
  mu_ = lambda_ / 2;
  weights_.resize(mu_);
  for (int i = 0; i < mu_; ++i) weights_[i] = std::log(mu_ + 0.5) - std::log(i + 1.0);
  weights_ /= weights_.sum();
  mu_eff_ = 1.0 / weights_.squaredNorm();
  c_sigma_ = (mu_eff_ + 2) / (n + mu_eff_ + 5);
  d_sigma_ = 1 + 2 * std::max(0.0, std::sqrt((mu_eff_ - 1) / (n + 1)) - 1) + c_sigma_;
  c_c_ = (4 + mu_eff_ / n) / (n + 4 + 2 * mu_eff_ / n);
  c_1_ = 2 / ((n + 1.3) * (n + 1.3) + mu_eff_);
  c_mu_ = std::min(1 - c_1_, 2 * (mu_eff_ - 2 + 1 / mu_eff_) / ((n + 2) * (n + 2) + mu_eff_));
  chi_n_ = std::sqrt(n) * (1 - 1 / (4 * n) + 1 / (21 * n * n));  // E|N(0, I)|
}

Genome CmaEs::decode(const Eigen::VectorXd& x) const {
  std::array<double, kGenomeLength> v = genome_to_vector(impose_fixed(Genome{}, setup_.space));
  for (int i = 0; i < n_; ++i) {
    const double gene = scale_[i] * x[i];
    v[gene_index_[i]] = clipped_[i] ? clamp_round(gene, 0, scale_[i]) : wrap_gene(std::lrint(gene));
  }
  return genome_from_vector(v, "CmaEs::decode");
}

Eigen::VectorXd CmaEs::encode(const Genome& g) const {
  const auto v = genome_to_vector(g);
  Eigen::VectorXd x(n_);
  for (int i = 0; i < n_; ++i) x[i] = v[gene_index_[i]] / scale_[i];
  return x;
}

double CmaEs::boundary_penalty(const Eigen::VectorXd& x) const {
  double p = 0;
  for (int i = 0; i < n_; ++i)
    if (clipped_[i]) {
      const double excess = x[i] - std::clamp(x[i], 0.0, 1.0);
      p += excess * excess;
    }
  return kBoundaryPenalty * p;
}

std::vector<Genome> CmaEs::propose() {
  pending_genomes_.clear();
  pending_x_.assign(setup_.runs, {});
  pending_y_.assign(setup_.runs, {});
  if (done()) return pending_genomes_;
  for (int r = 0; r < setup_.runs; ++r) {
    if (iteration_ == 0) {
      RandomStream rng(setup_.seed, static_cast<std::uint64_t>(r + 1), 0);  // the hill climber's start
      const Genome start = random_genome(setup_.space, rng);
      pending_genomes_.push_back(start);
      pending_x_[r].push_back(encode(start));
      continue;
    }
    const Run& run = runs_[r];
    // C = B diag(d^2) B^T; a sample is x = m + sigma B diag(d) z, z ~ N(0, I).
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(run.cov);
    const Eigen::VectorXd d = eig.eigenvalues().cwiseMax(1e-20).cwiseSqrt();
    RandomStream rng(setup_.seed, static_cast<std::uint64_t>(r + 1), kCmaStreamOffset + iteration_);
    const long k = std::min<long>(lambda_, setup_.generations + 1 - evaluations_);
    for (long i = 0; i < k; ++i) {
      Eigen::VectorXd z(n_);
      for (int j = 0; j < n_; ++j) z[j] = rng.normal();
      const Eigen::VectorXd y = eig.eigenvectors() * d.cwiseProduct(z);
      const Eigen::VectorXd x = run.mean + run.sigma * y;
      pending_x_[r].push_back(x);
      pending_y_[r].push_back(y);
      pending_genomes_.push_back(decode(x));
    }
  }
  return pending_genomes_;
}

void CmaEs::accept(const std::vector<double>& speeds) {
  if (speeds.size() != pending_genomes_.size() || pending_genomes_.empty())
    throw std::logic_error("CmaEs::accept: speeds do not match the proposed genomes");
  const size_t k = speeds.size() / setup_.runs;  // samples per run in this step
  if (iteration_ == 0) {
    runs_.assign(setup_.runs, {});
    best_ = pending_genomes_;
    best_speed_.resize(setup_.runs);
    for (int r = 0; r < setup_.runs; ++r) {
      Run& run = runs_[r];
      run.mean = pending_x_[r][0];
      run.p_sigma = Eigen::VectorXd::Zero(n_);
      run.p_c = Eigen::VectorXd::Zero(n_);
      run.cov = Eigen::MatrixXd::Identity(n_, n_);
      run.sigma = kInitialSigma;
      best_speed_[r] = finite_or_failed(speeds[r]);
    }
    history_.push_back(best_speed_);
  } else {
    // Best-so-far rows, one per evaluation index, runs side by side.
    for (size_t i = 0; i < k; ++i) {
      for (int r = 0; r < setup_.runs; ++r) {
        const double s = finite_or_failed(speeds[r * k + i]);
        if (keep_child(s, best_speed_[r])) best_speed_[r] = s, best_[r] = pending_genomes_[r * k + i];
      }
      history_.push_back(best_speed_);
    }
    if (static_cast<int>(k) == lambda_) {  // a full generation: update the distribution
      for (int r = 0; r < setup_.runs; ++r) {
        Run& run = runs_[r];
        std::vector<double> value(k);
        for (size_t i = 0; i < k; ++i)
          value[i] = finite_or_failed(speeds[r * k + i]) - boundary_penalty(pending_x_[r][i]);
        std::vector<int> order(k);
        std::iota(order.begin(), order.end(), 0);
        std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return value[a] > value[b]; });
        Eigen::VectorXd y_w = Eigen::VectorXd::Zero(n_);
        for (int i = 0; i < mu_; ++i) y_w += weights_[i] * pending_y_[r][order[i]];
        // C^(-1/2) y_w through the eigendecomposition of C.
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(run.cov);
        const Eigen::VectorXd d = eig.eigenvalues().cwiseMax(1e-20).cwiseSqrt();
        const Eigen::VectorXd c_inv_sqrt_y =
            eig.eigenvectors() * (eig.eigenvectors().transpose() * y_w).cwiseQuotient(d);
        run.mean += run.sigma * y_w;
        run.p_sigma = (1 - c_sigma_) * run.p_sigma + std::sqrt(c_sigma_ * (2 - c_sigma_) * mu_eff_) * c_inv_sqrt_y;
        const double t = static_cast<double>(iteration_);  // generations updated so far, counting this one
        const bool h_sigma =
            run.p_sigma.norm() / std::sqrt(1 - std::pow(1 - c_sigma_, 2 * t)) < (1.4 + 2.0 / (n_ + 1)) * chi_n_;
        run.p_c = (1 - c_c_) * run.p_c + (h_sigma ? std::sqrt(c_c_ * (2 - c_c_) * mu_eff_) : 0.0) * y_w;
        Eigen::MatrixXd rank_mu = Eigen::MatrixXd::Zero(n_, n_);
        for (int i = 0; i < mu_; ++i) {
          const Eigen::VectorXd& y = pending_y_[r][order[i]];
          rank_mu += weights_[i] * y * y.transpose();
        }
        const double lost = h_sigma ? 0.0 : c_c_ * (2 - c_c_);
        run.cov =
            (1 - c_1_ - c_mu_) * run.cov + c_1_ * (run.p_c * run.p_c.transpose() + lost * run.cov) + c_mu_ * rank_mu;
        run.cov = 0.5 * (run.cov + run.cov.transpose()).eval();
        run.sigma *= std::exp((c_sigma_ / d_sigma_) * (run.p_sigma.norm() / chi_n_ - 1));
        run.sigma = std::clamp(run.sigma, kMinSigma, kMaxSigma);
      }
    }
  }
  evaluations_ += static_cast<long>(k);
  ++iteration_;
  pending_genomes_.clear();
}

void CmaEs::save(SearchState& state) const {
  state.integers["iteration"] = iteration_;
  state.integers["evaluations"] = evaluations_;
  std::vector<double> cma;
  for (const Run& run : runs_) {
    cma.insert(cma.end(), run.mean.data(), run.mean.data() + n_);
    cma.insert(cma.end(), run.p_sigma.data(), run.p_sigma.data() + n_);
    cma.insert(cma.end(), run.p_c.data(), run.p_c.data() + n_);
    cma.insert(cma.end(), run.cov.data(), run.cov.data() + n_ * n_);
    cma.push_back(run.sigma);
  }
  state.arrays["cma_state"] = cma;  // per run: mean, p_sigma, p_c (n each), C (n x n), sigma
  state.arrays["genomes"] = genomes_to_array(best_);
  state.arrays["speeds"] = best_speed_;
  state.arrays["history"] = history_to_array(history_);
}

void CmaEs::restore(const SearchState& state, const std::string& where) {
  iteration_ = state.integer("iteration", where);
  evaluations_ = state.integer("evaluations", where);
  if (evaluations_ < 1 || evaluations_ > setup_.generations + 1)
    throw InputError(where, "checkpoint holds " + std::to_string(evaluations_) + " evaluations per run, outside 1.." +
                                std::to_string(setup_.generations + 1));
  const long per_run = 3 * n_ + n_ * n_ + 1;
  const auto& cma = state.array("cma_state", where, per_run * setup_.runs);
  runs_.assign(setup_.runs, {});
  for (int r = 0; r < setup_.runs; ++r) {
    const double* p = cma.data() + r * per_run;
    Run& run = runs_[r];
    run.mean = Eigen::Map<const Eigen::VectorXd>(p, n_);
    run.p_sigma = Eigen::Map<const Eigen::VectorXd>(p + n_, n_);
    run.p_c = Eigen::Map<const Eigen::VectorXd>(p + 2 * n_, n_);
    run.cov = Eigen::Map<const Eigen::MatrixXd>(p + 3 * n_, n_, n_);
    run.sigma = p[3 * n_ + n_ * n_];
  }
  best_ = genomes_from_array(state.array("genomes", where, long(setup_.runs) * kGenomeLength), where);
  best_speed_ = state.array("speeds", where, setup_.runs);
  history_ = history_from_array(state.array("history", where, evaluations_ * setup_.runs), setup_.runs, where);
  pending_genomes_.clear();
}

}  // namespace morphfem
