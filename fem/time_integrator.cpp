#include "fem/time_integrator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fem/assembly.h"
#include "fem/petsc_check.h"
#include "fem/term_state.h"

namespace morphfem {

const std::map<std::string, TimeScheme>& time_schemes() {
  static const std::map<std::string, TimeScheme> table{{"implicit_euler", TimeScheme::implicit_euler},
                                                       {"bdf1", TimeScheme::implicit_euler},
                                                       {"bdf2", TimeScheme::bdf2},
                                                       {"newmark", TimeScheme::newmark}};
  return table;
}

Bdf2Coefficients bdf2_coefficients(double w) {
  Bdf2Coefficients b;
  b.alpha0 = (1 + 2 * w) / (1 + w), b.alpha1 = -(1 + w), b.alpha2 = w * w / (1 + w);
  return b;
}

TimeIntegrator::TimeIntegrator(TimeIntegratorOptions options) : opt_(options) {
  if (!(opt_.newmark_beta > 0 && opt_.newmark_beta <= 0.5))
    throw std::invalid_argument("time integrator: newmark beta must be in (0, 1/2]");
  if (!(opt_.newmark_gamma >= 0.5 && opt_.newmark_gamma <= 1.0))
    throw std::invalid_argument("time integrator: newmark gamma must be in [1/2, 1]");
  if (!(opt_.error_tolerance > 0)) throw std::invalid_argument("time integrator: error_tolerance must be positive");
}

TimeIntegrator::~TimeIntegrator() {
  for (Vec* v : {&u_n_, &v_n_, &a_n_, &u_nm1_, &v_nm1_, &pred_, &v_new_, &a_new_, &err_})
    if (*v) VecDestroy(v);
}

void TimeIntegrator::set_initial_velocity(std::function<Eigen::Vector3d(const Eigen::Vector3d& X)> v0) {
  if (initialized()) throw std::logic_error("time integrator: the initial velocity must be set before the first step");
  v0_ = std::move(v0);
}

void TimeIntegrator::allocate(Assembler& assembler) {
  for (Vec* v : {&u_n_, &v_n_, &a_n_, &u_nm1_, &v_nm1_, &pred_, &v_new_, &a_new_, &err_})
    if (!*v) *v = assembler.create_vector();
}

void TimeIntegrator::initialize(Assembler& assembler, Vec u0, const InitialAcceleration& initial_acceleration) {
  if (initialized()) return;
  allocate(assembler);
  PETSC_CHECK(VecCopy(u0, u_n_));
  PETSC_CHECK(VecCopy(u0, u_nm1_));
  // v_0 = v0(X) on the free dofs; constrained dofs start at rest.
  if (v0_) {
    PetscScalar* a;
    PETSC_CHECK(VecGetArray(v_n_, &a));
    const PetscInt begin = assembler.owned_dof_begin();
    for (PetscInt node = begin / 3; node < assembler.owned_dof_end() / 3; ++node) {
      const Eigen::Vector3d v = v0_(assembler.mesh().X.row(node).transpose());
      for (int i = 0; i < 3; ++i)
        if (!assembler.constrained()[3 * node + i]) a[3 * node + i - begin] = v[i];
    }
    PETSC_CHECK(VecRestoreArray(v_n_, &a));
  }
  PETSC_CHECK(VecCopy(v_n_, v_nm1_));
  steps_done_ = 0;
  h_prev_ = 0.0;
  have_a0_ = false;
  if (opt_.equilibrium_initial_acceleration && opt_.scheme != TimeScheme::implicit_euler) {
    initial_acceleration(a_n_);
    have_a0_ = true;
  }
}

bool TimeIntegrator::takes_bdf2(double h, double h_prev) const {
  return opt_.scheme == TimeScheme::bdf2 && !(h > kBdf2MaxStepRatio * h_prev);
}

void TimeIntegrator::begin_step(double t0, double t1) {
  if (!initialized()) throw std::logic_error("time integrator: begin_step before initialize");
  h_ = t1 - t0;
  if (!(h_ > 0)) throw std::invalid_argument("time integrator: the time step must be positive");
  const double h = h_;
  PetscScalar coeff[4];
  Vec vecs[4];
  int count = 0;
  if (opt_.scheme == TimeScheme::implicit_euler || (opt_.scheme == TimeScheme::bdf2 && steps_done_ == 0 && !have_a0_)) {
    // u_pred = u_n + h v_n, c = 1/h^2
    kind_ = StepKind::implicit_euler;
    c_ = 1.0 / (h * h);
    coeff[0] = 1.0, vecs[0] = u_n_;
    coeff[1] = h, vecs[1] = v_n_;
    count = 2;
  } else if (steps_done_ == 0 || !takes_bdf2(h, h_prev_)) {
    // u_pred = u_n + h v_n + h^2 (1/2 - beta) a_n, c = 1/(beta h^2); the first bdf2
    // step and one that grows too much are trapezoidal (beta = 1/4, gamma = 1/2).
    kind_ = StepKind::newmark;
    const bool own = opt_.scheme == TimeScheme::newmark;
    beta_ = own ? opt_.newmark_beta : 0.25;
    gamma_ = own ? opt_.newmark_gamma : 0.5;
    c_ = 1.0 / (beta_ * h * h);
    coeff[0] = 1.0, vecs[0] = u_n_;
    coeff[1] = h, vecs[1] = v_n_;
    coeff[2] = h * h * (0.5 - beta_), vecs[2] = a_n_;
    count = 3;
  } else {
    kind_ = StepKind::bdf2;
    w_ = h / h_prev_;
    const Bdf2Coefficients b = bdf2_coefficients(w_);
    c_ = b.alpha0 * b.alpha0 / (h * h);
    coeff[0] = -b.alpha1 / b.alpha0, vecs[0] = u_n_;
    coeff[1] = -b.alpha2 / b.alpha0, vecs[1] = u_nm1_;
    coeff[2] = -h * b.alpha1 / (b.alpha0 * b.alpha0), vecs[2] = v_n_;
    coeff[3] = -h * b.alpha2 / (b.alpha0 * b.alpha0), vecs[3] = v_nm1_;
    count = 4;
  }
  PETSC_CHECK(VecSet(pred_, 0.0));
  PETSC_CHECK(VecMAXPY(pred_, count, coeff, vecs));
  begun_ = true;
}

// v_{n+1} and a_{n+1} of the current step from its converged displacement u1.
void TimeIntegrator::step_rates(Vec u1, Vec v1, Vec a1) {
  const double h = h_;
  switch (kind_) {
    case StepKind::implicit_euler:  // v1 = (u1 - u_n)/h, a1 = (v1 - v_n)/h
      PETSC_CHECK(VecWAXPY(v1, -1.0, u_n_, u1));
      PETSC_CHECK(VecScale(v1, 1.0 / h));
      PETSC_CHECK(VecWAXPY(a1, -1.0, v_n_, v1));
      PETSC_CHECK(VecScale(a1, 1.0 / h));
      break;
    case StepKind::newmark:  // a1 = c (u1 - u_pred), v1 = v_n + h ((1 - gamma) a_n + gamma a1)
      PETSC_CHECK(VecWAXPY(a1, -1.0, pred_, u1));
      PETSC_CHECK(VecScale(a1, c_));
      PETSC_CHECK(VecCopy(v_n_, v1));
      PETSC_CHECK(VecAXPBYPCZ(v1, h * (1 - gamma_), h * gamma_, 1.0, a_n_, a1));
      break;
    case StepKind::bdf2: {  // v1 = (alpha0 u1 + alpha1 u_n + alpha2 u_{n-1})/h, a1 likewise from v
      const Bdf2Coefficients b = bdf2_coefficients(w_);
      PETSC_CHECK(VecCopy(u1, v1));
      PETSC_CHECK(VecScale(v1, b.alpha0 / h));
      PETSC_CHECK(VecAXPBYPCZ(v1, b.alpha1 / h, b.alpha2 / h, 1.0, u_n_, u_nm1_));
      PETSC_CHECK(VecCopy(v1, a1));
      PETSC_CHECK(VecScale(a1, b.alpha0 / h));
      PETSC_CHECK(VecAXPBYPCZ(a1, b.alpha1 / h, b.alpha2 / h, 1.0, v_n_, v_nm1_));
      break;
    }
  }
}

// Local truncation error estimate (see the header) on the free dofs [m] and the
// step that would meet the tolerance.
double TimeIntegrator::error_of(Assembler& assembler, Vec v1, Vec a1, double& dt_next) {
  const double h = h_;
  int order = 2;
  if (kind_ == StepKind::implicit_euler) {  // e = h/2 (v1 - v_n)
    order = 1;
    PETSC_CHECK(VecWAXPY(err_, -1.0, v_n_, v1));
    PETSC_CHECK(VecScale(err_, 0.5 * h));
  } else {
    const double constant =
        kind_ == StepKind::newmark ? beta_ - 1.0 / 6.0 : (1 + w_) * (1 + w_) / (6 * w_ * (1 + 2 * w_));
    PETSC_CHECK(VecWAXPY(err_, -1.0, a_n_, a1));
    PETSC_CHECK(VecScale(err_, std::abs(constant) * h * h));
  }
  PetscScalar* e;
  PETSC_CHECK(VecGetArray(err_, &e));
  const PetscInt begin = assembler.owned_dof_begin();
  for (PetscInt d = begin; d < assembler.owned_dof_end(); ++d)
    if (assembler.constrained()[d]) e[d - begin] = 0.0;
  PETSC_CHECK(VecRestoreArray(err_, &e));
  PetscReal error;
  PETSC_CHECK(VecNorm(err_, NORM_INFINITY, &error));
  double factor = opt_.error_max_factor;
  if (error > 0) factor = opt_.error_safety * std::pow(opt_.error_tolerance / error, 1.0 / (order + 1));
  dt_next = h * std::clamp(factor, opt_.error_min_factor, opt_.error_max_factor);
  return error;
}

EnergyTerm::StepAdvice TimeIntegrator::advise_step(Assembler& assembler, Vec u1) {
  if (!opt_.adaptive) return {};
  double dt_next = 1e300;
  const double err = estimate_error(assembler, u1, dt_next);
  return {err <= 2.0 * opt_.error_tolerance, dt_next};
}

double TimeIntegrator::estimate_error(Assembler& assembler, Vec u1, double& dt_next) {
  if (!initialized() || !begun_) throw std::logic_error("time integrator: estimate_error before begin_step");
  step_rates(u1, v_new_, a_new_);
  return error_of(assembler, v_new_, a_new_, dt_next);
}

void TimeIntegrator::end_step(Assembler& assembler, Vec u1) {
  step_rates(u1, v_new_, a_new_);
  last_error_ = error_of(assembler, v_new_, a_new_, suggested_dt_);
  PETSC_CHECK(VecCopy(u_n_, u_nm1_));
  PETSC_CHECK(VecCopy(v_n_, v_nm1_));
  PETSC_CHECK(VecCopy(u1, u_n_));
  PETSC_CHECK(VecCopy(v_new_, v_n_));
  PETSC_CHECK(VecCopy(a_new_, a_n_));
  h_prev_ = h_;
  ++steps_done_;
  have_a0_ = true;
}

RateRule TimeIntegrator::rate_rule(double h, double h_prev, bool has_rate) const {
  RateRule rule;
  rule.h = h;
  if (!has_rate || opt_.scheme == TimeScheme::implicit_euler) return rule;
  if (takes_bdf2(h, h_prev)) {
    rule.kind = RateRule::Kind::bdf2;
    rule.bdf2 = bdf2_coefficients(h / h_prev);
    rule.kappa = rule.bdf2.alpha0;
  } else {
    rule.kind = RateRule::Kind::trapezoidal;
    rule.kappa = 2.0;
  }
  return rule;
}

// The history (u_n, v_n, a_n, u_{n-1}, v_{n-1}) and the step bookkeeping.
void TimeIntegrator::save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) {
  state.integers[prefix + ".initialized"] = initialized();
  if (!initialized()) return;
  const std::pair<const char*, Vec> history[] = {
      {"u_n", u_n_}, {"v_n", v_n_}, {"a_n", a_n_}, {"u_nm1", u_nm1_}, {"v_nm1", v_nm1_}};
  for (const auto& [key, v] : history) save_vector(assembler, v, prefix + "." + key, state);
  state.integers[prefix + ".steps_done"] = steps_done_;
  state.integers[prefix + ".have_a0"] = have_a0_;
  state.set_number(prefix + ".h_prev", h_prev_);
  state.set_number(prefix + ".last_error", last_error_);
  state.set_number(prefix + ".suggested_dt", suggested_dt_);
}

void TimeIntegrator::load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) {
  const std::string where = "checkpoint: " + prefix;
  if (!state.integer(prefix + ".initialized", where)) return;
  allocate(assembler);
  const std::pair<const char*, Vec> history[] = {
      {"u_n", u_n_}, {"v_n", v_n_}, {"a_n", a_n_}, {"u_nm1", u_nm1_}, {"v_nm1", v_nm1_}};
  for (const auto& [key, v] : history) load_vector(assembler, state, prefix + "." + key, v, where);
  steps_done_ = static_cast<int>(state.integer(prefix + ".steps_done", where));
  have_a0_ = state.integer(prefix + ".have_a0", where) != 0;
  h_prev_ = state.number(prefix + ".h_prev", where);
  last_error_ = state.number(prefix + ".last_error", where);
  suggested_dt_ = state.number(prefix + ".suggested_dt", where);
}

}  // namespace morphfem
