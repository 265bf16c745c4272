#include "fem/solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/log_event.h"
#include "fem/petsc_check.h"
#include "fem/term_state.h"

namespace morphfem {

namespace {

PetscErrorCode form_function(SNES snes, Vec u, Vec r, void* ctx) {
  auto* self = static_cast<IncrementalSolver*>(ctx);
  try {
    double e = self->assembler().gradient(u, r);
    if (!std::isfinite(e)) PetscCall(SNESSetFunctionDomainError(snes));
  } catch (const std::exception& ex) {
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "%s", ex.what());
  }
  return 0;
}

PetscErrorCode form_jacobian(SNES, Vec u, Mat J, Mat P, void* ctx) {
  return static_cast<IncrementalSolver*>(ctx)->jacobian(u, J, P);
}

PetscErrorCode shell_mult(Mat J, Vec x, Vec y) {
  void* ctx;
  PetscCall(MatShellGetContext(J, &ctx));
  return static_cast<IncrementalSolver*>(ctx)->operator_mult(x, y);
}

PetscErrorCode form_objective(SNES, Vec u, PetscReal* e, void* ctx) {
  *e = static_cast<IncrementalSolver*>(ctx)->assembler().energy(u);
  return 0;
}

PetscErrorCode line_search_trampoline(SNESLineSearch ls, void* ctx) {
  return static_cast<IncrementalSolver*>(ctx)->line_search(ls);
}

PetscErrorCode convergence_trampoline(SNES snes, PetscInt it, PetscReal, PetscReal snorm, PetscReal fnorm,
                                      SNESConvergedReason* reason, void* ctx) {
  return static_cast<IncrementalSolver*>(ctx)->convergence(snes, it, snorm, fnorm, reason);
}

}  // namespace

