// Inertia: the mass-matrix term of the incremental potential of a dynamic step,
//
//   E_inertia(u) = c/2 (u - u_pred)^T M (u - u_pred)   [J]
//
// with c [1/s^2] and u_pred [m] from the time integrator (fem/time_integrator.h: the
// schemes, their history and error estimate) and the mass matrix M [kg].
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
// The term runs the integrator's step life cycle from its own (begin_step,
// advise_step, end_step, checkpoints under the term's prefix): the solver calls every
// term's, and every dynamic scene has inertia.
#pragma once
#include <petscvec.h>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fem/element.h"
#include "fem/energy.h"
#include "fem/time_integrator.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

// A dynamic scene's inertia: its time integrator's options and the mass lumping.
struct InertiaOptions : TimeIntegratorOptions {
  bool lumped = false;  // HRZ-lumped (diagonal) instead of consistent mass
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
  // volumes); pieces: cells of part `rank` with positive density. The integrator
  // weights the mass matrix; the term advances it.
  InertiaTerm(const Mesh& mesh, const Partition& partition, int rank, std::vector<double> density,
              std::shared_ptr<TimeIntegrator> integrator, bool lumped = false);

  std::string name() const override { return "inertia"; }
  int n_pieces() const override { return static_cast<int>(cells_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  void end_step(Assembler& assembler, Vec u1, double t1) override;
  StepAdvice advise_step(Assembler& assembler, Vec u1, double t0, double t1) override;
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) override;
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) override;

  // Starts the integrator's history at the state u0 at time t0, with a_0 from
  // M a_0 = f(u_0, t_0) (CG on this term's mass matrix) where the scheme uses it.
  // Called by the first begin_step if not called before; call it explicitly (after
  // the solver is constructed, which sets up the assembler) to report the initial
  // kinetic energy. Collective.
  void initialize(Assembler& assembler, Vec u0, double t0);

  // Kinetic energy 1/2 v_n^T M v_n [J] of the last converged step. Collective.
  double kinetic_energy(Assembler& assembler);
  // Total mass [kg]. Collective.
  double mass(Assembler& assembler) const;

  // The integrator's initial velocity, velocity v_n and error estimate, for the
  // term's users.
  void set_initial_velocity(std::function<Eigen::Vector3d(const Eigen::Vector3d& X)> v0) {
    integrator_->set_initial_velocity(std::move(v0));
  }
  Vec velocity() const { return integrator_->velocity(); }
  double last_error() const { return integrator_->last_error(); }

 private:
  void equilibrium_acceleration(Assembler& assembler, Vec u0, double t0, Vec a0);

  const Mesh& mesh_;
  std::vector<int> cells_;
  std::vector<Eigen::MatrixXd> mass_;  // per piece, n x n [kg]
  std::shared_ptr<TimeIntegrator> integrator_;

  std::vector<Eigen::MatrixXd> pred_piece_;  // per piece, n x 3 [m], of the current step
  bool suppressed_ = false;                  // piece() returns 0 (forces for a_0)
};

}  // namespace morphfem
