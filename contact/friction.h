// Smoothed Coulomb friction against a ground plane, IPC-style lagged ("lazy"):
// the normal force lambda_a [N] of every contact node is taken from the
// GroundContactTerm at the start of the step (begin_step), the plane's tangent
// projector P = I - n n^T is constant, and the dissipative potential of a step
// t0 -> t1 (h = t1 - t0) is
//
//   D = sum_a lambda_a F_a(|r_a|),   r_a = P (u_a - u0_a)  (tangential slip over the step) [m]
//
// with F(y) = int_0^y phi(z) dz and the friction force per unit normal force
//
//   phi(y) = mu_s f1(y)                                       y <= eps
//          = mu_s + (mu_k - mu_s)(3 z^2 - 2 z^3), z = y/eps - 1   eps < y <= 2 eps
//          = mu_k                                             y > 2 eps
//   f1(y)  = 2 y/eps - y^2/eps^2   (C1 mollifier: f1(0) = 0, f1(eps) = 1, f1'(eps) = 0)
//
// where eps = eps_v h [m] and eps_v [m/s] is the smoothing velocity. The force on
// node a is -lambda_a phi(y) r_a / y: up to slip velocity eps_v friction grows
// from 0 to the static limit mu_s lambda ("stick" is a creep below eps_v: a node
// loaded at a fraction q < 1 of mu_s lambda creeps at y/h = eps_v (1 - sqrt(1 - q))),
// then drops smoothly (C1) to the kinetic value mu_k lambda between eps_v and
// 2 eps_v. So tangential loads below mu_s lambda stick, loads above slide against
// mu_k lambda. With mu_s = mu_k this is IPC's mollified Coulomb friction.
//
// Derivatives (y = |r|, rhat = r/y):
//   grad_a D = lambda phi(y)/y r
//   Hess_a D = lambda [ phi(y)/y P + (phi'(y) - phi(y)/y) rhat rhat^T ]
// phi(y)/y >= 0 and phi' >= 0 for y <= eps, so the Hessian is PSD except in the
// static-to-kinetic drop (eps, 2 eps) where phi' < 0 (mu_k < mu_s); there, with
// project_hessian (default), phi' is clamped to 0 (the PSD projection), as IPC
// projects its friction Hessians. At y = 0: Hess = lambda (2 mu_s/eps) P.
//
// Coefficients per surface region and over time: each region has TimeFunctions
// mu_s(t), mu_k(t); a node's coefficients are the area-weighted means over the
// friction regions its faces belong to (weights as the contact term's nodal
// areas), evaluated at the end of the step (set_time(t1): implicit in time).
// Pseudo-time (quasi-static) runs use h in pseudo-seconds: eps_v is then a slip
// per unit pseudo-time [m/s_pseudo].
//
// Lagging: lambda is evaluated at the step's start state; with lag_updates > 0
// the converged step is re-solved (update_after_solve) with lambda from the
// converged state until it changes by less than lag_tolerance relative to the
// largest lambda, at most lag_updates times (the slip is still measured from u0).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "contact/ground.h"
#include "fem/time_function.h"