IncrementalSolver::IncrementalSolver(Assembler& assembler, std::vector<DirichletCondition> bcs, SolverOptions options)
    : assembler_(assembler), bcs_(std::move(bcs)), opt_(std::move(options)) {
  PETSC_CHECK(PetscOptionsGetBool(nullptr, nullptr, "-morphfem_linesearch_monitor", &linesearch_monitor_, nullptr));
  PETSC_CHECK(PetscOptionsGetBool(nullptr, nullptr, "-morphfem_step_monitor", &step_monitor_, nullptr));
  PETSC_CHECK(
      PetscOptionsGetReal(nullptr, nullptr, "-morphfem_newton_velocity_tol", &opt_.newton_velocity_tol, nullptr));
  PetscBool extrapolate = opt_.extrapolate ? PETSC_TRUE : PETSC_FALSE;
  PETSC_CHECK(PetscOptionsGetBool(nullptr, nullptr, "-morphfem_extrapolate", &extrapolate, nullptr));
  opt_.extrapolate = extrapolate;
  std::vector<int> dofs;
  for (const auto& bc : bcs_)
    for (int n : bc.nodes)
      for (int i = 0; i < 3; ++i)
        if (bc.components[i]) dofs.push_back(3 * n + i);
  assembler_.set_constrained(dofs);
  const Mesh& mesh = assembler_.mesh();
  length_scale_ = (mesh.X.colwise().maxCoeff() - mesh.X.colwise().minCoeff()).norm();
  assembler_.setup();
  u_ = assembler_.create_vector();
  u_prev_ = assembler_.create_vector();
  work_ = assembler_.create_vector();
  H_ = assembler_.create_matrix();

  PETSC_CHECK(SNESCreate(assembler_.comm(), &snes_));
  PETSC_CHECK(SNESSetType(snes_, SNESNEWTONLS));
  PETSC_CHECK(SNESSetFunction(snes_, work_, form_function, this));
  set_jacobian();
  PETSC_CHECK(SNESSetObjective(snes_, form_objective, this));
  PETSC_CHECK(SNESSetConvergenceTest(snes_, convergence_trampoline, this, nullptr));
  PETSC_CHECK(SNESSetTolerances(snes_, 0.0, 0.0, 0.0, opt_.max_newton_its, 100000));
  SNESLineSearch ls;
  PETSC_CHECK(SNESGetLineSearch(snes_, &ls));
  PETSC_CHECK(SNESLineSearchSetType(ls, SNESLINESEARCHSHELL));
  PETSC_CHECK(SNESLineSearchShellSetUserFunc(ls, line_search_trampoline, this));

  KSP ksp;
  PC pc;
  PETSC_CHECK(SNESGetKSP(snes_, &ksp));
  PETSC_CHECK(KSPGetPC(ksp, &pc));
  if (opt_.linear_solver == "mumps" || opt_.linear_solver == "mumps_lu") {
    PETSC_CHECK(KSPSetType(ksp, J_ ? KSPGMRES : KSPPREONLY));
    if (J_) PETSC_CHECK(KSPSetTolerances(ksp, 1e-12, 1e-50, PETSC_DEFAULT, 100));
    // Every term is an energy, so the Hessian is symmetric (Assembler::create_matrix
    // marks it so): MUMPS's LDL^T (symmetric indefinite with pivoting, since the exact
    // Hessian need not be positive definite) does half the flops of LU and gives the
    // same Newton iterates (README, "Linear solvers").
    PETSC_CHECK(PCSetType(pc, opt_.linear_solver == "mumps" ? PCCHOLESKY : PCLU));
    PETSC_CHECK(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
  } else if (opt_.linear_solver == "gamg") {
    PETSC_CHECK(KSPSetType(ksp, J_ ? KSPGMRES : KSPCG));
    PETSC_CHECK(PCSetType(pc, PCGAMG));
    PETSC_CHECK(KSPSetTolerances(ksp, 1e-10, 1e-50, PETSC_DEFAULT, 2000));
    attach_near_nullspace();
  } else {
    throw InputError("solver.linear_solver",
                     "unknown linear solver '" + opt_.linear_solver + "' (allowed: mumps, mumps_lu, gamg)");
  }
  PETSC_CHECK(SNESSetFromOptions(snes_));
  apply_dirichlet(u_, 0.0);
}

IncrementalSolver::~IncrementalSolver() {
  clear_low_rank();
  SNESDestroy(&snes_);
  if (J_) MatDestroy(&J_);
  MatDestroy(&H_);
  VecDestroy(&u_);
  VecDestroy(&u_prev_);
  VecDestroy(&work_);
}

void IncrementalSolver::set_jacobian() {
  bool any_low_rank = false;
  for (const auto& term : assembler_.terms()) any_low_rank = any_low_rank || term->has_low_rank();
  if (any_low_rank) {
    // Dense low-rank Hessian parts stay out of the sparse matrix: the Newton
    // operator is a shell H + sum c v v^T, preconditioned by (a factorisation of) H.
    if (!J_) {
      const PetscInt n_local = assembler_.owned_dof_end() - assembler_.owned_dof_begin();
      PETSC_CHECK(
          MatCreateShell(assembler_.comm(), n_local, n_local, assembler_.n_dofs(), assembler_.n_dofs(), this, &J_));
      PETSC_CHECK(MatShellSetOperation(J_, MATOP_MULT, (void (*)(void))shell_mult));
    }
    PETSC_CHECK(SNESSetJacobian(snes_, J_, H_, form_jacobian, this));
  } else {
    PETSC_CHECK(SNESSetJacobian(snes_, H_, H_, form_jacobian, this));
  }
}

// Rigid-body modes from the reference coordinates of the owned nodes (GAMG).
void IncrementalSolver::attach_near_nullspace() {
  Vec coords = assembler_.create_vector();
  assembler_.scatter_all(assembler_.mesh().X, coords);
  MatNullSpace near_null;
  PETSC_CHECK(MatNullSpaceCreateRigidBody(coords, &near_null));
  PETSC_CHECK(MatSetNearNullSpace(H_, near_null));
  PETSC_CHECK(MatNullSpaceDestroy(&near_null));
  PETSC_CHECK(VecDestroy(&coords));
}

// A term whose pieces changed (self-contact candidates) makes the assembler
// rebuild its ghost scatter and nonzero pattern; the Hessian is re-created with
// the new pattern and handed to SNES (the linear solver re-factors it anyway at
// the next Newton iteration). Terms that never change keep everything as it was.
void IncrementalSolver::refresh_pieces() {
  static const PetscLogEvent event = log_event("RefreshPieces");
  LogEventScope scope(event);
  int changed = 0;
  for (const auto& term : assembler_.terms()) changed |= term->refresh_pieces(assembler_, u_) ? 1 : 0;
  int any = 0;
  MPI_Allreduce(&changed, &any, 1, MPI_INT, MPI_LOR, assembler_.comm());
  if (!any) return;
  rebuild_pattern();
  ++pattern_rebuilds_;
}

void IncrementalSolver::rebuild_pattern() {
  static const PetscLogEvent event = log_event("PatternRebuild");
  LogEventScope scope(event);
  assembler_.setup();
  PETSC_CHECK(MatDestroy(&H_));
  H_ = assembler_.create_matrix();
  if (opt_.linear_solver == "gamg") attach_near_nullspace();
  set_jacobian();
}

void IncrementalSolver::save_state(StateRecord& state) {
  static const PetscLogEvent event = log_event("SolverSave");
  LogEventScope scope(event);
  const RunStats& counters = counters_;
  save_vector(assembler_, u_, "solver.u", state);
  save_vector(assembler_, u_prev_, "solver.u_prev", state);
  state.set_number("solver.t", t_);
  state.set_number("solver.dt_prev", dt_prev_);
  state.set_number("solver.dt_next", dt_next_);
  state.set_number("solver.fnorm_scale", fnorm_scale_);
  state.integers["solver.pattern_rebuilds"] = pattern_rebuilds_;
  state.integers["solver.exact_hessian_its"] = exact_hessian_its_;
  state.integers["solver.projection_fallbacks"] = projection_fallbacks_;
  state.integers["solver.steps"] = counters.steps;
  state.integers["solver.newton_its"] = counters.newton_its;
  state.integers["solver.linear_its"] = counters.linear_its;
  state.integers["solver.step_cuts"] = counters.step_cuts;
  state.integers["solver.error_rejections"] = counters.error_rejections;
  for (const auto& [cause, n] : counters.cuts_by_cause) state.integers["solver.cuts." + cause] = n;
  state.integers["solver.terms"] = static_cast<long>(assembler_.terms().size());
  for (size_t k = 0; k < assembler_.terms().size(); ++k) {
    const std::string prefix = "term" + std::to_string(k);
    if (assembler_.rank() == 0) state.texts[prefix] = assembler_.terms()[k]->name();
    assembler_.terms()[k]->save_state(assembler_, prefix, state);
  }
}

RunStats IncrementalSolver::load_state(const StateRecord& state, const std::string& where) {
  const auto& terms = assembler_.terms();
  if (state.integer("solver.terms", where) != static_cast<long>(terms.size()))
    throw InputError(where, "the checkpoint has " + std::to_string(state.integer("solver.terms", where)) +
                                " energy terms, this scene builds " + std::to_string(terms.size()));
  for (size_t k = 0; k < terms.size(); ++k) {
    const std::string prefix = "term" + std::to_string(k);
    if (state.text(prefix, where) != terms[k]->name())
      throw InputError(where, "energy term " + std::to_string(k) + " is '" + state.text(prefix, where) +
                                  "' in the checkpoint, '" + terms[k]->name() + "' in this scene");
  }
  load_vector(assembler_, state, "solver.u", u_, where);
  load_vector(assembler_, state, "solver.u_prev", u_prev_, where);
  t_ = state.number("solver.t", where);
  dt_prev_ = state.number("solver.dt_prev", where);
  dt_next_ = state.number("solver.dt_next", where);
  fnorm_scale_ = state.number("solver.fnorm_scale", where);
  pattern_rebuilds_ = static_cast<int>(state.integer("solver.pattern_rebuilds", where));
  // Absent in checkpoints written before the adaptive projection.
  const auto optional = [&](const std::string& key) {
    return state.integers.count(key) ? static_cast<int>(state.integers.at(key)) : 0;
  };
  exact_hessian_its_ = optional("solver.exact_hessian_its");
  projection_fallbacks_ = optional("solver.projection_fallbacks");
  RunStats counters;
  counters.steps = static_cast<int>(state.integer("solver.steps", where));
  counters.newton_its = static_cast<int>(state.integer("solver.newton_its", where));
  counters.linear_its = static_cast<int>(state.integer("solver.linear_its", where));
  counters.step_cuts = static_cast<int>(state.integer("solver.step_cuts", where));
  counters.error_rejections = static_cast<int>(state.integer("solver.error_rejections", where));
  const std::string cuts = "solver.cuts.";  // absent in checkpoints written before the causes were kept
  for (auto it = state.integers.lower_bound(cuts); it != state.integers.end() && it->first.rfind(cuts, 0) == 0; ++it)
    counters.cuts_by_cause[it->first.substr(cuts.size())] = static_cast<int>(it->second);
  counters_ = counters;
  for (size_t k = 0; k < terms.size(); ++k) terms[k]->load_state(assembler_, "term" + std::to_string(k), state);
  rebuild_pattern();  // pieces that depend on the state (self-contact candidates) were rebuilt
  return counters;
}

void IncrementalSolver::clear_low_rank() {
  for (auto& lr : low_rank_) VecDestroy(&lr.v);
  low_rank_.clear();
}

PetscErrorCode IncrementalSolver::jacobian(Vec u, Mat J, Mat P) {
  try {
    for (const auto& term : assembler_.terms()) term->set_exact_hessian(exact_hessian_);
    if (exact_hessian_) ++exact_hessian_its_;
    assembler_.hessian(u, P);
    for (const auto& term : assembler_.terms()) term->set_exact_hessian(false);
    if (J_) {
      static const PetscLogEvent event = log_event("LowRank");
      LogEventScope scope(event);
      clear_low_rank();
      for (const auto& term : assembler_.terms()) term->low_rank(assembler_, u, low_rank_);
    }
  } catch (const std::exception& ex) {
    SETERRQ(PETSC_COMM_SELF, PETSC_ERR_LIB, "%s", ex.what());
  }
  if (J != P) {
    PetscCall(MatAssemblyBegin(J, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(J, MAT_FINAL_ASSEMBLY));
  }
  return 0;
}

PetscErrorCode IncrementalSolver::operator_mult(Vec x, Vec y) {
  PetscCall(MatMult(H_, x, y));
  for (const auto& lr : low_rank_) {
    PetscScalar dot;
    PetscCall(VecDot(lr.v, x, &dot));
    PetscCall(VecAXPY(y, lr.c * dot, lr.v));
  }
  return 0;
}

void IncrementalSolver::apply_dirichlet(Vec u, double t) const {
  const PetscInt begin = assembler_.owned_dof_begin(), end = assembler_.owned_dof_end();
  const Mesh& mesh = assembler_.mesh();
  PetscScalar* a;
  PETSC_CHECK(VecGetArray(u, &a));
  for (const auto& bc : bcs_)
    for (int n : bc.nodes) {
      if (3 * n < begin || 3 * n >= end) continue;
      const Eigen::Vector3d value = bc.value(mesh.X.row(n).transpose(), t);
      for (int i = 0; i < 3; ++i)
        if (bc.components[i]) a[3 * n + i - begin] = value[i];
    }
  PETSC_CHECK(VecRestoreArray(u, &a));
}

// max_a |v_a| over the nodes a (3 dofs each) of v (collective) [units of v].
double IncrementalSolver::largest_nodal_norm(Vec v) const {
  const PetscScalar* a;
  PetscInt n = 0;
  PETSC_CHECK(VecGetLocalSize(v, &n));
  PETSC_CHECK(VecGetArrayRead(v, &a));
  double local = 0.0;
  for (PetscInt i = 0; i + 2 < n; i += 3)
    local = std::max(local, std::sqrt(a[i] * a[i] + a[i + 1] * a[i + 1] + a[i + 2] * a[i + 2]));
  PETSC_CHECK(VecRestoreArrayRead(v, &a));
  double total = 0.0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_MAX, assembler_.comm());
  return total;
}

double IncrementalSolver::admissible_step(Vec u, Vec du, std::string* limiter) {
  const auto& terms = assembler_.terms();
  if (max_step_events_.size() != terms.size()) {
    max_step_events_.clear();
    for (const auto& term : terms) max_step_events_.push_back(log_event("MaxStep:" + term->name()));
  }
  double alpha = 1.0;
  if (limiter) *limiter = "none";
  for (size_t k = 0; k < terms.size(); ++k) {
    LogEventScope scope(max_step_events_[k]);
    const double a = terms[k]->max_step(assembler_, u, du);
    if (a < alpha) {
      alpha = a;
      if (limiter) *limiter = terms[k]->name();
    }
  }
  return alpha;
}

// -morphfem_linesearch_monitor: the admissible step, the term that bounds it, and
// the accepted step (diagnosing stagnating Newton iterations); after a backtrack,
// which terms' energies rose over the largest step. W is left at X - lambda Y.
PetscErrorCode IncrementalSolver::print_line_search(Vec X, Vec Y, Vec W, double lambda_max, const std::string& limiter,
                                                    double lambda, bool accepted, double slope) {
  PetscCall(PetscPrintf(assembler_.comm(), "      line search: max step %.3e (%s), %s %.3e, slope %.3e, %s Hessian\n",
                        lambda_max, limiter.c_str(), accepted ? "accepted" : "rejected down to", lambda, slope,
                        exact_hessian_ ? "exact" : "projected"));
  if (!(lambda < lambda_max)) return 0;
  const std::vector<double> before = assembler_.term_energies(X);
  PetscCall(VecWAXPY(W, -lambda_max, Y, X));
  const std::vector<double> after = assembler_.term_energies(W);
  for (size_t k = 0; k < before.size(); ++k)
    PetscCall(PetscPrintf(assembler_.comm(), "        %-24s dE %+.3e at the max step\n",
                          assembler_.terms()[k]->name().c_str(), after[k] - before[k]));
  PetscCall(VecWAXPY(W, -lambda, Y, X));  // the accepted state, as before
  return 0;
}

// Energy-based backtracking (Armijo) along the Newton direction: W = X - lambda Y.
// Rejects states with infinite energy (outside the domain); if the direction is
// not a descent direction (indefinite Hessian), falls back to steepest descent.
PetscErrorCode IncrementalSolver::line_search(SNESLineSearch ls) {
  Vec X, F, Y, W, G;
  PetscCall(SNESLineSearchGetVecs(ls, &X, &F, &Y, &W, &G));
  SNES snes;
  PetscCall(SNESLineSearchGetSNES(ls, &snes));
  static const PetscLogEvent energy_event = log_event("LSEnergy"), reproject_event = log_event("LSReproject");
  const double e0 = [&] {
    LogEventScope scope(energy_event);
    return assembler_.energy(X);
  }();
  PetscReal fnorm_old;
  PetscCall(VecNorm(F, NORM_2, &fnorm_old));
  // Adaptive projection's fallback: re-solve for Y with the projected Hessian, which
  // is positive semi-definite (the exact one may be indefinite along Y).
  const auto reproject = [&]() -> PetscErrorCode {
    LogEventScope scope(reproject_event);
    exact_hessian_ = false;
    ++projection_fallbacks_;
    Mat A, B;
    KSP ksp;
    PetscCall(SNESGetJacobian(snes, &A, &B, nullptr, nullptr));
    PetscCall(SNESComputeJacobian(snes, X, A, B));
    PetscCall(SNESGetKSP(snes, &ksp));
    PetscCall(KSPSetOperators(ksp, A, B));
    PetscCall(KSPSolve(ksp, F, Y));
    return 0;
  };
  PetscReal slope;  // d/dlambda E(X - lambda Y) at 0 = -F.Y
  double lambda = 1.0, lambda_max = 1.0;
  std::string limiter = "none";
  bool accepted = false, newton_direction = true;
  for (;;) {
    PetscCall(VecDot(F, Y, &slope));
    slope = -slope;
    if (!(slope < 0) && exact_hessian_) {  // not a descent direction
      PetscCall(reproject());
      continue;
    }
    if (!(slope < 0)) {
      newton_direction = false;  // steepest descent instead
      PetscReal ynorm;
      PetscCall(VecNorm(Y, NORM_2, &ynorm));
      PetscCall(VecCopy(F, Y));
      if (fnorm_old > 0) PetscCall(VecScale(Y, ynorm / fnorm_old));
      slope = -ynorm * fnorm_old;
    }
    // Largest admissible step along du = -Y (contact barriers, ...).
    PetscCall(VecCopy(Y, W));
    PetscCall(VecScale(W, -1.0));
    lambda = admissible_step(X, W, &limiter);
    if (!(lambda > 0)) {
      PetscCall(SNESLineSearchSetReason(ls, SNES_LINESEARCH_FAILED_DOMAIN));
      return 0;
    }
    lambda_max = lambda;
    for (int attempt = 0; attempt < 40 && !accepted; ++attempt, lambda *= 0.5) {
      PetscCall(VecWAXPY(W, -lambda, Y, X));
      LogEventScope scope(energy_event);
      const double e = assembler_.energy(W);
      if (!std::isfinite(e)) continue;
      const double noise = 1e-12 * std::max(1.0, std::abs(e0));
      if (e <= e0 + 1e-4 * lambda * slope) {
        accepted = true;
      } else if (e <= e0 + noise) {
        // Energy change below round-off: accept if the residual decreases.
        PetscCall(SNESComputeFunction(snes, W, G));
        PetscReal gnorm;
        PetscCall(VecNorm(G, NORM_2, &gnorm));
        accepted = gnorm < fnorm_old;
      }
      if (accepted) break;
    }
    // A descent direction of the exact Hessian along which the energy does not
    // decrease enough: once more with the projected one.
    if (accepted || !exact_hessian_) break;
    PetscCall(reproject());
  }
  if (opt_.newton_velocity_tol > 0) direction_max_ = newton_direction ? largest_nodal_norm(Y) : 1e300;
  if (linesearch_monitor_) PetscCall(print_line_search(X, Y, W, lambda_max, limiter, lambda, accepted, slope));
  if (!accepted) {
    PetscCall(SNESLineSearchSetReason(ls, SNES_LINESEARCH_FAILED_REDUCT));
    return 0;
  }
  // Adaptive projection: a full Newton step (not backtracked, not bounded by a
  // term's max_step) makes the next iteration exact.
  exact_hessian_ = opt_.hessian_projection == HessianProjection::adaptive && lambda == 1.0;
  PetscCall(SNESLineSearchSetLambda(ls, lambda));
  PetscCall(VecCopy(W, X));
  PetscCall(SNESComputeFunction(snes, X, F));
  PetscCall(SNESLineSearchComputeNorms(ls));
  PetscCall(SNESLineSearchSetReason(ls, SNES_LINESEARCH_SUCCEEDED));
  return 0;
}

namespace {
bool full_newton_step(SNES snes) {
  SNESLineSearch ls;
  PetscReal lambda = 0;
  if (SNESGetLineSearch(snes, &ls) || SNESLineSearchGetLambda(ls, &lambda)) return false;
  return lambda == 1.0;
}
}  // namespace

// Converged when the residual [N] fell by rtol, or is below atol_factor times the
// largest initial residual of the run, or when a full (undamped) Newton update is
// at round-off level (RMS below 1e-13 of the body's size): the linearisation then
// says the state is the solution to double precision, and the residual cannot
// fall further. Also converged when the residual, already 1e-7 of its start,
// stopped falling for two iterations: the damped updates then only move the state
// at round-off level (seen on a stiff block on a slope: 1.8e-2 N -> 1.8e-10 N in
// one step, then 50 iterations wandering at 1.8-2.0e-10 N).
// With SolverOptions::newton_velocity_tol > 0, also converged when the last Newton
// direction moves no node by more than tol * dt [m].
PetscErrorCode IncrementalSolver::convergence(SNES snes, PetscInt it, PetscReal snorm, PetscReal fnorm,
                                              SNESConvergedReason* reason) {
  *reason = SNES_CONVERGED_ITERATING;
  if (it == 0) {
    fnorm0_ = fnorm;
    fnorm_scale_ = std::max(fnorm_scale_, fnorm);
    stalled_its_ = 0;
  } else {
    stalled_its_ = fnorm >= 0.9 * fnorm_prev_ ? stalled_its_ + 1 : 0;
  }
  fnorm_prev_ = fnorm;
  if (std::isnan(fnorm)) {
    *reason = SNES_DIVERGED_FNORM_NAN;
  } else if (fnorm <= opt_.atol_factor * fnorm_scale_ || fnorm == 0.0) {
    *reason = SNES_CONVERGED_FNORM_ABS;
  } else if (it > 0 && fnorm <= opt_.rtol * fnorm0_) {
    *reason = SNES_CONVERGED_FNORM_RELATIVE;
  } else if (it > 0 && full_newton_step(snes) &&
             snorm <= 1e-13 * length_scale_ * std::sqrt(double(assembler_.n_dofs()))) {
    *reason = SNES_CONVERGED_SNORM_RELATIVE;
  } else if (stalled_its_ >= 2 && fnorm <= 1e-7 * fnorm0_) {
    *reason = SNES_CONVERGED_FNORM_RELATIVE;
  } else if (it > 0 && opt_.newton_velocity_tol > 0 && direction_max_ <= opt_.newton_velocity_tol * dt_step_) {
    *reason = SNES_CONVERGED_SNORM_RELATIVE;
  } else if (it >= opt_.max_newton_its) {
    *reason = SNES_DIVERGED_MAX_IT;
  }
  return 0;
}

// Newton's start in work_: u_n + dt (u_n - u_{n-1}) / dt_{n-1} (the last step's
// velocity times dt; SolverOptions::extrapolate) or u_n, scaled back to stay
// admissible, with the prescribed values at t_new. False (why, cause_) if even u_n
// with the prescribed increment is outside the energy's domain.
bool IncrementalSolver::predict(double t_new, std::string& why) {
  static const PetscLogEvent event = log_event("Predictor");
  LogEventScope scope(event);
  PETSC_CHECK(VecCopy(u_, work_));
  const double dt = t_new - t_;
  if (opt_.extrapolate && dt_prev_ > 0) {  // work = u + (dt/dt_prev) (u - u_prev)
    PETSC_CHECK(VecAXPY(work_, dt / dt_prev_, u_));
    PETSC_CHECK(VecAXPY(work_, -dt / dt_prev_, u_prev_));
  }
  apply_dirichlet(work_, t_new);
  // Keep the predictor admissible (no jump through a contact surface).
  PETSC_CHECK(VecAXPY(work_, -1.0, u_));
  const double alpha = admissible_step(u_, work_, nullptr);
  PETSC_CHECK(VecAYPX(work_, std::max(alpha, 0.0), u_));  // work = u + alpha (work - u)
  apply_dirichlet(work_, t_new);                          // prescribed values are never scaled
  if (!std::isfinite(assembler_.energy(work_))) {
    PETSC_CHECK(VecCopy(u_, work_));
    apply_dirichlet(work_, t_new);
    if (!std::isfinite(assembler_.energy(work_))) {
      why = "the prescribed displacement increment inverts an element";
      cause_ = "dirichlet_inverts";
      return false;
    }
  }
  return true;
}

bool IncrementalSolver::solve_step(double t_new, int& newton_its, int& linear_its, std::string& why) {
  static const PetscLogEvent hooks_event = log_event("StepHooks");
  refresh_pieces();
  const double dt = t_new - t_;
  dt_step_ = dt;
  {
    LogEventScope scope(hooks_event);
    for (const auto& term : assembler_.terms()) {
      term->set_time(t_new);
      term->begin_step(assembler_, u_, t_, t_new);
    }
  }
  if (!predict(t_new, why)) return false;
  Vec x;
  PETSC_CHECK(VecDuplicate(u_, &x));
  PETSC_CHECK(VecCopy(work_, x));
  PetscErrorCode ierr = 0;
  SNESConvergedReason reason = SNES_DIVERGED_FUNCTION_DOMAIN;
  newton_its = linear_its = 0;
  for (int outer = 0; outer <= opt_.max_outer_updates; ++outer) {
    exact_hessian_ = false;  // every solve starts projected
    ierr = SNESSolve(snes_, nullptr, x);
    if (ierr) break;
    SNESGetConvergedReason(snes_, &reason);
    PetscInt its = 0, lits = 0;
    SNESGetIterationNumber(snes_, &its);
    SNESGetLinearSolveIterations(snes_, &lits);
    newton_its += static_cast<int>(its);
    linear_its += static_cast<int>(lits);
    if (reason <= 0) break;
    bool again = false;
    LogEventScope scope(hooks_event);
    for (const auto& term : assembler_.terms()) again = term->update_after_solve(assembler_, x) || again;
    if (!again) break;
    if (outer == opt_.max_outer_updates) reason = SNES_DIVERGED_MAX_IT;
  }
  bool ok = !ierr && reason > 0 && std::isfinite(assembler_.energy(x));
  advised_dt_ = 1e300;
  if (ok) {
    LogEventScope scope(hooks_event);
    bool accept = true;
    for (const auto& term : assembler_.terms()) {
      const auto advice = term->advise_step(assembler_, x, t_, t_new);
      accept = accept && advice.accept;
      advised_dt_ = std::min(advised_dt_, advice.dt_next);
    }
    if (!accept) {
      ok = false;
      reason = SNES_CONVERGED_ITERATING;
      ierr = 0;
    }
  }
  if (ok) {
    PETSC_CHECK(VecCopy(u_, u_prev_));
    PETSC_CHECK(VecCopy(x, u_));
    LogEventScope scope(hooks_event);
    for (const auto& term : assembler_.terms()) term->end_step(assembler_, u_, t_new);
    dt_prev_ = dt;
    t_ = t_new;
  } else {
    why = ierr                                 ? "PETSc error during the solve"
          : reason == SNES_CONVERGED_ITERATING ? "time-step error estimate above tolerance"
                                               : std::string("Newton: ") + SNESConvergedReasons[reason];
    cause_ = ierr                                 ? "petsc_error"
             : reason == SNES_CONVERGED_ITERATING ? "rejected_by_term"
                                                  : SNESConvergedReasons[reason];
    for (const auto& term : assembler_.terms()) term->set_time(t_);
  }
  VecDestroy(&x);
  return ok;
}

// The times steps land on: output times, the end and (with land_on_breakpoints) the
// loads' breakpoints, sorted. A breakpoint within kBreakpointMerge * dt_max of the one
// before is not a stop of its own (the end of a switch that takes a fraction of a
// millisecond).
std::vector<double> IncrementalSolver::step_stops() const {
  std::vector<double> stops = opt_.output_times;
  if (opt_.land_on_breakpoints) {
    std::vector<double> breaks = opt_.breakpoints;
    std::sort(breaks.begin(), breaks.end());
    double last = -1e300;
    for (double b : breaks)
      if (b - last > kBreakpointMerge * opt_.dt_max) {
        stops.push_back(b);
        last = b;
      }
  }
  stops.push_back(opt_.t_end);
  std::sort(stops.begin(), stops.end());
  return stops;
}

// The end of the next step of size about dt from t_, landing exactly on the next stop.
double IncrementalSolver::step_end(const std::vector<double>& stops, double dt, double eps) const {
  double next_stop = opt_.t_end;
  for (double s : stops)
    if (s > t_ + eps) {
      next_stop = s;
      break;
    }
  if (opt_.land_on_breakpoints) {
    // n equal steps to the next stop, none longer than dt: no sliver before it.
    const double n = std::max(1.0, std::ceil((next_stop - t_) / dt - 1e-9));
    return n > 1 ? t_ + (next_stop - t_) / n : next_stop;
  }
  const double t_new = std::min(t_ + dt, next_stop);
  // Never leave a sliver before an output time: stretch this step by up to 25 %.
  return next_stop - t_new < 0.25 * dt ? next_stop : t_new;
}

RunStats IncrementalSolver::run(const std::function<void(const StepReport&)>& on_step) {
  auto start = std::chrono::steady_clock::now();
  RunStats stats = counters_;
  stats.completed = false;
  stats.failure.clear();
  for (const auto& term : assembler_.terms()) term->set_time(t_);
  const std::vector<double> stops = step_stops();
  double dt = dt_next_ > 0 ? std::min(dt_next_, opt_.dt_max) : std::min(opt_.dt_initial, opt_.dt_max);
  int cuts = 0;
  const double eps = 1e-12 * std::max(1.0, opt_.t_end);
  while (t_ < opt_.t_end - eps) {
    const double t_new = step_end(stops, dt, eps);
    int its = 0, lits = 0;
    std::string why;
    if (solve_step(t_new, its, lits, why)) {
      ++stats.steps;
      stats.newton_its += its;
      stats.linear_its += lits;
      StepReport report{stats.steps, t_, dt_prev_, its, lits, cuts, assembler_.energy(u_)};
      if (its <= opt_.easy_newton_its && cuts == 0) dt = std::min(dt * opt_.grow, opt_.dt_max);
      dt = std::min(dt, advised_dt_);
      if (step_monitor_)
        PetscPrintf(assembler_.comm(), "  step %d: t = %.6g s, dt = %.4g s, %d Newton its, %d cuts, next dt %.4g s%s\n",
                    stats.steps, t_, dt_prev_, its, cuts, dt, advised_dt_ <= dt ? " (a term's advice)" : "");
      dt_next_ = dt;  // before on_step, which may save a checkpoint
      counters_ = stats;
      cuts = 0;
      if (on_step) on_step(report);
    } else if (why == "time-step error estimate above tolerance" && advised_dt_ < t_new - t_) {
      ++stats.error_rejections;
      dt = advised_dt_;
      if (dt < opt_.dt_min) {
        stats.failure = "step " + std::to_string(stats.steps + 1) + " from t = " + std::to_string(t_) +
                        " s: the time-error estimate asks for a step below dt_min";
        break;
      }
    } else {
      ++stats.step_cuts;
      ++stats.cuts_by_cause[cause_];
      if (step_monitor_)
        PetscPrintf(assembler_.comm(), "  cut: t = %.6g s, dt = %.4g s (%s)\n", t_, t_new - t_, cause_.c_str());
      ++cuts;
      dt = 0.5 * (t_new - t_);
      if (dt < opt_.dt_min) {
        std::ostringstream s;
        s << "step " << stats.steps + 1 << " from t = " << t_ << " s: no convergence with the smallest step dt = " << dt
          << " s after " << cuts << " cuts (" << why << ")";
        stats.failure = s.str();
        break;
      }
    }
  }
  stats.exact_hessian_its = exact_hessian_its_;
  stats.projection_fallbacks = projection_fallbacks_;
  stats.completed = stats.failure.empty();
  stats.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace morphfem
