// The one energy-term interface. Every model ingredient (elasticity, body force,
// dead tractions, cavity pressure, later contact, friction, inertia) is a sum of
// local "pieces" (a cell, a face, a contact pair), each a pure kernel mapping the
// piece's reference and current nodal positions to an energy [J], its gradient
// [N] and Hessian [N/m]. One assembly loop (fem/assembly.cpp) serves every term.
#pragma once
#include <petscvec.h>

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "core/state_file.h"

namespace morphfem {

// Nodal data of one piece, n nodes: reference coordinates X and displacement u
// (both n x 3, metres). Current position x = X + u.
struct PieceState {
  Eigen::MatrixXd X;
  Eigen::MatrixXd u;
};

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  virtual std::string name() const = 0;

  // Pieces assembled on this MPI rank, and the global node ids of piece k.
  virtual int n_pieces() const = 0;
  virtual void piece_nodes(int k, std::vector<int>& nodes) const = 0;

  // Energy of piece k [J]. If g (size 3n) / H (3n x 3n) are given, also the
  // gradient and Hessian w.r.t. the piece's displacement dofs, ordered 3*a + i
  // (node a, component i). Returns +infinity if the state is outside the term's
  // domain (an inverted element, a penetrated barrier): the line search then
  // rejects the step.
  virtual double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const = 0;

  // True if at any state most pieces are zero (contact candidates beyond the
  // barrier). The assembler then stores the term's Hessian in one 3 x 3 block per
  // coupled node pair, shared by every piece that couples them, and adds only the
  // nonzero pieces, instead of one n x n block per piece: the pattern and the work
  // scale with the coupled node pairs, not with the candidates. Same matrix.
  virtual bool sparse_pieces() const { return false; }

  // Terms that project their Hessian to PSD (per-pair barrier Hessians, friction's
  // static-to-kinetic drop) give the exact Hessian while `exact` is set. The solver's
  // adaptive projection sets it once Newton takes full steps: near a minimum the
  // total Hessian is positive definite and the exact one converges quadratically,
  // where the projected one converges linearly (SolverOptions::hessian_projection).
  virtual void set_exact_hessian(bool /*exact*/) {}

  // Time-dependent parameters (pressure, traction, friction at time t) [s].
  virtual void set_time(double /*t*/) {}
  // Called once before every sweep over the pieces with the full displacement on
  // this rank's nodes, for terms that need a global reduction first (cavity
  // volumes of gas-filled cavities). Default: nothing.
  virtual void prepare(const class Assembler& /*assembler*/, const std::vector<double>& /*u_local*/) {}

  // Called once before each step with the converged state u0: a term whose
  // pieces depend on the state (self-contact candidate pairs) may rebuild them and
  // return true; the solver then rebuilds the assembly pattern. Collective.
  virtual bool refresh_pieces(class Assembler& /*assembler*/, Vec /*u0*/) { return false; }

  // Step life cycle (time stepping, lagged quantities). begin_step is called
  // before every attempt of the step t0 -> t1 with the converged state u0 at t0
  // (again after a step cut); end_step once the step converged with u1. Terms
  // keep history (velocities, lagged normal forces, gas amounts) here.
  virtual void begin_step(class Assembler& /*assembler*/, Vec /*u0*/, double /*t0*/, double /*t1*/) {}
  virtual void end_step(class Assembler& /*assembler*/, Vec /*u1*/, double /*t1*/) {}
  // After the step t0 -> t1 converged (before end_step): time-step control from a
  // local error estimate. accept = false rejects the step (it is retried with
  // dt_next); dt_next bounds the next step. Collective. Default: no opinion.
  struct StepAdvice {
    bool accept = true;
    double dt_next = 1e300;
  };
  virtual StepAdvice advise_step(class Assembler& /*assembler*/, Vec /*u1*/, double /*t0*/, double /*t1*/) {
    return {};
  }
  // After Newton converged at t1 and before end_step: a term may update its own
  // parameters (e.g. an augmented-Lagrangian multiplier of a volume constraint)
  // and return true to ask for another solve of the same step (at most
  // SolverOptions::max_outer_updates times). Collective. Default: false.
  virtual bool update_after_solve(class Assembler& /*assembler*/, Vec /*u1*/) { return false; }

  // Largest fraction alpha in (0, 1] such that u + alpha du stays admissible for
  // this term (e.g. no node crosses a contact barrier). Collective. Default 1.
  virtual double max_step(class Assembler& /*assembler*/, Vec /*u*/, Vec /*du*/) { return 1.0; }

  // Dense low-rank Hessian parts that would fill the sparse matrix, e.g. the gas
  // stiffness (nRT/V^2) dV dV^T of a gas-filled cavity: H += sum_j c_j v_j v_j^T.
  // The term creates the vectors (assembled global vectors, zero on constrained
  // dofs, from assembler.create_vector()); the caller destroys them. Collective.
  struct LowRank {
    Vec v;
    double c;
  };
  virtual bool has_low_rank() const { return false; }
  virtual void low_rank(class Assembler& /*assembler*/, Vec /*u*/, std::vector<LowRank>& /*out*/) {}

  // Checkpoints (morphfem run --resume): a term with history between steps
  // (velocities, strain rates, gas amounts, multipliers, contact candidates) saves
  // it under keys that start with `prefix` and loads it back exactly, so a resumed
  // run continues as if it had never stopped. Called between steps only. Collective;
  // `state` is complete on rank 0 after save_state and on every rank for load_state
  // (fem/term_state.h has the helpers). Default: no history.
  virtual void save_state(class Assembler& /*assembler*/, const std::string& /*prefix*/, StateRecord& /*state*/) {}
  virtual void load_state(class Assembler& /*assembler*/, const std::string& /*prefix*/, const StateRecord& /*state*/) {
  }
};

}  // namespace morphfem
