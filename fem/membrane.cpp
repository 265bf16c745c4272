#include "fem/membrane.h"

#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/strings.h"
#include "fem/loads.h"
#include "fem/material.h"

namespace morphfem {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Incompressible neo-Hookean matrix (plane stress) plus optional tension-only fibres.
class FabricMembrane final : public MembraneLaw {
 public:
  FabricMembrane(std::string name, double mu, double fibre_modulus, std::vector<Eigen::Vector3d> fibres)
      : name_(std::move(name)), mu_(mu), fibre_modulus_(fibre_modulus), fibres_(std::move(fibres)) {}
  std::string name() const override { return name_; }
  const std::vector<Eigen::Vector3d>& fibre_directions() const override { return fibres_; }

  double energy(const Eigen::Matrix2d& C, const std::vector<Eigen::Vector2d>& fibres) const override {
    if (!(C.determinant() > 0)) return kInf;
    double psi;
    Eigen::Matrix2d S;
    evaluate(C, fibres, psi, S, nullptr);
    return psi;
  }

  void evaluate(const Eigen::Matrix2d& C, const std::vector<Eigen::Vector2d>& fibres, double& psi, Eigen::Matrix2d& S,
                Eigen::Matrix4d* CC) const override {
    const double D = C.determinant();
    const Eigen::Matrix2d Ci = C.inverse();
    psi = 0.5 * mu_ * (C.trace() + 1.0 / D - 3.0);
    S = mu_ * (Eigen::Matrix2d::Identity() - Ci / D);
    if (CC) {
      for (int I = 0; I < 2; ++I)
        for (int J = 0; J < 2; ++J)
          for (int K = 0; K < 2; ++K)
            for (int L = 0; L < 2; ++L)
              (*CC)(2 * I + J, 2 * K + L) =
                  2.0 * mu_ / D * (Ci(I, J) * Ci(K, L) + 0.5 * (Ci(I, K) * Ci(J, L) + Ci(I, L) * Ci(J, K)));
    }
    if (!(fibre_modulus_ > 0)) return;
    for (const auto& a : fibres) {
      const double e = a.dot(C * a) - 1.0;
      if (!(e > 0)) continue;  // slack fibre: no energy, stress or stiffness
      const Eigen::Matrix2d aa = a * a.transpose();
      psi += 0.125 * fibre_modulus_ * e * e;
      S += 0.5 * fibre_modulus_ * e * aa;
      if (CC) {
        const Eigen::Vector4d v(aa(0, 0), aa(0, 1), aa(1, 0), aa(1, 1));
        *CC += fibre_modulus_ * v * v.transpose();
      }
    }
  }

 private:
  std::string name_;
  double mu_;             // matrix shear modulus [Pa]
  double fibre_modulus_;  // E_f [Pa] (0: no fibres)
  std::vector<Eigen::Vector3d> fibres_;
};

std::unique_ptr<MembraneLaw> make_neo_hookean_membrane(const ParamSet& params) {
  params.allow_only({"model", "mu"});
  return std::make_unique<FabricMembrane>("neo_hookean", positive_parameter(params, "mu", 1e13, "shear modulus [Pa]"),
                                          0.0, std::vector<Eigen::Vector3d>{});
}

std::unique_ptr<MembraneLaw> make_fabric_membrane(const ParamSet& params) {
  params.allow_only({"model", "mu", "fibre_modulus", "fibres"});
  const double mu = positive_parameter(params, "mu", 1e13, "matrix shear modulus [Pa]");
  const double modulus = positive_parameter(params, "fibre_modulus", 1e13, "fibre modulus E_f [Pa]");
  return std::make_unique<FabricMembrane>("fabric", mu, modulus, fibre_directions(params));
}

}  // namespace

const std::vector<Eigen::Vector3d>& MembraneLaw::fibre_directions() const {
  static const std::vector<Eigen::Vector3d> none;
  return none;
}

const std::map<std::string, MembraneLawFactory>& membrane_law_registry() {
  static const std::map<std::string, MembraneLawFactory> registry = {
      {"neo_hookean", make_neo_hookean_membrane},
      {"fabric", make_fabric_membrane},
  };
  return registry;
}

std::unique_ptr<MembraneLaw> make_membrane_law(const ParamSet& params) {
  const std::string model = params.string("model");
  const auto& registry = membrane_law_registry();
  const auto it = registry.find(model);
  if (it == registry.end()) {
    throw InputError(params.where("model"),
                     "unknown membrane model '" + model + "' (known: " + join_keys(registry, ", ") + ")");
  }
  return it->second(params);
}

