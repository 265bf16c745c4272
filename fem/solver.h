// Incremental solver: time t in [0, t_end] (pseudo-time for a quasi-static scene)
// drives every time-dependent load and prescribed displacement; each step minimises
// the step's incremental potential (the total energy, plus inertia's and damping's
// terms in a dynamic scene, fem/inertia.h) with
// Newton (PETSc SNES) and an energy-based backtracking line search that never
// accepts a state outside the energy's domain (an inverted element) and always
// decreases the energy. Steps adapt: a failed solve is cut and retried from the
// last converged state, easy solves grow the step.
//
// Linear solver: MUMPS LDL^T by default (the Hessian is symmetric, possibly
// indefinite); "mumps_lu" selects MUMPS LU, "gamg" CG + GAMG with the rigid-body
// near-nullspace. Any PETSc option (-snes_*, -ksp_*, -pc_*) on the command line
// overrides these defaults.
//
// Diagnostics: -morphfem_step_monitor prints a line per step (t, dt, Newton
// iterations, the next dt) and per cut (its cause); -morphfem_linesearch_monitor
// one per line search. Where the time goes: -log_view (events in fem/profile.h).
#pragma once
#include <petscsnes.h>

#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/state_file.h"
#include "fem/assembly.h"

namespace morphfem {

// Prescribed displacement u_i = value(X, t)_i on the given components of `nodes`.
struct DirichletCondition {
  std::string name;
  std::vector<int> nodes;
  std::array<bool, 3> components{true, true, true};
  std::function<Eigen::Vector3d(const Eigen::Vector3d& X, double t)> value;
};

// How the Newton Hessian treats energy terms that can project theirs to PSD (below).
enum class HessianProjection { adaptive, always };

struct SolverOptions {
  double t_end = 1.0;       // end of the pseudo-time [s]
  double dt_initial = 0.1;  // first step [s]
  double dt_min = 1e-6;     // smallest step before giving up [s]
  double dt_max = 1.0;      // largest step [s]
  double grow = 1.5;        // step growth after an easy solve
  int easy_newton_its = 6;  // "easy": converged in at most this many iterations
  int max_newton_its = 30;
  int max_outer_updates = 20;  // re-solves a step while a term's update_after_solve asks
  double rtol = 1e-9;          // ||r|| <= rtol ||r_0|| ...
  double atol_factor = 1e-11;  // ... or ||r|| <= atol_factor * (largest ||r_0|| seen)
  // ... or, if > 0, when the last Newton direction du (before the line search) moves
  // no node by more than newton_velocity_tol * dt: max_a |du_a| / dt <= tol [m/s], a
  // test in the units of the motion (IPC's). Off (0) by default; PETSc option
  // -morphfem_newton_velocity_tol overrides it.
  double newton_velocity_tol = 0.0;
  // Newton's start: u_n + dt (u_n - u_{n-1}) / dt_{n-1} (the last step's velocity,
  // which is implicit Euler's u_n + dt v_n) if true, else u_n. PETSc option
  // -morphfem_extrapolate <bool> overrides it.
  bool extrapolate = true;
  std::string linear_solver = "mumps";  // "mumps" (LDL^T) | "mumps_lu" | "gamg"
  // always: terms that project their Hessian to PSD (EnergyTerm::set_exact_hessian)
  // always do. adaptive: the first iteration of a solve and every one after a
  // damped (backtracked or CCD-bounded) step are projected; after a full Newton step
  // the next is exact, and if its direction does not descend, or the line search
  // finds no decrease along it, the line search re-solves with the projected
  // Hessian. Projection makes the Newton tail linear (the residual halving per
  // iteration on the rolling sleeve with self-contact); the exact Hessian restores
  // quadratic convergence where it is positive definite.
  HessianProjection hessian_projection = HessianProjection::adaptive;  // README, "stalled on the Hessian's projection"
  std::vector<double> output_times;                                    // steps land exactly on these times
  // Breakpoints of the loads [s] (a schedule's column boundaries and ramp ends, its foot
  // switches): with land_on_breakpoints, steps land exactly on them too, and the steps
  // up to each stop (breakpoint or output time) are equal and no longer than the current
  // step, so a load switches at its own time whatever the step sequence. Without it,
  // only output times are stops, and a step stretches by up to 25 % to reach one. Off by
  // default: the gaits' reference speeds were measured without it (docs/solver-notes.md).
  std::vector<double> breakpoints;
  bool land_on_breakpoints = false;
};
// Breakpoints closer than this fraction of dt_max to the one before share its stop.
constexpr double kBreakpointMerge = 0.02;

struct StepReport {
  int step = 0;  // 1-based converged step count
  double t = 0, dt = 0;
  int newton_its = 0;  // Newton iterations of this step
  int linear_its = 0;
  int cuts = 0;       // failed attempts before this step converged
  double energy = 0;  // total energy [J]
};

struct RunStats {
  int steps = 0, newton_its = 0, linear_its = 0, step_cuts = 0;
  int error_rejections = 0;  // steps retried because a time-error estimate was too large
  // Step cuts by cause: a SNES reason (DIVERGED_MAX_IT, DIVERGED_LINE_SEARCH, ...),
  // rejected_by_term (a term's advise_step refused a converged step), petsc_error or
  // dirichlet_inverts (the prescribed increment alone inverts an element).
  std::map<std::string, int> cuts_by_cause;
  // Adaptive Hessian projection (SolverOptions::hessian_projection): Newton iterations
  // with the exact Hessian, and exact directions that did not descend and were
  // re-solved with the projected one. Failed attempts count too.
  int exact_hessian_its = 0, projection_fallbacks = 0;
  double wall_s = 0;
  bool completed = false;
  std::string failure;  // diagnostic if !completed
};

class IncrementalSolver {
 public:
  IncrementalSolver(Assembler& assembler, std::vector<DirichletCondition> bcs, SolverOptions options);
  ~IncrementalSolver();
  IncrementalSolver(const IncrementalSolver&) = delete;
  IncrementalSolver& operator=(const IncrementalSolver&) = delete;

