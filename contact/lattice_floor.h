// The voxel lattice's floor contact (Voxelyze, CVX_Voxel::floorPenetration /
// floorForce), as an energy term: a diagnostic that gives a finite-element body the
// contact the lattice has, to test which of the lattice's mechanics its gaits need
// (README, "Rolling does not reproduce on flat ground"). Not a contact model of the
// real robot: a continuum touches the ground with its faces (contact/ground.h).
//
// In the lattice every voxel touches the floor as a sphere at its centre, of radius
// half its mean scaled size, r = L (s_x + s_y + s_z) / 6 (L [m] the nominal voxel
// size, s its scale), whatever its orientation and shape; the floor force acts at
// the centre (no moment). Here a lattice voxel is a box of reference space and its
// centre the material point at the box's centre X_k, as the finite-element field
// interpolates it: with N_a the shape functions of the cell containing X_k,
//
//   c = sum_a w_a x_a,   w_a = N_a(X_k)                                  [-]
//
// a fixed linear combination of nodal positions, exact under affine motion and
// defined on any mesh, however coarse against the voxels. Each point k carries the
// smooth log barrier of contact/barrier.h and IPC-style lagged friction
// (contact/friction.h):
//
//   gap      d_k = n . (c_k - p0) - r_k                                  [m]
//   barrier  E_k = A_k kappa dhat phi(d_k / dhat)                        [J]
//   friction D_k = lambda_k F(|P (c_k - c0_k)|),  mu_k(t), eps = eps_v h  [J]
//
// A_k [m^2] the box's reference footprint (its x-y extent), lambda_k the barrier
// force at the step's start c0_k, P = I - n n^T.
//
// Growing radii: r_k(t) is prescribed (the lattice's nominal scale, not the
// deformation), so a radius that grows during a step could put the start state
// inside the floor (infinite energy). The radius of a step is therefore
//   r_k = min(r_k(t1), max(r_prev, n . (c0_k - p0) - catch_up dhat)),
// where r_prev is the previous step's radius: it grows at most until the sphere is
// catch_up dhat from the floor at the step's start, and catches up in the next
// steps as the body is pushed off (the lattice, stepping explicitly, resolves a
// growing voxel's penetration over its next steps too). It shrinks without lag.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "contact/box_grid.h"
#include "fem/assembly.h"
#include "fem/energy.h"
#include "fem/time_function.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

struct LatticePoint {
  std::vector<int> nodes;                // nodes whose positions make the centre
  std::vector<double> weights;           // c = sum w_a x_a (sum w_a = 1)
  double area = 0.0;                     // A [m^2], the barrier's area weight
  std::function<double(double)> radius;  // r(t) [m]
  TimeFunction mu;                       // friction coefficient mu(t) [-] (static = kinetic)
  int owner_cell = 0;                    // the rank owning this cell assembles the point
};

// Interpolation weights of the material point at reference position X (see the
// header comment): the cell of `cells` that contains X (straight cells), or, if none
// does, the one nearest to containing it (the largest smallest barycentric
// coordinate); fills nodes (its nodes) and weights (its shape functions at X), and
// returns the cell. Throws InputError if cells is empty.
int interpolation_weights(const Mesh& mesh, const std::vector<int>& cells, const Eigen::Vector3d& X,
                          std::vector<int>& nodes, std::vector<double>& weights);

// interpolation_weights for many points X in the same cells, at the cost of the
// cells listed at X instead of all: a BoxGrid of the cells' bounding boxes (spacing
// their mean size) gives the cells whose box holds X, which include every cell that
// contains X; if none of them contains X, every cell is scored. The result is the
// same cell as interpolation_weights's (the test compares them). Building costs
// O(cells), a point O(cells listed at X) when it lies in the mesh.
class CellLocator {
 public:
  CellLocator(const Mesh& mesh, std::vector<int> cells);  // throws InputError if cells is empty
  int weights(const Eigen::Vector3d& X, std::vector<int>& nodes, std::vector<double>& weights) const;

 private:
  const Mesh& mesh_;
  std::vector<int> cells_;
  BoxGrid grid_;  // positions into cells_
};

struct LatticeFloorSpec {
  Eigen::Vector3d point{0.0, 0.0, 0.0};   // p0 [m], a point of the floor
  Eigen::Vector3d normal{0.0, 0.0, 1.0};  // n (normalised here), floor -> body side
  double dhat = 1e-3;                     // barrier width [m]
  double kappa = 0.0;                     // barrier stiffness [Pa]
  double eps_v = 1e-3;                    // friction smoothing velocity [m/s]
  double max_step_fraction = 0.9;         // a Newton step closes at most this fraction of a gap
  double catch_up = 0.5;                  // a growing radius stops catch_up dhat from the floor
  bool project_hessian = true;            // friction: clamp its curvature to PSD (as FrictionTerm)
};

class LatticeFloorTerm : public EnergyTerm {
 public:
  // Keeps the points whose owner cell partition part `rank` owns. Throws InputError
  // (where "contact.lattice_floor") for a zero normal, kappa or dhat <= 0, a point
  // without nodes, weights that do not sum to 1, or a sphere that starts in the floor.
  LatticeFloorTerm(const Mesh& mesh, const Partition& partition, int rank, LatticeFloorSpec spec,
                   std::vector<LatticePoint> points);

  std::string name() const override { return "lattice_floor"; }
  int n_pieces() const override { return static_cast<int>(points_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override { nodes = points_[k].nodes; }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override;
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  // Exact CCD: the gap is linear along u + alpha du.
  double max_step(Assembler& assembler, Vec u, Vec du) override;
  void set_exact_hessian(bool exact) override { exact_hessian_ = exact; }
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) override;
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) override;

  const LatticeFloorSpec& spec() const { return spec_; }
  // Centre c_k [m] of piece k at nodal displacements s.u.
  Eigen::Vector3d centre(int k, const PieceState& s) const;
  double step_radius(int k) const { return radius_[k]; }
  // For tests: the lagged state of piece k (normal force [N], centre at the step's
  // start [m], the step's radius [m]) and the step length h [s].
  void set_lagged(int k, double lambda, const Eigen::Vector3d& c0, double radius) {
    lambda_[k] = lambda;
    c0_[k] = c0;
    radius_[k] = radius;
  }
  void set_step_length(double h) { h_ = h; }
  // Sum of the floor's normal forces on the body at u [N] (collective).
  double total_normal_force(Assembler& assembler, Vec u) const;

 private:
  Eigen::Vector3d centre_at(int k, const std::vector<double>& u_local, const Assembler& assembler) const;
  double normal_force(int k, double gap) const;

  const Mesh& mesh_;
  LatticeFloorSpec spec_;
  std::vector<LatticePoint> points_;  // owned pieces
  Eigen::Matrix3d tangent_projector_;
  bool exact_hessian_ = false;
  double h_ = 1.0;                   // step length [s]
  std::vector<double> mu_;           // per piece at the current time
  std::vector<double> radius_;       // per piece, this step's radius [m]
  std::vector<double> lambda_;       // per piece, lagged normal force [N]
  std::vector<Eigen::Vector3d> c0_;  // per piece, centre at the step's start [m]
};

}  // namespace morphfem
