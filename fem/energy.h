// The one energy-term interface. Every model ingredient (elasticity, body force,
// dead tractions, cavity pressure, later contact, friction, inertia) is a sum of
// local "pieces" (a cell, a face, a contact pair), each a pure kernel mapping the
// piece's reference and current nodal positions to an energy [J], its gradient
// [N] and Hessian [N/m]. One assembly loop (fem/assembly.cpp) serves every term.
#pragma once
#include <Eigen/Dense>
#include <string>
#include <vector>

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

  // Time-dependent parameters (pressure, traction, friction at time t) [s].
  virtual void set_time(double /*t*/) {}
  // Called once before every sweep over the pieces with the full displacement on
  // this rank's nodes, for terms that need a global reduction first (cavity
  // volumes of gas-filled cavities). Default: nothing.
  virtual void prepare(const class Assembler& /*assembler*/, const std::vector<double>& /*u_local*/) {}
};

}  // namespace morphfem
