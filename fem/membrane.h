// Membranes: thin sheets (a fabric, a strain-limiting layer) carried by a surface region
// of the mesh, with in-plane stiffness and no bending stiffness. The sheet follows the
// triangles of the surface (a boundary face or an internal interface between two
// volumes: it is then embedded in the solid), so a 0.5 mm fabric needs no 0.5 mm
// layer of tetrahedra (thin tetrahedra lock in bending).
//
// Kinematics at a quadrature point of a reference triangle (P1 or P2, curved P2 faces
// allowed): an orthonormal reference tangent basis (e1, e2) with e1 along dX/dxi_1 and
// e2 = n x e1, the in-plane reference gradients dN/dS (n x 2), and
//   F_s = sum_a x_a (dN_a/dS)^T   (3 x 2),   C = F_s^T F_s   (2 x 2, in (e1, e2)).
// Energy (t the sheet's reference thickness [m], psi [Pa] per reference volume):
//   E = t int_S0 psi(C) dA0    [J].
//
// Laws (membrane_law_registry, by `model`):
//   neo_hookean  incompressible neo-Hookean in plane stress (the thickness stretch
//                lambda_3 = det(C)^(-1/2) condensed out):
//                  psi = mu/2 (tr C + 1/det C - 3)
//                  S   = 2 dpsi/dC = mu (I - C^-1 / det C)
//                  CC  = 2 dS/dC:  CC_IJKL = 2 mu / det C (Ci_IJ Ci_KL + (Ci_IK Ci_JL + Ci_IL Ci_JK)/2)
//                Small strain: plane-stress Young's modulus 3 mu, Poisson 1/2.
//   fabric       the same matrix plus fibre families that carry tension only, with
//                in-plane unit directions a (the scene's 3D directions projected on the
//                reference tangent plane):
//                  psi += E_f/8 <I4 - 1>_+^2,  I4 = a . C a
//                  S   += E_f/2 <I4 - 1>_+ a a,   CC += E_f [I4 > 1] a a a a
//                (at small strain a fibre adds E_f eps_aa^2 / 2, as the solid `fabric` law
//                of fem/material.h). Keys mu [Pa], fibre_modulus [Pa], fibres (3 numbers
//                per family, default the warp along x and the weft along y).
// First Piola-Kirchhoff P = F_s S (3 x 2) and its tangent
//   A_iJkL = dP_iJ/dF_kL = d_ik S_JL + F_iI CC_IJML F_kM,
// flattened a = 2 i + J (F_s row-major), like the solid laws.
//
// Mass: a membrane carries none; a scene folds the sheet's areal mass into the volume
// it is embedded in (its density).
#pragma once
#include <Eigen/Dense>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/params.h"
#include "fem/element.h"
#include "fem/energy.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

using Mat32 = Eigen::Matrix<double, 3, 2>;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

class MembraneLaw {
 public:
  virtual ~MembraneLaw() = default;
  virtual std::string name() const = 0;
  // psi(C) [Pa]; +infinity if det C <= 0. `fibres` are the in-plane unit fibre
  // directions at this point (in the basis of C); laws without fibres ignore them.
  virtual double energy(const Eigen::Matrix2d& C, const std::vector<Eigen::Vector2d>& fibres) const = 0;
  // psi, S = 2 dpsi/dC (2 x 2) and, if CC != nullptr, CC = 2 dS/dC as a 4 x 4 matrix
  // CC(2 I + J, 2 K + L). Requires det C > 0.
  virtual void evaluate(const Eigen::Matrix2d& C, const std::vector<Eigen::Vector2d>& fibres, double& psi,
                        Eigen::Matrix2d& S, Eigen::Matrix4d* CC) const = 0;
  // The 3D fibre directions of the scene (empty for laws without fibres).
  virtual const std::vector<Eigen::Vector3d>& fibre_directions() const;
};

using MembraneLawFactory = std::function<std::unique_ptr<MembraneLaw>(const ParamSet&)>;
// name -> factory: neo_hookean (mu), fabric (mu, fibre_modulus, fibres).
const std::map<std::string, MembraneLawFactory>& membrane_law_registry();
// The law named by params["model"] (InputError naming the known models otherwise).
std::unique_ptr<MembraneLaw> make_membrane_law(const ParamSet& params);

// psi, P = dpsi/dF_s (3 x 2) and, if A != nullptr, A = dP/dF_s (6 x 6, a = 2 i + J)
// of a law at F_s. Returns +infinity (and leaves P, A) if det C <= 0.
double membrane_stress(const MembraneLaw& law, const Mat32& F, const std::vector<Eigen::Vector2d>& fibres, Mat32* P,
                       Mat6* A);

struct MembraneSpec {
  std::string surface;     // surface region carrying the sheet
  double thickness = 0.0;  // t [m]
  std::shared_ptr<const MembraneLaw> law;
  std::string where;  // scene key, for messages
};

// Pieces: the faces of spec.surface whose first node rank `rank` owns.
class MembraneTerm final : public EnergyTerm {
 public:
  // Throws InputError (at spec.where) if the surface is unknown, the thickness is not
  // positive, or a fibre direction is normal to the surface somewhere.
  MembraneTerm(const Mesh& mesh, const Partition& partition, int rank, MembraneSpec spec);
  std::string name() const override { return "membrane:" + spec_.surface; }
  int n_pieces() const override { return static_cast<int>(faces_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;

 private:
  struct Point {
    Eigen::MatrixXd dN_dS;                // n x 2 in-plane reference gradients
    double weight = 0.0;                  // t x quadrature weight x reference area measure [m^3]
    std::vector<Eigen::Vector2d> fibres;  // in-plane unit fibre directions
  };
  const Mesh& mesh_;
  MembraneSpec spec_;
  std::vector<int> faces_;
  std::vector<std::vector<Point>> points_;  // per owned face
};

}  // namespace morphfem
