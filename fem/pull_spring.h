// A materials testing machine pulling a surface region through a linear spring
// (the load cell plus the cable / fixture compliance):
//
//   E(u, t) = k/2 (a(t) - d . xbar(u))^2                                    [J]
//   xbar    = sum_a w_a (X_a + u_a),  w_a = A_a / sum_b A_b                  [m]
//   a(t)    = d . xbar(0) + |v| max(0, t - t0)   (crosshead position)         [m]
//   load    F = k (a(t) - d . xbar(u))            (what the load cell reads) [N]
//
// d = v/|v| the pull direction, k [N/m] the spring stiffness, v [m/s] the crosshead
// velocity, t0 [s] the start, A_a the nodal area weights of the region's faces (a
// third of each face's area to each of its three corner nodes; a P2 face's mid-nodes
// get none, which keeps xbar the exact area mean on flat faces).
// Only the component along d is pulled (the machine's cable is free laterally), so
// the body may move sideways or lift without spring force.
//
// Gradient and Hessian w.r.t. u_a (components i):
//   dE/du_ai      = -k (a - d . xbar) w_a d_i
//   d2E/du_ai du_bj = k w_a w_b d_i d_j           (rank one, PSD)
// One piece holding every node of the region (on rank 0 only; the assembler gathers
// the nodes it needs), so the Hessian block is dense over the region's nodes: keep
// the pulled region small (a foot, a clamp face).
#pragma once
#include <string>
#include <vector>

#include "fem/energy.h"
#include "mesh/mesh.h"

namespace morphfem {

struct PullSpringSpec {
  std::string surface;                // surface region pulled
  double stiffness = 0.0;             // k [N/m]
  Eigen::Vector3d velocity{0, 0, 0};  // v [m/s] (direction and speed of the crosshead)
  double start = 0.0;                 // t0 [s]
  std::string where;                  // scene location for errors
};

class PullSpringTerm : public EnergyTerm {
 public:
  // Throws InputError if the surface is unknown, k <= 0 or v = 0.
  PullSpringTerm(const Mesh& mesh, int rank, PullSpringSpec spec);
  std::string name() const override { return "pull:" + spec_.surface; }
  int n_pieces() const override { return rank_ == 0 ? 1 : 0; }
  void piece_nodes(int k, std::vector<int>& nodes) const override { nodes = nodes_; }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override { time_ = t; }

  const PullSpringSpec& spec() const { return spec_; }
  // Crosshead position a(t) [m] along d.
  double crosshead(double t) const;
  // Pull direction d and the area-weighted mean position along it for a full
  // displacement field (n_nodes x 3) [m].
  const Eigen::Vector3d& direction() const { return direction_; }
  double mean_position(const RowMatrixXd& u) const;
  // Load-cell force k (a(t) - d . xbar(u)) [N] for a full displacement field.
  double force(const RowMatrixXd& u, double t) const { return spec_.stiffness * (crosshead(t) - mean_position(u)); }

 private:
  const Mesh& mesh_;
  int rank_;
  PullSpringSpec spec_;
  Eigen::Vector3d direction_;
  std::vector<int> nodes_;       // region nodes with weight > 0
  std::vector<double> weights_;  // w_a, sum 1
  double x0_ = 0.0;              // d . xbar(0)
  double time_ = 0.0;
};

}  // namespace morphfem
