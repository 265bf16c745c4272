#include "contact/friction.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"

namespace morphfem {

// F(y) = int_0^y phi:  y <= eps:        mu_s (y^2/eps - y^3/(3 eps^2))
//                      eps < y <= 2eps: mu_s 2eps/3 + eps [mu_s z + (mu_k - mu_s)(z^3 - z^4/2)], z = y/eps - 1
//                      y > 2 eps:       mu_s 2eps/3 + eps (mu_s + mu_k)/2 + mu_k (y - 2 eps)
double FrictionLaw::potential(double y) const {
  if (y <= eps) return mu_s * (y * y / eps - y * y * y / (3.0 * eps * eps));
  const double stick = mu_s * 2.0 * eps / 3.0;
  if (y <= 2.0 * eps) {
    const double z = y / eps - 1.0;
    return stick + eps * (mu_s * z + (mu_k - mu_s) * (z * z * z - 0.5 * z * z * z * z));
  }
  return stick + 0.5 * eps * (mu_s + mu_k) + mu_k * (y - 2.0 * eps);
}

double FrictionLaw::force(double y) const {
  if (y <= eps) return mu_s * (2.0 * y / eps - y * y / (eps * eps));
  if (y <= 2.0 * eps) {
    const double z = y / eps - 1.0;
    return mu_s + (mu_k - mu_s) * (3.0 * z * z - 2.0 * z * z * z);
  }
  return mu_k;
}

double FrictionLaw::force_over_y(double y) const {
  if (y <= eps) return mu_s * (2.0 / eps - y / (eps * eps));
  return force(y) / y;
}

double FrictionLaw::dforce(double y) const {
  if (y <= eps) return mu_s * (2.0 / eps - 2.0 * y / (eps * eps));
  if (y <= 2.0 * eps) {
    const double z = y / eps - 1.0;
    return (mu_k - mu_s) * (6.0 * z - 6.0 * z * z) / eps;
  }
  return 0.0;
}

FrictionTerm::FrictionTerm(const Mesh& mesh, const Partition& partition, int rank,
                           std::shared_ptr<const GroundContactTerm> ground, FrictionSpec spec)
    : mesh_(mesh), ground_(std::move(ground)), spec_(std::move(spec)) {
  const std::string where = "contact." + ground_->spec().name + ".friction";
  if (!(spec_.eps_v > 0)) throw InputError(where, "the smoothing velocity eps_v [m/s] must be > 0");
  if (spec_.lag_updates < 0) throw InputError(where, "lag_updates must be >= 0");
  const Eigen::Vector3d n = ground_->normal();
  tangent_projector_ = Eigen::Matrix3d::Identity() - n * n.transpose();

  const size_t n_regions = spec_.regions.size();
  std::vector<std::vector<double>> weights(n_regions);
  for (size_t r = 0; r < n_regions; ++r) {
    weights[r] = nodal_area_weights(mesh, mesh.faces_of(spec_.regions[r].surface));
    for (int a = 0; a < mesh.n_nodes(); ++a)
      if (weights[r][a] > 0 && !(ground_->area_weight(a) > 0))
        throw InputError(where, "friction surface '" + spec_.regions[r].surface +
                                    "' has nodes that are not contact nodes of the ground (add it to its surfaces)");
  }
  const int begin = partition.node_begin[rank], end = partition.node_begin[rank + 1];
  for (int a = begin; a < end; ++a) {
    std::vector<double> w(n_regions, 0.0);
    double total = 0.0;
    for (size_t r = 0; r < n_regions; ++r) total += (w[r] = weights[r][a]);
    if (total <= 0) continue;
    nodes_.push_back(a);
    region_weight_.push_back(w);
  }
  mu_s_.assign(nodes_.size(), 0.0);
  mu_k_.assign(nodes_.size(), 0.0);
  lambda_.assign(nodes_.size(), 0.0);
  u0_.assign(nodes_.size(), Eigen::Vector3d::Zero());
  set_time(0.0);
}

void FrictionTerm::set_time(double t) {
  std::vector<double> mu_s(spec_.regions.size()), mu_k(spec_.regions.size());
  for (size_t r = 0; r < spec_.regions.size(); ++r) {
    mu_s[r] = spec_.regions[r].mu_static(t);
    mu_k[r] = spec_.regions[r].mu_kinetic(t);
  }
  for (size_t k = 0; k < nodes_.size(); ++k) {
    double total = 0.0, s = 0.0, kin = 0.0;
    for (size_t r = 0; r < mu_s.size(); ++r) {
      total += region_weight_[k][r];
      s += region_weight_[k][r] * mu_s[r];
      kin += region_weight_[k][r] * mu_k[r];
    }
    mu_s_[k] = s / total;
    mu_k_[k] = kin / total;
  }
}

FrictionLaw FrictionTerm::law(int k) const { return FrictionLaw{mu_s_[k], mu_k_[k], spec_.eps_v * h_}; }

void FrictionTerm::compute_normal_forces(Assembler& assembler, Vec u, std::vector<double>& lambda) const {
  const std::vector<double>& u_local = assembler.gather(u);
  lambda.assign(nodes_.size(), 0.0);
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const int node = nodes_[k];
    const int slot = assembler.node_slot(node);
    const double d = ground_->gap(mesh_.X.row(node).transpose() + Eigen::Vector3d::Map(&u_local[3 * slot]));
    if (d < ground_->dhat()) lambda[k] = ground_->normal_force(ground_->area_weight(node), d);
  }
}

