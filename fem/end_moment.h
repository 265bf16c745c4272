// Conservative pure end moment on a beam's end section (e.g. the cantilever's
// "tip" face), bending in the plane spanned by the beam axis (component `axis`) and
// the section's thickness direction (component `across`):
//   E = -M(t) theta(x)      [J],  M [N m], theta [rad]
// theta is the rotation angle of the section in that plane, measured from a
// director d computed from the current positions x_a of the section's nodes by a
// least-squares fit of x against the reference thickness coordinate Z:
//   d = sum_a c_a x_a,  c_a = (Z_a - Zbar) / sum_b (Z_b - Zbar)^2    (d = dx/dZ)
//   theta = atan2(-d_axis, d_across) - theta_0     (theta_0: the reference value)
// For a rigid rotation of the section by phi about the third axis, theta = phi
// exactly (sum_a c_a = 0 removes translations). Positive M turns the section from
// `across` towards -`axis` (e.g. axis x, across z: the tip rises in +z and curls
// back towards the root). atan2 jumps at +-pi; the term follows the branch
// continuously: theta is taken within pi of the angle of the last converged state,
// updated in begin_step / end_step, so theta = 2 pi (a closed circle) is reachable.
//
// With p = d_axis, q = d_across, r^2 = p^2 + q^2 (theta = atan2(-p, q)):
//   dtheta/dp = -q/r^2, dtheta/dq = p/r^2,
//   d2theta/dp2 = 2pq/r^4, d2theta/dp dq = (q^2 - p^2)/r^4, d2theta/dq2 = -2pq/r^4,
// and dd/du_a = c_a I, so dtheta/du_ai = c_a dtheta/dd_i and
// d2theta/du_ai du_bk = c_a c_b d2theta/dd_i dd_k.
// One piece holds every node of the section (assembled by the rank owning the first).
#pragma once
#include <functional>
#include <vector>

#include "fem/energy.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

class EndMomentTerm : public EnergyTerm {
 public:
  // section_nodes: node ids of the end section after partitioning (e.g.
  // mesh.nodes_of_surface("tip")); axis, across: distinct components 0..2;
  // moment(t): M [N m] at pseudo-time t [s].
  EndMomentTerm(const Mesh& mesh, const Partition& partition, int rank, std::vector<int> section_nodes, int axis,
                int across, std::function<double(double)> moment);

  std::string name() const override { return "end_moment"; }
  int n_pieces() const override { return owner_ ? 1 : 0; }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override { moment_now_ = moment_(t); }
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  void end_step(Assembler& assembler, Vec u1, double t1) override;
  // The branch centre (the winding of the section's rotation).
  void save_state(Assembler&, const std::string& prefix, StateRecord& state) override {
    state.set_number(prefix + ".branch", branch_);
  }
  void load_state(Assembler&, const std::string& prefix, const StateRecord& state) override {
    branch_ = state.number(prefix + ".branch", "checkpoint: " + prefix);
  }

  // Section rotation theta [rad] of a whole displacement field (n_nodes x 3), on the
  // branch of the last converged state.
  double angle(const RowMatrixXd& u) const;
  // Moves the branch centre to the angle of a whole displacement field (what
  // begin_step / end_step do with the converged state).
  void follow(const RowMatrixXd& u) { branch_ = angle(u); }
  // Angle of the last converged state (the branch centre) [rad].
  double converged_angle() const { return branch_; }
  double moment() const { return moment_now_; }

 private:
  // theta of current section positions x (n x 3, ordered as section_nodes_).
  double angle_of_positions(const Eigen::MatrixXd& x) const;

  const Mesh& mesh_;
  std::vector<int> nodes_;
  Eigen::VectorXd weights_;  // c_a [1/m]
  int axis_, across_;
  std::function<double(double)> moment_;
  double moment_now_ = 0.0;
  double theta0_ = 0.0;  // raw angle of the reference configuration [rad]
  double branch_ = 0.0;  // theta of the last converged state [rad]
  bool owner_ = false;
};

}  // namespace morphfem
