// Inertia as an incremental potential (implicit time stepping by minimisation).
//
// Every scheme below advances (u, v, a) [m, m/s, m/s^2] from t_n to t_{n+1} =
// t_n + h by minimising, over the displacement u of the new step,
//
//   E(u) = c/2 (u - u_pred)^T M (u - u_pred) + (every other energy term)   [J]
//
// with the mass matrix M [kg] and a scheme-dependent coefficient c [1/s^2] and
// predictor u_pred [m] built from the history in begin_step. Stationarity gives
// M a_{n+1} = f(u_{n+1}) with a_{n+1} = c (u_{n+1} - u_pred): the discrete
// equation of motion, f = -(gradient of the other terms) [N].
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
// Mass matrix per cell, M_ab = int rho N_a N_b dV (times the 3x3 identity):
//   consistent  exact quadrature (degree 2 for P1; degree 6 for P2, exact for
//               straight-sided cells);
//   lumped      HRZ (Hinton-Rock-Zienkiewicz): m_a = M_aa * (rho V / sum_b M_bb),
//               diagonal and positive for P1 and P2; for P1 it equals the
//               row-sum rho V/4. (Plain row sums of P2 are negative at vertices.)
//               Caveat: P2 lumped masses do not match the consistent nodal loads of
//               a uniform body force (int N_a rho g), so a P2 lumped free fall
//               deforms slightly; its centre of mass still falls exactly.
//
// History (u_n, v_n, a_n, u_{n-1}, v_{n-1}) lives in PETSc vectors owned by the
// term. begin_step only reads it (a rejected step calls begin_step again with the
// same u_n); end_step advances it. Dirichlet dofs follow the same formulas (their
// prescribed motion gives their velocity).
#pragma once
#include <petscvec.h>

#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "fem/element.h"
#include "fem/energy.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

enum class TimeScheme { implicit_euler, bdf2, newmark };
// Largest step ratio h_n / h_{n-1} taken with the two-step BDF2 formula.
constexpr double kBdf2MaxStepRatio = 2.0;
// Names in one table: implicit_euler (alias bdf1), bdf2, newmark.
const std::map<std::string, TimeScheme>& time_schemes();

struct InertiaOptions {
  TimeScheme scheme = TimeScheme::newmark;
  bool lumped = false;         // HRZ-lumped (diagonal) instead of consistent mass
  double newmark_beta = 0.25;  // (0, 1/2]
  double newmark_gamma = 0.5;  // [1/2, 1]; > 1/2 adds numerical dissipation
  // a_0 from the forces at t_0 (true) or zero (false). Used by newmark and by the
  // trapezoidal first step of bdf2.
  bool equilibrium_initial_acceleration = true;
  // Local truncation error control (see suggested_dt): the largest nodal error
  // estimate allowed per step [m], and the safety factor and growth bounds.
  double error_tolerance = 1e-4;
  bool adaptive = false;  // let the error estimate reject steps and choose dt (advise_step)
  double error_safety = 0.9, error_min_factor = 0.2, error_max_factor = 2.0;
};

// Element mass matrix (scalar, n x n; times the 3x3 identity per node pair) [kg]:
// consistent M_ab = rho int N_a N_b dV, or HRZ-lumped (diagonal). X: n x 3 [m],
// density [kg/m^3]. `table` must integrate N_a N_b det(J0) (see make_mass_table).
Eigen::MatrixXd element_mass_matrix(const ShapeTable& table, const Eigen::MatrixXd& X, double density, bool lumped);
ShapeTable make_mass_table(int order);

// Kernel: E = c/2 sum_ab M_ab w_a . w_b, w = u - u_pred (n x 3) [m], c [1/s^2];
// g_{3a+i} = c sum_b M_ab w_bi, H = c M (x) I_3.
double inertia_kernel(const Eigen::MatrixXd& mass, double c, const Eigen::MatrixXd& w, Eigen::VectorXd* g,
                      Eigen::MatrixXd* H);

class Assembler;

class InertiaTerm : public EnergyTerm {
 public:
  // density[region id] [kg/m^3] (0 for regions without mass or that are not
  // volumes); pieces: cells of part `rank` with positive density.
  InertiaTerm(const Mesh& mesh, const Partition& partition, int rank, std::vector<double> density,
              InertiaOptions options = {});
  ~InertiaTerm() override;
  InertiaTerm(const InertiaTerm&) = delete;
  InertiaTerm& operator=(const InertiaTerm&) = delete;

