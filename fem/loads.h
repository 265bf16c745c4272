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

// The shared part of both: pieces are mesh entities (cells or boundary faces), each
// with nodal forces f_a = int N_a v(X, t) dm [N] (dm = dV or the reference dA) that
// set_time recomputes when t changes.
class DeadLoadTerm : public EnergyTerm {
 public:
  int n_pieces() const override { return static_cast<int>(entities_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override;

 protected:
  enum class Entity { cell, face };
  DeadLoadTerm(const Mesh& mesh, Entity kind, std::vector<int> entities, VectorField field, ShapeTable table);

 private:
  const Mesh& mesh_;
  Entity kind_;
  std::vector<int> entities_;
  VectorField field_;
  ShapeTable table_;
  double time_ = -1.0;
  std::vector<Eigen::VectorXd> nodal_force_;  // per piece, 3n [N]
};

// Pieces: the given cells that partition part `rank` owns; b [N/m^3].
class BodyForceTerm final : public DeadLoadTerm {
 public:
  BodyForceTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& cells,
                VectorField body_force, int quadrature_degree);
  std::string name() const override { return "body_force"; }
};

// Pieces: the given boundary faces whose first node this rank owns; t [Pa].
class SurfaceLoadTerm final : public DeadLoadTerm {
 public:
  SurfaceLoadTerm(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& faces,
                  VectorField traction);
  std::string name() const override { return "surface_load"; }
};

// The faces among `faces` that rank `rank` assembles (owner of the face's first node).
std::vector<int> owned_faces(const Mesh& mesh, const Partition& partition, int rank, const std::vector<int>& faces);

}  // namespace morphfem