  // Runs from the current state and time to t_end, calling on_step after each
  // converged step. On failure (no convergence at dt_min) the solution keeps the
  // last converged state and stats.failure says which step, time and why.
  RunStats run(const std::function<void(const StepReport&)>& on_step = {});

  // Checkpoints (between runs or from an on_step callback): the state, the time,
  // the step the next attempt takes, the counters and every term's history
  // (EnergyTerm::save_state) under "solver.*" and "term<k>.*". load_state restores
  // them exactly (collective; `state` on every rank), so run() continues the same
  // sequence of steps; the counters (steps, Newton iterations, cuts; not wall_s) of
  // the next run() continue from the saved ones.
  void save_state(StateRecord& state);
  RunStats load_state(const StateRecord& state, const std::string& where);

  Vec solution() const { return u_; }
  double time() const { return t_; }
  Assembler& assembler() { return assembler_; }
  // How often a term's refresh_pieces asked for a new assembly pattern.
  int pattern_rebuilds() const { return pattern_rebuilds_; }

  // PETSc callbacks (public for the C trampolines).
  PetscErrorCode line_search(SNESLineSearch ls);
  PetscErrorCode convergence(SNES snes, PetscInt it, PetscReal snorm, PetscReal fnorm, SNESConvergedReason* reason);
  PetscErrorCode jacobian(Vec u, Mat J, Mat P);
  PetscErrorCode operator_mult(Vec x, Vec y);  // (H + sum c v v^T) x

 private:
  std::vector<double> step_stops() const;
  double step_end(const std::vector<double>& stops, double dt, double eps) const;
  void apply_dirichlet(Vec u, double t) const;
  void set_jacobian();    // (re)attach the Hessian (and shell operator) to SNES
  void refresh_pieces();  // lets terms rebuild state-dependent pieces (then a new pattern)
  void rebuild_pattern();
  void attach_near_nullspace();
  bool predict(double t_new, std::string& why);
  bool solve_step(double t_new, int& newton_its, int& linear_its, std::string& why);
  // Largest alpha in [0, 1] with u + alpha du admissible for every term
  // (EnergyTerm::max_step); `limiter` (optional) names the term that bounds it.
  double admissible_step(Vec u, Vec du, std::string* limiter);
  double largest_nodal_norm(Vec v) const;
  PetscErrorCode print_line_search(Vec X, Vec Y, Vec W, double lambda_max, const std::string& limiter, double lambda,
                                   bool accepted, double slope);
  std::vector<PetscLogEvent> max_step_events_;  // "MaxStep:NAME" per term

  Assembler& assembler_;
  std::vector<DirichletCondition> bcs_;
  SolverOptions opt_;
  Vec u_ = nullptr, u_prev_ = nullptr, work_ = nullptr;
  Mat H_ = nullptr;
  Mat J_ = nullptr;  // shell operator H + low-rank parts (only if a term has them)
  std::vector<EnergyTerm::LowRank> low_rank_;
  void clear_low_rank();
  SNES snes_ = nullptr;
  double t_ = 0.0, dt_prev_ = 0.0;
  double dt_next_ = 0.0;  // the next step run() tries (0: dt_initial)
  RunStats counters_;     // where run()'s counters start (load_state)
  int pattern_rebuilds_ = 0;
  bool exact_hessian_ = false;  // the next Jacobian is exact (adaptive projection)
  int exact_hessian_its_ = 0, projection_fallbacks_ = 0;
  double fnorm0_ = 0.0, fnorm_scale_ = 0.0;
  double fnorm_prev_ = 0.0;                     // residual of the previous iteration [N]
  double dt_step_ = 0.0;                        // the step being solved [s]
  double direction_max_ = 0.0;                  // largest nodal |du| of the last Newton direction [m]
  int stalled_its_ = 0;                         // consecutive iterations without a 10 % residual decrease
  PetscBool linesearch_monitor_ = PETSC_FALSE;  // -morphfem_linesearch_monitor (read once)
  PetscBool step_monitor_ = PETSC_FALSE;        // -morphfem_step_monitor: a line per step and per cut
  double length_scale_ = 1.0;                   // diagonal of the mesh's bounding box [m]
  std::string cause_;                           // short cause of the last failed attempt (RunStats::cuts_by_cause key)
  double advised_dt_ = 1e300;                   // smallest dt_next advised by the terms for the last attempt
};

}  // namespace morphfem
