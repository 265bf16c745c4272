// Contact of the body with a rigid plane (flat or inclined ground), enforced at
// the nodes of declared surface regions by a smooth log barrier (contact/barrier.h):
//
//   gap      d_a = n . (X_a + u_a - p0)                                   [m]
//   energy   E   = sum_a A_a kappa dhat phi(d_a / dhat)                   [J]
//   force    f_a = A_a kappa (-phi'(d_a / dhat)) n   (on the body)        [N]
//
// p0 [m] a point of the plane, n its unit normal pointing from the ground into the
// body's side, A_a [m^2] the nodal area weight (reference configuration, fixed),
// kappa [Pa] the barrier stiffness, dhat [m] the barrier width.
//
// Tolerance semantics: the gap is always > 0 -- a state with any d_a <= 0 has
// infinite energy (the line search rejects it) and max_step() keeps every Newton
// step at least (1 - max_step_fraction) of each node's gap away from the plane
// (continuous collision detection against a plane is exact: along u + alpha du
// the gap is linear in alpha). A node is "in contact" while 0 < d < dhat: the
// geometric error of contact (how far above the plane a resting body floats)
// is below dhat, and at contact pressure p the gap settles where
// -phi'(d/dhat) = p/kappa (p << kappa: d ~ dhat (1 - sqrt(p / (3 kappa)))).
//
// Nodal area weights and P2 faces: every node of a contact face (the three
// vertices and, on P2 faces, the three edge mid-nodes) is a contact point. P1:
// A_vertex = area/3 per face. P2: the face is split at its mid-nodes into four
// sub-triangles and each sub-triangle gives a third of its area to its corners
// (vertex area/12, mid-node area/4 per face): positive weights summing to the face
// area (the consistent integrals of the P2 shape functions give vertices zero
// weight, which would leave them unprotected). Between nodes a P1 face against a
// flat plane is linear, so positive nodal gaps mean the whole face is above the
// plane; a curved P2 face may dip between its nodes by O(h^2 x curvature).
//
// Defaults: dhat = 1e-3 x the diagonal of the mesh's bounding box; kappa = the
// Young's modulus E [Pa] of the contacting solid (then the contact pressure in
// units of E is -phi'(s); p = E is reached at s ~ 0.06).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "fem/assembly.h"
#include "fem/energy.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

struct GroundContactSpec {
  std::string name = "ground";
  Eigen::Vector3d point{0.0, 0.0, 0.0};   // p0 [m], a point of the plane
  Eigen::Vector3d normal{0.0, 0.0, 1.0};  // n (normalised here), ground -> body side
  std::vector<std::string> surfaces;      // surface regions whose nodes touch the plane
  double dhat = 0.0;                      // barrier width [m]; <= 0: 1e-3 x bounding-box diagonal
  double kappa = 0.0;                     // barrier stiffness [Pa]; <= 0: young_modulus
  double young_modulus = 0.0;             // [Pa], used only for the default kappa
  double max_step_fraction = 0.9;         // s in (0, 1): a Newton step may close at most s of a gap
};

// Nodal area weights [m^2] of the given faces (reference configuration), one entry
// per mesh node (zero for nodes of no face); see the header comment for P2.
std::vector<double> nodal_area_weights(const Mesh& mesh, const std::vector<int>& faces);

class GroundContactTerm : public EnergyTerm {
 public:
  // Pieces: the contact nodes that partition part `rank` owns (one node each).
  // Throws InputError if a surface is unknown, the normal is zero, kappa cannot
  // be chosen, or a contact node starts on or below the plane (reference gap <= 0).
  GroundContactTerm(const Mesh& mesh, const Partition& partition, int rank, GroundContactSpec spec);

  std::string name() const override { return "ground:" + spec_.name; }
  int n_pieces() const override { return static_cast<int>(owned_nodes_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override { nodes.assign(1, owned_nodes_[k]); }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  // Exact CCD against the plane: alpha = min over nodes approaching the plane of
  // s * d / (-du . n), s = max_step_fraction. Collective.
  double max_step(Assembler& assembler, Vec u, Vec du) override;

  const GroundContactSpec& spec() const { return spec_; }
  double dhat() const { return spec_.dhat; }
  double kappa() const { return spec_.kappa; }
  const Eigen::Vector3d& normal() const { return spec_.normal; }
  // Gap d = n . (x - p0) [m] of a current position x [m].
  double gap(const Eigen::Vector3d& x) const { return spec_.normal.dot(x - spec_.point); }
  // Nodal area weight [m^2] (0 for nodes that are not contact nodes).
  double area_weight(int node) const { return weight_[node]; }
  // Normal force magnitude [N] at a node of area weight A at gap d (0 for d >= dhat;
  // +inf for d <= 0): A kappa (-phi'(d/dhat)).
  double normal_force(double area_weight, double gap) const;
  // The gap [m] at which the barrier carries a uniform contact pressure p [Pa]
  // (solves kappa (-phi'(d/dhat)) = p by bisection; dhat for p <= 0). Place a
  // resting body at this gap to start it in equilibrium (a body started closer is
  // pushed off, one started farther falls onto the plane).
  double resting_gap(double pressure) const;
  const std::vector<int>& contact_nodes() const { return all_nodes_; }  // every rank, sorted

  // Per mesh node, identical on every rank (collective): the force of the plane
  // on the node [N] (zero off contact), the gap [m] (NaN for non-contact nodes)
  // and the status (0: not a contact node or gap >= dhat, 1: in contact).
  struct NodalContact {
    RowMatrixXd force;
    std::vector<double> gap;
    std::vector<int> status;
  };
  NodalContact nodal_contact(Assembler& assembler, Vec u) const;
  // Sum of the contact forces on the body [N] (collective).
  Eigen::Vector3d total_force(Assembler& assembler, Vec u) const;
  // Smallest gap over all contact nodes [m] (collective).
  double min_gap(Assembler& assembler, Vec u) const;

 private:
  const Mesh& mesh_;
  GroundContactSpec spec_;
  std::vector<double> weight_;    // per mesh node [m^2]
  std::vector<int> all_nodes_;    // contact nodes (weight > 0)
  std::vector<int> owned_nodes_;  // those this rank owns = pieces
};

}  // namespace morphfem