double membrane_stress(const MembraneLaw& law, const Mat32& F, const std::vector<Eigen::Vector2d>& fibres, Mat32* P,
                       Mat6* A) {
  const Eigen::Matrix2d C = F.transpose() * F;
  if (!(C.determinant() > 0)) return kInf;
  if (!P) return law.energy(C, fibres);
  double psi = 0.0;
  Eigen::Matrix2d S;
  Eigen::Matrix4d CC;
  law.evaluate(C, fibres, psi, S, A ? &CC : nullptr);
  *P = F * S;
  if (A) {
    // A_iJkL = d_ik S_JL + F_iI CC_IJML F_kM
    A->setZero();
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 2; ++J)
        for (int k = 0; k < 3; ++k)
          for (int L = 0; L < 2; ++L) {
            double v = i == k ? S(J, L) : 0.0;
            for (int I = 0; I < 2; ++I)
              for (int M = 0; M < 2; ++M) v += F(i, I) * CC(2 * I + J, 2 * M + L) * F(k, M);
            (*A)(2 * i + J, 2 * k + L) = v;
          }
  }
  return psi;
}

MembraneTerm::MembraneTerm(const Mesh& mesh, const Partition& partition, int rank, MembraneSpec spec)
    : mesh_(mesh), spec_(std::move(spec)) {
  if (!spec_.law) throw InputError(spec_.where, "no membrane law given");
  if (!(spec_.thickness > 0) || !std::isfinite(spec_.thickness))
    throw InputError(spec_.where, "thickness must be a positive length [m]");
  if (!mesh.has_region(spec_.surface, 2))
    throw InputError(spec_.where, "the mesh has no surface region '" + spec_.surface + "'");
  faces_ = owned_faces(mesh, partition, rank, mesh.faces_of(spec_.surface));
  const ShapeTable table = make_triangle_table(mesh.order, 2 * mesh.order);
  const int n = mesh.nodes_per_face();
  Eigen::MatrixXd X(n, 3);
  points_.resize(faces_.size());
  for (size_t k = 0; k < faces_.size(); ++k) {
    for (int a = 0; a < n; ++a) X.row(a) = mesh.X.row(mesh.faces(faces_[k], a));
    for (size_t q = 0; q < table.points.size(); ++q) {
      const Eigen::Matrix<double, 3, 2> T = X.transpose() * table.dN[q];  // dX/dxi
      const Eigen::Vector3d t1 = T.col(0), normal = t1.cross(Eigen::Vector3d(T.col(1)));
      const double measure = normal.norm();
      if (!(measure > 0)) throw InputError(spec_.where, "surface '" + spec_.surface + "' has a degenerate triangle");
      const Eigen::Vector3d e1 = t1.normalized(), nn = normal / measure, e2 = nn.cross(e1);
      Eigen::Matrix<double, 2, 3> E;
      E.row(0) = e1.transpose();
      E.row(1) = e2.transpose();
      const Eigen::Matrix2d J2 = E * T;  // in-plane reference Jacobian, det = measure
      Point p;
      p.dN_dS = table.dN[q] * J2.inverse();
      p.weight = spec_.thickness * table.points[q].weight * measure;
      for (const Eigen::Vector3d& d : spec_.law->fibre_directions()) {
        const Eigen::Vector3d in_plane = d - d.dot(nn) * nn;
        if (!(in_plane.norm() > 1e-6))
          throw InputError(spec_.where, "a fibre direction is normal to surface '" + spec_.surface + "'");
        p.fibres.push_back((E * in_plane).normalized());
      }
      points_[k].push_back(std::move(p));
    }
  }
}

void MembraneTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int f = faces_[k];
  nodes.assign(mesh_.faces.row(f).data(), mesh_.faces.row(f).data() + mesh_.faces.cols());
}

// E = sum_q w_q psi(F_s(q)), F_s = x^T dN/dS; g = sum_q w_q B^T P, H = sum_q w_q B^T A B
// with B(2 i + J, 3 b + k) = d_ik dN_b/dS_J.
double MembraneTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int n = static_cast<int>(s.X.rows());
  const Eigen::MatrixXd x = s.X + s.u;
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  double energy = 0.0;
  Mat32 P;
  Mat6 A;
  Eigen::MatrixXd B(6, 3 * n);
  for (const Point& p : points_[k]) {
    const Mat32 F = x.transpose() * p.dN_dS;
    const bool derivatives = g || H;
    const double psi = membrane_stress(*spec_.law, F, p.fibres, derivatives ? &P : nullptr, H ? &A : nullptr);
    if (!std::isfinite(psi)) return kInf;
    energy += p.weight * psi;
    if (!derivatives) continue;
    B.setZero();
    for (int b = 0; b < n; ++b)
      for (int i = 0; i < 3; ++i)
        for (int J = 0; J < 2; ++J) B(2 * i + J, 3 * b + i) = p.dN_dS(b, J);
    Vec6 Pv;
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 2; ++J) Pv(2 * i + J) = P(i, J);
    if (g) *g += p.weight * B.transpose() * Pv;
    if (H) *H += p.weight * B.transpose() * A * B;
  }
  return energy;
}

}  // namespace morphfem
