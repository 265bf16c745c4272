// The time integrator: implicit time stepping by minimisation.
//
// Every scheme below advances (u, v, a) [m, m/s, m/s^2] from t_n to t_{n+1} =
// t_n + h by minimising, over the displacement u of the new step,
//
//   E(u) = c/2 (u - u_pred)^T M (u - u_pred) + (every other energy term)   [J]
//
// with the mass matrix M [kg] (the inertia term, fem/inertia.h) and a
// scheme-dependent coefficient c [1/s^2] and predictor u_pred [m] built from the
// history in begin_step. Stationarity gives M a_{n+1} = f(u_{n+1}) with
// a_{n+1} = c (u_{n+1} - u_pred): the discrete equation of motion,
// f = -(gradient of the other terms) [N].
//
//   implicit_euler (BDF1, first order, dissipative):
//     c = 1/h^2,  u_pred = u_n + h v_n
//     v_{n+1} = (u_{n+1} - u_n)/h,  a_{n+1} = (v_{n+1} - v_n)/h
//
//   bdf2 (second order, weakly dissipative; variable step, w = h/h_{n-1}):
//     alpha0 = (1 + 2w)/(1 + w), alpha1 = -(1 + w), alpha2 = w^2/(1 + w)
//     v_{n+1} = (alpha0 u_{n+1} + alpha1 u_n + alpha2 u_{n-1})/h
//     a_{n+1} = (alpha0 v_{n+1} + alpha1 v_n + alpha2 v_{n-1})/h
//     c = alpha0^2/h^2,
//     u_pred = -(alpha1 u_n + alpha2 u_{n-1})/alpha0 - h (alpha1 v_n + alpha2 v_{n-1})/alpha0^2
//     (w = 1: c = 9/(4h^2), u_pred = 4/3 u_n - 1/3 u_{n-1} + 8/9 h v_n - 2/9 h v_{n-1}).
//     Its first step has no u_{n-1}: it is one trapezoidal (Newmark 1/4, 1/2) step,
//     second order like the rest, so quadratic motions are integrated exactly; with
//     initial_acceleration = zero it is one implicit-Euler step instead. Variable-step
//     BDF2 is zero-stable only for w < 1 + sqrt(2): a step that grows by more than
//     kBdf2MaxStepRatio (e.g. right after a short step that lands on an output time)
//     is taken as one trapezoidal step instead (one-step, second order).
//
//   newmark (beta, gamma; default 1/4, 1/2 = trapezoidal / average acceleration,
//   second order, no numerical dissipation: conserves the energy of a linear
//   system exactly, of a nonlinear one to O(h^2)):
//     c = 1/(beta h^2),  u_pred = u_n + h v_n + h^2 (1/2 - beta) a_n
//     a_{n+1} = c (u_{n+1} - u_pred),  v_{n+1} = v_n + h ((1 - gamma) a_n + gamma a_{n+1})
//     Needs a_0: by default from M a_0 = f(u_0, t_0) (one CG solve with the mass
//     matrix at the first step), else a_0 = 0.
//
// The rate of another quantity q that a term tracks itself (the damping's strain,
// fem/damping.h) at the end of the step, from q's own history (q_n, q_{n-1} and
// qdot_n, which it has from its second step on):
//   qdot_{n+1} = kappa/h (q_{n+1} - q*)                                 (RateRule)
//   backward     (implicit_euler, and every scheme's first step): kappa = 1, q* = q_n
//   trapezoidal  (newmark, whatever beta and gamma, and a bdf2 step that grows by more
//                than kBdf2MaxStepRatio): kappa = 2, q* = q_n + h/2 qdot_n
//   bdf2:        kappa = alpha0, q* = -(alpha1 q_n + alpha2 q_{n-1})/alpha0
// For q = u these are the velocities above (trapezoidal: newmark 1/4, 1/2).
//
// Local truncation error of a converged step, largest nodal estimate over the free
// dofs [m], and the next step it suggests [s] so that the estimate meets
// options.error_tolerance:
//   newmark:  e = (beta - 1/6) h^2 (a_{n+1} - a_n)       (zero for beta = 1/6)
//   bdf2:     e = (1 + w)^2 / (6 w (1 + 2w)) h^2 (a_{n+1} - a_n)   (w = 1: 2/9)
//   implicit_euler: e = h/2 (v_{n+1} - v_n)  (= h^2/2 u'')
// from u''' ~ (a_{n+1} - a_n)/h; dt_next = h * clamp(safety (tol/e)^(1/(p+1)),
// min_factor, max_factor) with order p (1 or 2).
//
// History (u_n, v_n, a_n, u_{n-1}, v_{n-1}) lives in PETSc vectors owned by the
// integrator. begin_step only reads it (a rejected step calls begin_step again with
// the same u_n); end_step advances it. Dirichlet dofs follow the same formulas (their
// prescribed motion gives their velocity). The integrator is not an energy term: the
// inertia term runs its step life cycle (begin_step, advise_step, end_step,
// checkpoints) from its own, and weights its mass matrix with c and u_pred.
#pragma once
#include <petscvec.h>

