// Dead loads (fixed in the reference configuration):
//   body force     E = - int_V  b(X, t) . u dV      b [N/m^3] (gravity: rho g)
//   surface load   E = - int_S  t(X, t) . u dA      t [Pa]    (reference area)
// Their gradients are the (negated) consistent nodal forces; Hessians are zero.
// The nodal forces of every piece are computed once per time (set_time) and
// reused by every sweep: the energy is then -f_e . u_e.
#pragma once
#include <functional>

#include "fem/element.h"
#include "fem/energy.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

using VectorField = std::function<Eigen::Vector3d(const Eigen::Vector3d& X, double t)>;

// Pieces: the given cells that partition part `rank` owns.
class BodyForceTerm : public EnergyTerm {
 public:
  BodyForceTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& cells,
                VectorField body_force, int quadrature_degree);
  std::string name() const override { return "body_force"; }
  int n_pieces() const override { return static_cast<int>(cells_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override;

 private:
  const Mesh& mesh_;
  std::vector<int> cells_;
  VectorField force_;
  ShapeTable table_;
  double time_ = -1.0;
  std::vector<Eigen::VectorXd> nodal_force_;  // per piece, 3n [N]
};

// Pieces: the given boundary faces whose first node this rank owns.
class SurfaceLoadTerm : public EnergyTerm {
 public:
  SurfaceLoadTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& faces,
                  VectorField traction);
  std::string name() const override { return "surface_load"; }
  int n_pieces() const override { return static_cast<int>(faces_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override;

 private:
  const Mesh& mesh_;
  std::vector<int> faces_;
  VectorField traction_;
  ShapeTable table_;
  double time_ = -1.0;
  std::vector<Eigen::VectorXd> nodal_force_;  // per piece, 3n [N]
};

// The faces among `faces` that rank `rank` assembles (owner of the face's first node).
std::vector<int> owned_faces(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& faces);

}  // namespace morphfem
