// Mean-dilatation element (formulas in mean_dilatation.h).
#include "fem/mean_dilatation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/errors.h"

namespace morphfem {

namespace {

int isochoric_degree(int quadrature_degree) { return quadrature_degree > 0 ? quadrature_degree : 2; }

}  // namespace

MeanDilatationTerm::MeanDilatationTerm(const Mesh& mesh, const Partition& partition, int rank,
                                       std::vector<std::shared_ptr<const Material>> materials, int quadrature_degree)
    : ElasticTerm(mesh, partition, rank, std::move(materials),
                  mesh.order == 1 ? 1 : isochoric_degree(quadrature_degree)) {
  if (mesh.order != 2)
    throw InputError("solver.formulation",
                     "formulation 'mean_dilatation' needs P2 (order: 2) tetrahedra: on P1 tetrahedra J is "
                     "already constant per cell, so it would be identical to 'displacement' and lock the "
                     "same way at nu -> 0.5");
  volume_table_ = make_tet_table(2, std::max(3, isochoric_degree(quadrature_degree)));
}

void MeanDilatationTerm::dilatation(const PieceState& s, double& reference_volume, double& theta) const {
  Eigen::MatrixXd dN_dX;
  double V = 0.0, v = 0.0;
  for (size_t q = 0; q < volume_table_.points.size(); ++q) {
    const double dV = volume_table_.points[q].weight * physical_gradients(s.X, volume_table_.dN[q], dN_dX);
    const Mat3 F = Mat3::Identity() + s.u.transpose() * dN_dX;
    V += dV;
    v += dV * F.determinant();
  }
  reference_volume = V;
  theta = v / V;
}

double MeanDilatationTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const Material& material = *materials_[mesh_.cell_region[cells_[k]]];
  const int n = static_cast<int>(s.X.rows());
  const double inf = std::numeric_limits<double>::infinity();
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  Eigen::MatrixXd dN_dX, B;
  double energy = 0.0;
  Mat3 P;
  Tangent A;

  // ---- Isochoric part: int_e W_iso(F) dV.
  for (size_t q = 0; q < table_.points.size(); ++q) {
    const double dV = table_.points[q].weight * physical_gradients(s.X, table_.dN[q], dN_dX);
    const Mat3 F = Mat3::Identity() + s.u.transpose() * dN_dX;
    if (!(F.determinant() > 0.0)) return inf;
    double W;
    material.evaluate_isochoric(F, W, P, H ? &A : nullptr);
    energy += dV * W;
    if (!g && !H) continue;
    deformation_gradient_map(dN_dX, B);
    if (g) {
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> P_rows = P;  // flattened as 3*i + J
      *g += dV * B.transpose() * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(P_rows.data());
    }
    if (H) H->noalias() += dV * B.transpose() * A * B;
  }

  // ---- Volumetric part: V_e U(Theta_e), Theta_e = v_e / V_e.
  double V = 0.0, v = 0.0;
  Eigen::VectorXd dv;   // dv/du (3n) [m^2]
  Eigen::MatrixXd d2v;  // d2v/du2 (3n x 3n) [m]
  if (g || H) dv.setZero(3 * n);
  if (H) d2v.setZero(3 * n, 3 * n);
  Eigen::MatrixXd grad_x;  // spatial gradients g_ai = (dN/dX F^-1)_ai  [1/m]
  for (size_t q = 0; q < volume_table_.points.size(); ++q) {
    const double dV = volume_table_.points[q].weight * physical_gradients(s.X, volume_table_.dN[q], dN_dX);
    const Mat3 F = Mat3::Identity() + s.u.transpose() * dN_dX;
    const double J = F.determinant();
    if (!(J > 0.0)) return inf;
    V += dV;
    v += dV * J;
    if (!g && !H) continue;
    grad_x = dN_dX * F.inverse();
    for (int a = 0; a < n; ++a)
      for (int i = 0; i < 3; ++i) dv(3 * a + i) += dV * J * grad_x(a, i);
    if (!H) continue;
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        for (int i = 0; i < 3; ++i)
          for (int kk = 0; kk < 3; ++kk)
            d2v(3 * a + i, 3 * b + kk) += dV * J * (grad_x(a, i) * grad_x(b, kk) - grad_x(a, kk) * grad_x(b, i));
  }
  const double theta = v / V;
  double U, dU, d2U;
  material.volumetric_energy(theta, U, dU, d2U);
  energy += V * U;
  // d(V U(v/V))/du = U' dv;  d2 = U''/V dv dv^T + U' d2v
  if (g) *g += dU * dv;
  if (H) {
    H->noalias() += (d2U / V) * dv * dv.transpose();
    *H += dU * d2v;
  }
  return energy;
}

void MeanDilatationTerm::set_growth(int, GrowthFunction) {
  throw std::invalid_argument("growth (active strain) is not available with the mean_dilatation formulation");
}

}  // namespace morphfem