#include <Eigen/Dense>
#include <functional>
#include <limits>
#include <map>
#include <string>

#include "core/state_file.h"
#include "fem/energy.h"

namespace morphfem {

enum class TimeScheme { implicit_euler, bdf2, newmark };
// Largest step ratio h_n / h_{n-1} taken with the two-step BDF2 formula.
constexpr double kBdf2MaxStepRatio = 2.0;
// Names in one table: implicit_euler (alias bdf1), bdf2, newmark.
const std::map<std::string, TimeScheme>& time_schemes();

struct TimeIntegratorOptions {
  TimeScheme scheme = TimeScheme::newmark;
  double newmark_beta = 0.25;  // (0, 1/2]
  double newmark_gamma = 0.5;  // [1/2, 1]; > 1/2 adds numerical dissipation
  // a_0 from the forces at t_0 (true) or zero (false). Used by newmark and by the
  // trapezoidal first step of bdf2.
  bool equilibrium_initial_acceleration = true;
  // Local truncation error control (see above): the largest nodal error estimate
  // allowed per step [m], and the safety factor and growth bounds.
  double error_tolerance = 1e-4;
  bool adaptive = false;  // let the error estimate reject steps and choose dt (advise_step)
  double error_safety = 0.9, error_min_factor = 0.2, error_max_factor = 2.0;
};

// BDF2's coefficients for the step ratio w = h/h_{n-1} [-] (formulas above).
struct Bdf2Coefficients {
  double alpha0 = 1.0, alpha1 = -1.0, alpha2 = 0.0;
};
Bdf2Coefficients bdf2_coefficients(double w);

// The rate of a quantity q at the end of a step of length h: qdot_{n+1} = kappa/h
// (q_{n+1} - q*), q* from q's history (the rule above). T: any type with + and
// scalar * (a 3x3 tensor, a vector of values).
struct RateRule {
  enum class Kind { backward, trapezoidal, bdf2 };
  Kind kind = Kind::backward;
  double h = 0.0;      // the step [s]
  double kappa = 1.0;  // [-]
  Bdf2Coefficients bdf2;

  // q* from q_n and, if the rule uses them, q_{n-1} (bdf2) and qdot_n (trapezoidal).
  template <class T>
  T anchor(const T& q_n, const T& q_nm1, const T& qdot_n) const {
    switch (kind) {
      case Kind::trapezoidal:
        return T(q_n + 0.5 * h * qdot_n);
      case Kind::bdf2:
        return T(-(bdf2.alpha1 * q_n + bdf2.alpha2 * q_nm1) / bdf2.alpha0);
      case Kind::backward:
        break;
    }
    return q_n;
  }
  bool uses_history() const { return kind != Kind::backward; }
  template <class T>
  T rate(const T& q1, const T& q_star) const {
    return T(kappa / h * (q1 - q_star));
  }
  // The rate whose conjugate force does the step's work: the mean of the step's two
  // ends for the trapezoidal rule, the end rate otherwise.
  template <class T>
  T work_rate(const T& qdot_n, const T& qdot1) const {
    return kind == Kind::trapezoidal ? T(0.5 * (qdot_n + qdot1)) : qdot1;
  }
};

class Assembler;

class TimeIntegrator {
 public:
  explicit TimeIntegrator(TimeIntegratorOptions options = {});
  ~TimeIntegrator();
  TimeIntegrator(const TimeIntegrator&) = delete;
  TimeIntegrator& operator=(const TimeIntegrator&) = delete;

