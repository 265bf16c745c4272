// Closed cavity (bladder) loaded by a prescribed pressure p(t) [Pa] as a follower
// load: the energy is the negative pressure work  E = - p V(x),  V the enclosed
// volume [m^3] computed from the cavity's wall faces by the divergence theorem:
//
//   V = -(1/|S|) sum_faces int_face (S x) . n dA,   S = diag(s_x, s_y, s_z), s in {0,1}
//
// where n is the wall's normal pointing out of the solid (into the cavity) and
// |S| = s_x + s_y + s_z. With S = I the wall must be closed. A cavity cut by
// symmetry planes or plane-strain end caps uses only the axes whose coordinate
// vanishes (times n) on the missing faces, e.g. S = diag(1,1,0) for a quarter
// cylinder with caps z = const: the missing faces then contribute nothing and V
// is exact. The Hessian of -pV is the load stiffness; p > 0 inflates.
//
// An open sleeve (open_axis k, e.g. the core of a laminate bonded only along its long
// edges, or a sleeve around a balloon) has no end caps: its wall coordinate along k is
// taken at the reference value X_k inside V, so V = sum of cross-section areas times
// reference lengths. The pressure then acts in the cross-section planes only: no force
// along k and none from the missing caps (the plain S mask would put the caps' p A on
// the rims). S must then be the other two axes.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "fem/assembly.h"
#include "fem/element.h"
#include "fem/energy.h"
#include "fem/time_function.h"

namespace morphfem {

struct CavitySpec {
  std::string name;
  std::vector<std::string> surfaces;           // wall surface regions
  std::array<bool, 3> axes{true, true, true};  // S: which coordinates enter V
  TimeFunction pressure;                       // p(t) [Pa], gauge
  int open_axis = -1;                          // 0, 1, 2: an open sleeve along that axis
};

// Checks an axes mask and open axis (S non-empty; an open axis not in S and S the
// other two); throws std::invalid_argument naming the cavity.
void check_cavity_axes(const std::string& name, const std::array<bool, 3>& axes, int open_axis);

// Kernel for one wall face (n nodes): f = int (S x).(a x b) dxi deta with
// a = dx/dxi, b = dx/deta; gradient and Hessian w.r.t. nodal positions (3n).
// Exposed for the finite-difference tests.
double cavity_face_integral(const ShapeTable& table, const std::array<bool, 3>& axes, const Eigen::MatrixXd& x,
                            Eigen::VectorXd* g, Eigen::MatrixXd* H);

// The same integral for a wall face at reference positions X and current positions x,
// with the open axis (if any, >= 0) frozen at X: derivatives along it are zero.
double cavity_wall_integral(const ShapeTable& table, const std::array<bool, 3>& axes, int open_axis,
                            const Eigen::MatrixXd& X, const Eigen::MatrixXd& x, Eigen::VectorXd* g, Eigen::MatrixXd* H);

// Volume enclosed by a cavity wall [m^3]: -(1/|S|) sum over the wall term's pieces (its
// faces on this rank) of the wall integral at x = X + u, summed over the ranks
// (collective). u_ghost: the rank's ghosted displacement (Assembler::gather).
double cavity_wall_volume(const EnergyTerm& wall, const Mesh& mesh, const Assembler& assembler,
                          const std::vector<double>& u_ghost, const ShapeTable& table, const std::array<bool, 3>& axes,
                          int open_axis);

class CavityPressureTerm : public EnergyTerm {
 public:
  CavityPressureTerm(const Mesh& mesh, const Partition& partition, int rank, CavitySpec spec);
  std::string name() const override { return "cavity:" + spec_.name; }
  int n_pieces() const override { return static_cast<int>(faces_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  void set_time(double t) override { pressure_ = spec_.pressure(t); }

  double pressure() const { return pressure_; }
  const CavitySpec& spec() const { return spec_; }
  // Enclosed volume [m^3] at displacement u (collective). V at u = 0 is the
  // reference volume.
  double volume(Assembler& assembler, Vec u) const;

 private:
  const Mesh& mesh_;
  CavitySpec spec_;
  std::vector<int> faces_;
  ShapeTable table_;
  double pressure_ = 0.0;
};

}  // namespace morphfem