namespace morphfem {

struct FrictionRegion {
  std::string surface;      // surface region (its nodes must be contact nodes of the ground)
  TimeFunction mu_static;   // mu_s(t) [-]
  TimeFunction mu_kinetic;  // mu_k(t) [-]
};

struct FrictionSpec {
  std::vector<FrictionRegion> regions;
  double eps_v = 1e-4;          // smoothing (creep) velocity [m/s]
  int lag_updates = 0;          // re-solves per step with lambda from the converged state
  double lag_tolerance = 1e-3;  // relative change of lambda that asks for another re-solve
  bool project_hessian = true;  // clamp the negative curvature of the static->kinetic drop
};

// Friction force per unit normal force phi(y) [-] and its derivative phi'(y)
// [1/m] and the integral F(y) = int_0^y phi [m], for slip y >= 0 [m] over a step,
// smoothing width eps [m] (see the header comment). Exposed for tests.
struct FrictionLaw {
  double mu_s = 0.0, mu_k = 0.0, eps = 1.0;
  double potential(double y) const;     // F(y)
  double force(double y) const;         // phi(y)
  double force_over_y(double y) const;  // phi(y)/y, finite at y = 0
  double dforce(double y) const;        // phi'(y)
};

// The lagged friction potential of one contact point, the kernel every friction
// term calls: with normal force lambda [N] and tangential slip r = P dx over the
// step (P = I - n n^T, dx the point's motion since the step's start [m]),
//   D = lambda F(|r|) [J],  dD/dx = lambda phi(y)/y r [N],
//   d2D/dx2 = lambda [ phi(y)/y P + (phi'(y) - phi(y)/y) rhat rhat^T ] [N/m],
// phi' clamped to >= 0 when clamp_drop (the PSD projection of the static->kinetic
// drop). Returns D; grad and hess (may be null) are overwritten.
double lagged_friction(const FrictionLaw& law, double lambda, const Eigen::Matrix3d& tangent_projector,
                       const Eigen::Vector3d& dx, bool clamp_drop, Eigen::Vector3d* grad, Eigen::Matrix3d* hess);

class FrictionTerm : public EnergyTerm {
 public:
  // Pieces: the owned contact nodes of `ground` that lie on a friction region.
  // Throws InputError for an unknown region or a friction region with nodes that
  // are not contact nodes of `ground`.
  FrictionTerm(const Mesh& mesh, const Partition& partition, int rank, std::shared_ptr<const GroundContactTerm> ground,
               FrictionSpec spec);

  std::string name() const override { return "friction:" + ground_->spec().name; }
  int n_pieces() const override { return static_cast<int>(nodes_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override { nodes.assign(1, nodes_[k]); }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override;
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  bool update_after_solve(Assembler& assembler, Vec u1) override;
  // With project_hessian, the exact (unclamped) Hessian while set (adaptive projection).
  void set_exact_hessian(bool exact) override { exact_hessian_ = exact; }

  const FrictionSpec& spec() const { return spec_; }
  // For tests: sets the lagged state of piece k directly (normal force [N], start
  // displacement [m]) and the step length h [s].
  void set_lagged(int k, double lambda, const Eigen::Vector3d& u0) {
    lambda_[k] = lambda;
    u0_[k] = u0;
  }
  void set_step_length(double h) { h_ = h; }

  // Per mesh node, identical on every rank (collective): friction force on the
  // node [N], status (0: no normal force, 1: stick = slip velocity below eps_v,
  // 2: slip) and the slip over the current step [m].
  struct NodalFriction {
    RowMatrixXd force;
    std::vector<int> status;
    std::vector<double> slip;
  };
  NodalFriction nodal_friction(Assembler& assembler, Vec u) const;
  // Work of the friction forces over the current step, sum lambda phi(y) y [J]
  // (the energy dissipated by friction from the step's start to u; collective).
  double dissipated(Assembler& assembler, Vec u) const;

 private:
  FrictionLaw law(int k) const;
  void compute_normal_forces(Assembler& assembler, Vec u, std::vector<double>& lambda) const;

  const Mesh& mesh_;
  std::shared_ptr<const GroundContactTerm> ground_;
  FrictionSpec spec_;
  bool exact_hessian_ = false;
  Eigen::Matrix3d tangent_projector_;
  std::vector<int> nodes_;                          // pieces: owned friction nodes
  std::vector<std::vector<double>> region_weight_;  // per piece, per region: area [m^2]
  std::vector<double> mu_s_, mu_k_;                 // per piece at the current time
  std::vector<double> lambda_;                      // per piece, lagged normal force [N]
  std::vector<Eigen::Vector3d> u0_;                 // per piece, displacement at the step start [m]
  double h_ = 1.0;                                  // step length [s]
  int lag_count_ = 0;
};

}  // namespace morphfem
