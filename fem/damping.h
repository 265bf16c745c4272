// Viscous (Kelvin-Voigt) damping as a dissipation potential.
//
// Physical meaning: the silicone is a hyperelastic spring (ElasticTerm) in
// parallel with an isotropic dashpot. The dashpot's viscous second
// Piola-Kirchhoff stress is
//   S_v = 2 eta dev(Edot) + zeta tr(Edot) I        [Pa]
// with the Green-Lagrange strain rate Edot, the shear viscosity eta [Pa s] and
// the bulk viscosity zeta [Pa s] (default 0). At small strain this is the
// textbook Kelvin-Voigt solid sigma_v = 2 eta dev(epsdot) + zeta tr(epsdot) I.
// Because E = 1/2 (F^T F - I) is blind to rotations, rigid motions (a rolling
// robot) are not damped; only straining is.
//
// For silicone: a Kelvin-Voigt solid has loss tangent tan(delta) = omega eta / G
// at angular frequency omega (G: shear modulus), and a shear-dominated vibration
// mode a damping ratio xi = omega eta / (2 G). Real silicones have a nearly flat
// tan(delta) (about 0.05-0.3 for Ecoflex/Dragon Skin at 1-10 Hz), so eta is
// fitted at the frequency that matters (gait or ringing frequency):
// eta = G tan(delta) / omega, e.g. G = 0.1 MPa, tan(delta) = 0.1 at 5 Hz gives
// eta ~ 300 Pa s.
//
// Time discretisation. The strain rate at the end of the step t_n -> t_n + h is
// the time integrator's rate of E (RateRule, fem/time_integrator.h), so that the
// viscous force enters the same end-of-step equilibrium as M a_{n+1}:
//   Edot(u) = kappa/h (E(u) - E*),  E* from E_n, E_{n-1} and Edot_n:
// backward (kappa = 1, E* = E_n) at the first step, which has no Edot_n yet, and with
// implicit_euler; trapezoidal with newmark; bdf2 with bdf2.
// Incremental potential (dE = E(u) - E*, reference volume):
//   D(u) = h/kappa int R(Edot) dV = kappa/h int [ eta |dev dE|^2 + zeta/2 (tr dE)^2 ] dV   [J]
// with R = eta |dev Edot|^2 + zeta/2 (tr Edot)^2, so dD/dE = S_v(Edot) and dD/dF = F S_v
// (first Piola-Kirchhoff viscous stress): the gradient is the viscous nodal force.
// Energy dissipated by the step (>= 0), accumulated in end_step:
//   backward, bdf2:  W = int S_v(Edot_{n+1}) : (E_{n+1} - E_n) dV
//   trapezoidal:     W = int S_v((Edot_n + Edot_{n+1})/2) : (E_{n+1} - E_n) dV
// (for a linear system the trapezoidal W is exactly the energy the scheme removes).
// D is not convex in u for large dE; its Hessian is exact.
#pragma once
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "fem/element.h"
#include "fem/energy.h"
#include "fem/material.h"
#include "fem/time_integrator.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

// Green-Lagrange strain E = 1/2 (F^T F - I) at every point of `table`,
// F = I + u^T dN/dX (X, u: n x 3 [m]).
std::vector<Mat3> green_lagrange_at_points(const ShapeTable& table, const Eigen::MatrixXd& X, const Eigen::MatrixXd& u);

// Kernel: D = 1/h_eff int [ eta |dev dE|^2 + zeta/2 (tr dE)^2 ] dV of one cell,
// dE = E(u) - E_star at every point, eta, zeta [Pa s], h_eff = h/kappa [s];
// g (3n) and H (3n x 3n) w.r.t. u if given.
double viscous_damping_kernel(const ShapeTable& table, const Eigen::MatrixXd& X, const Eigen::MatrixXd& u,
                              const std::vector<Mat3>& E_star, double eta, double zeta, double h_eff,
                              Eigen::VectorXd* g, Eigen::MatrixXd* H);

class Assembler;

class DampingTerm : public EnergyTerm {
 public:
  // shear_viscosity[region id], bulk_viscosity[region id] [Pa s] (empty bulk:
  // zero everywhere); pieces: cells of part `rank` with a positive viscosity.
  // integrator: the inertia's, whose rate rule discretises the strain rate (above).
  // quadrature_degree 0: 1 for P1 (E constant), 2 for P2.
  DampingTerm(const Mesh& mesh, const Partition& partition, int rank, std::vector<double> shear_viscosity,
              std::vector<double> bulk_viscosity, std::shared_ptr<const TimeIntegrator> integrator,
              int quadrature_degree = 0);

  std::string name() const override { return "damping"; }
  int n_pieces() const override { return static_cast<int>(cells_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  // E(u_n) from u0, kappa and E* of the step (reads the history only).
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  // Advances Edot_n, E_{n-1}; adds the step's dissipated energy W. Collective.
  void end_step(Assembler& assembler, Vec u1, double t1) override;
  // Edot_n, E_{n-1} per point (this rank's pieces), the last step length, the dissipation.
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) override;
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) override;

  double last_dissipated() const { return last_dissipated_; }    // of the last step [J]
  double total_dissipated() const { return total_dissipated_; }  // since the start [J]

 private:
  const Mesh& mesh_;
  std::vector<int> cells_;
  std::vector<double> eta_, zeta_;  // per piece [Pa s]
  ShapeTable table_;
  std::shared_ptr<const TimeIntegrator> integrator_;
  RateRule rule_;  // of the current step
  double h_prev_ = 0.0;
  int steps_done_ = 0;
  // Per piece, per point: E_n, E*, and the history Edot_n [1/s], E_{n-1}.
  std::vector<std::vector<Mat3>> E_n_, E_star_, Edot_n_, E_nm1_;
  double last_dissipated_ = 0.0, total_dissipated_ = 0.0;
};

}  // namespace morphfem