  std::string name() const override { return "inertia"; }
  int n_pieces() const override { return static_cast<int>(cells_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  void end_step(Assembler& assembler, Vec u1, double t1) override;
  StepAdvice advise_step(Assembler& assembler, Vec u1, double t0, double t1) override;
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) override;
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) override;

  // Initial velocity v_0(X) [m/s]; set before the first step.
  void set_initial_velocity(std::function<Eigen::Vector3d(const Eigen::Vector3d& X)> v0);
  // Creates the history from the state u0 at time t0 (v_0 from the function above,
  // a_0 per options). Called by the first begin_step if not called before; call it
  // explicitly (after the solver is constructed, which sets up the assembler) to
  // report the initial kinetic energy. Collective.
  void initialize(Assembler& assembler, Vec u0, double t0);
  bool initialized() const { return u_n_ != nullptr; }

  // Kinetic energy 1/2 v_n^T M v_n [J] of the last converged step. Collective.
  double kinetic_energy(Assembler& assembler);
  // Total mass [kg] (collective) and the history vectors (owned by the term).
  double mass(Assembler& assembler) const;
  Vec velocity() const { return v_n_; }
  Vec acceleration() const { return a_n_; }

  // Local truncation error of the last converged step: largest nodal estimate over
  // the free dofs [m], and the next step it suggests [s] so that the estimate meets
  // options.error_tolerance:
  //   newmark:  e = (beta - 1/6) h^2 (a_{n+1} - a_n)       (zero for beta = 1/6)
  //   bdf2:     e = (1 + w)^2 / (6 w (1 + 2w)) h^2 (a_{n+1} - a_n)   (w = 1: 2/9)
  //   implicit_euler: e = h/2 (v_{n+1} - v_n)  (= h^2/2 u'')
  // from u''' ~ (a_{n+1} - a_n)/h; dt_next = h * clamp(safety (tol/e)^(1/(p+1)),
  // min_factor, max_factor) with order p (1 or 2). Computed in end_step;
  // suggested_dt() is +infinity before the first step.
  double last_error() const { return last_error_; }
  double suggested_dt() const { return suggested_dt_; }
  // The same estimate for a converged candidate u1 of the current step (begin_step
  // has been called), without advancing the history: for a solver that rejects
  // steps whose error exceeds the tolerance. Returns the error [m]; dt_next [s].
  double estimate_error(Assembler& assembler, Vec u1, double& dt_next);

 private:
  enum class StepKind { implicit_euler, bdf2, newmark };
  void step_accelerations(Vec u1, Vec v1, Vec a1);  // v_{n+1}, a_{n+1} of the current step
  double error_of(Assembler& assembler, Vec v1, Vec a1, double& dt_next);
  void equilibrium_acceleration(Assembler& assembler, Vec u0, double t0);
  void allocate(Assembler& assembler);

  const Mesh& mesh_;
  std::vector<int> cells_;
  std::vector<Eigen::MatrixXd> mass_;  // per piece, n x n [kg]
  InertiaOptions opt_;
  std::function<Eigen::Vector3d(const Eigen::Vector3d&)> v0_;

  // History and work vectors (global layout of the assembler).
  Vec u_n_ = nullptr, v_n_ = nullptr, a_n_ = nullptr, u_nm1_ = nullptr, v_nm1_ = nullptr;
  Vec pred_ = nullptr, v_new_ = nullptr, a_new_ = nullptr, err_ = nullptr;
  int steps_done_ = 0;
  double h_prev_ = 0.0;
  bool have_a0_ = false;  // a_n holds a consistent acceleration

  // The current step (set by begin_step).
  StepKind kind_ = StepKind::newmark;
  double h_ = 0.0, c_ = 0.0, w_ = 1.0;
  double beta_ = 0.25, gamma_ = 0.5;         // of the current step if kind_ == newmark
  std::vector<Eigen::MatrixXd> pred_piece_;  // per piece, n x 3 [m]
  bool suppressed_ = false;                  // piece() returns 0 (forces for a_0)

  double last_error_ = 0.0, suggested_dt_ = std::numeric_limits<double>::infinity();
};

}  // namespace morphfem