void FrictionTerm::begin_step(Assembler& assembler, Vec u0, double t0, double t1) {
  h_ = std::max(t1 - t0, std::numeric_limits<double>::min());
  lag_count_ = 0;
  compute_normal_forces(assembler, u0, lambda_);
  const std::vector<double>& u_local = assembler.gather(u0);
  for (size_t k = 0; k < nodes_.size(); ++k)
    u0_[k] = Eigen::Vector3d::Map(&u_local[3 * assembler.node_slot(nodes_[k])]);
}

bool FrictionTerm::update_after_solve(Assembler& assembler, Vec u1) {
  if (lag_count_ >= spec_.lag_updates) return false;  // same count on every rank
  std::vector<double> lambda;
  compute_normal_forces(assembler, u1, lambda);
  double local[2] = {0.0, 0.0};  // largest change, largest lambda [N]
  for (size_t k = 0; k < nodes_.size(); ++k) {
    local[0] = std::max(local[0], std::abs(lambda[k] - lambda_[k]));
    local[1] = std::max(local[1], lambda[k]);
  }
  double global[2];
  MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_MAX, assembler.comm());
  if (!(global[0] > spec_.lag_tolerance * global[1])) return false;
  lambda_ = lambda;
  ++lag_count_;
  return true;
}

// D = lambda F(y), y = |r|, r = P (u - u0):
// grad = lambda phi/y r,  Hess = lambda [phi/y P + (phi' - phi/y) rhat rhat^T].
double lagged_friction(const FrictionLaw& law, double lambda, const Eigen::Matrix3d& tangent_projector,
                       const Eigen::Vector3d& dx, bool clamp_drop, Eigen::Vector3d* grad, Eigen::Matrix3d* hess) {
  const Eigen::Vector3d r = tangent_projector * dx;
  const double y = r.norm();
  const double phi_over_y = law.force_over_y(y);
  if (grad) *grad = lambda * phi_over_y * r;
  if (hess) {
    *hess = lambda * phi_over_y * tangent_projector;
    if (y > 0) {
      double dphi = law.dforce(y);
      if (clamp_drop) dphi = std::max(dphi, 0.0);
      const Eigen::Vector3d rhat = r / y;
      *hess += lambda * (dphi - phi_over_y) * rhat * rhat.transpose();
    }
  }
  return lambda * law.potential(y);
}

double FrictionTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  if (g) g->setZero(3);
  if (H) H->setZero(3, 3);
  const double lambda = lambda_[k];
  if (!(lambda > 0)) return 0.0;
  Eigen::Vector3d grad;
  Eigen::Matrix3d hess;
  const double energy =
      lagged_friction(law(k), lambda, tangent_projector_, s.u.row(0).transpose() - u0_[k],
                      spec_.project_hessian && !exact_hessian_, g ? &grad : nullptr, H ? &hess : nullptr);
  if (g) *g = grad;
  if (H) *H = hess;
  return energy;
}

FrictionTerm::NodalFriction FrictionTerm::nodal_friction(Assembler& assembler, Vec u) const {
  const int n = mesh_.n_nodes();
  const std::vector<double>& u_local = assembler.gather(u);
  std::vector<double> buffer(5 * static_cast<size_t>(n), 0.0);  // force (3), status, slip
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const int node = nodes_[k];
    const FrictionLaw f = law(static_cast<int>(k));
    const Eigen::Vector3d r =
        tangent_projector_ * (Eigen::Vector3d::Map(&u_local[3 * assembler.node_slot(node)]) - u0_[k]);
    const double y = r.norm();
    const Eigen::Vector3d force = -lambda_[k] * f.force_over_y(y) * r;
    for (int i = 0; i < 3; ++i) buffer[5 * node + i] = force[i];
    buffer[5 * node + 3] = lambda_[k] > 0 ? (y < f.eps ? 1.0 : 2.0) : 0.0;
    buffer[5 * node + 4] = y;
  }
  std::vector<double> sum(buffer.size(), 0.0);
  MPI_Allreduce(buffer.data(), sum.data(), static_cast<int>(sum.size()), MPI_DOUBLE, MPI_SUM, assembler.comm());
  NodalFriction out;
  out.force.setZero(n, 3);
  out.status.assign(n, 0);
  out.slip.assign(n, 0.0);
  for (int a = 0; a < n; ++a) {
    for (int i = 0; i < 3; ++i) out.force(a, i) = sum[5 * a + i];
    out.status[a] = static_cast<int>(std::lround(sum[5 * a + 3]));
    out.slip[a] = sum[5 * a + 4];
  }
  return out;
}

double FrictionTerm::dissipated(Assembler& assembler, Vec u) const {
  const std::vector<double>& u_local = assembler.gather(u);
  double local = 0.0;
  for (size_t k = 0; k < nodes_.size(); ++k) {
    const FrictionLaw f = law(static_cast<int>(k));
    const Eigen::Vector3d r =
        tangent_projector_ * (Eigen::Vector3d::Map(&u_local[3 * assembler.node_slot(nodes_[k])]) - u0_[k]);
    const double y = r.norm();
    local += lambda_[k] * f.force(y) * y;
  }
  double global = 0.0;
  MPI_Allreduce(&local, &global, 1, MPI_DOUBLE, MPI_SUM, assembler.comm());
  return global;
}

}  // namespace morphfem