  const TimeIntegratorOptions& options() const { return opt_; }

  // Initial velocity v_0(X) [m/s]; set before the first step.
  void set_initial_velocity(std::function<Eigen::Vector3d(const Eigen::Vector3d& X)> v0);
  // Solves M a_0 = f(u_0, t_0) into its argument (the inertia term owns M).
  using InitialAcceleration = std::function<void(Vec a0)>;
  // Creates the history from the state u0 (v_0 from the function above on the free
  // dofs, constrained ones at rest; a_0 from `initial_acceleration` if the scheme uses
  // it and options.equilibrium_initial_acceleration, else zero). Collective.
  void initialize(Assembler& assembler, Vec u0, const InitialAcceleration& initial_acceleration);
  bool initialized() const { return u_n_ != nullptr; }

  // The step t0 -> t1 [s]: its formula, c and u_pred from the history (read only).
  void begin_step(double t0, double t1);
  double c() const { return c_; }          // of the current step [1/s^2]
  Vec predictor() const { return pred_; }  // u_pred of the current step [m]
  // The history advanced by the converged step u1 (and its error estimate). Collective.
  void end_step(Assembler& assembler, Vec u1);
  // With options.adaptive: accepts the converged candidate u1 if its error estimate
  // is within twice the tolerance (the next step aims at the tolerance itself), and
  // bounds the next step. Collective.
  EnergyTerm::StepAdvice advise_step(Assembler& assembler, Vec u1);

  // Error estimate of the last converged step [m] and the next step it suggests [s]
  // (+infinity before the first step), computed in end_step.
  double last_error() const { return last_error_; }
  double suggested_dt() const { return suggested_dt_; }
  // The same estimate for a converged candidate u1 of the current step, without
  // advancing the history. Returns the error [m]; dt_next [s].
  double estimate_error(Assembler& assembler, Vec u1, double& dt_next);

  // The history vectors of the last converged step (owned by the integrator).
  Vec velocity() const { return v_n_; }
  Vec acceleration() const { return a_n_; }

  // The rule for the rate of a quantity with its own history over a step of length
  // h [s] after one of h_prev [s]; has_rate: the quantity's rate at the step's start
  // is known (not its first step).
  RateRule rate_rule(double h, double h_prev, bool has_rate) const;

  // The history and the step bookkeeping under `prefix` (fem/term_state.h). Collective.
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state);
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state);

 private:
  enum class StepKind { implicit_euler, bdf2, newmark };
  bool takes_bdf2(double h, double h_prev) const;  // the two-step formula for this step
  void step_rates(Vec u1, Vec v1, Vec a1);         // v_{n+1}, a_{n+1} of the current step
  double error_of(Assembler& assembler, Vec v1, Vec a1, double& dt_next);
  void allocate(Assembler& assembler);

  TimeIntegratorOptions opt_;
  std::function<Eigen::Vector3d(const Eigen::Vector3d&)> v0_;

  // History and work vectors (global layout of the assembler).
  Vec u_n_ = nullptr, v_n_ = nullptr, a_n_ = nullptr, u_nm1_ = nullptr, v_nm1_ = nullptr;
  Vec pred_ = nullptr, v_new_ = nullptr, a_new_ = nullptr, err_ = nullptr;
  int steps_done_ = 0;
  double h_prev_ = 0.0;
  bool have_a0_ = false;  // a_n holds a consistent acceleration

  // The current step (set by begin_step).
  bool begun_ = false;
  StepKind kind_ = StepKind::newmark;
  double h_ = 0.0, c_ = 0.0, w_ = 1.0;
  double beta_ = 0.25, gamma_ = 0.5;  // of the current step if kind_ == newmark

  double last_error_ = 0.0, suggested_dt_ = std::numeric_limits<double>::infinity();
};

}  // namespace morphfem
