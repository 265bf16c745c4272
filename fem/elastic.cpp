#include "fem/elastic.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "fem/mean_dilatation.h"

namespace morphfem {

ElasticTerm::ElasticTerm(const Mesh& mesh, const Partition& partition, int rank,
                         std::vector<std::shared_ptr<const Material>> materials, int quadrature_degree)
    : mesh_(mesh), materials_(std::move(materials)) {
  for (int c = 0; c < mesh.n_cells(); ++c)
    if (partition.cell_part[c] == rank) {
      if (!materials_.at(mesh.cell_region[c]))
        throw std::invalid_argument("cell region '" + mesh.regions[mesh.cell_region[c]].name + "' has no material");
      cells_.push_back(c);
    }
  int degree = quadrature_degree > 0 ? quadrature_degree : (mesh.order == 1 ? 1 : 2);
  table_ = make_tet_table(mesh.order, degree);
  growth_stretch_.assign(mesh.regions.size(), Eigen::Vector3d::Ones());
}

void ElasticTerm::set_growth(int region, GrowthFunction growth) {
  if (region < 0 || region >= static_cast<int>(mesh_.regions.size()))
    throw std::invalid_argument("growth: no region " + std::to_string(region));
  growth_.resize(mesh_.regions.size());
  growth_[region] = std::move(growth);
  has_growth_ = true;
  set_time(0.0);
}

void ElasticTerm::set_time(double t) {
  if (!has_growth_) return;
  for (size_t r = 0; r < growth_.size(); ++r) {
    if (!growth_[r]) continue;
    const Eigen::Vector3d g = growth_[r](t);
    if (!(g.minCoeff() > 0))
      throw std::invalid_argument("growth of region '" + mesh_.regions[r].name + "' must stay positive");
    growth_stretch_[r] = g;
  }
}

void ElasticTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int c = cells_[k];
  nodes.assign(mesh_.cells.row(c).data(), mesh_.cells.row(c).data() + mesh_.nodes_per_cell());
}

double ElasticTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const int region = mesh_.cell_region[cells_[k]];
  const Material& material = *materials_[region];
  // Growth: W_G(F) = det G W(F G^-1); h_J = 1/g_J scales column J of F (see the header).
  const Eigen::Vector3d h = growth_stretch_[region].cwiseInverse();
  const double det_G = growth_stretch_[region].prod();
  const bool grown = det_G != 1.0 || h != Eigen::Vector3d::Ones();
  Eigen::Matrix<double, 9, 1> column_scale;  // h_J at flat index 3*i + J
  for (int i = 0; i < 3; ++i) column_scale.segment<3>(3 * i) = h;
  const int n = static_cast<int>(s.X.rows());
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  Eigen::MatrixXd dN_dX, B;
  double energy = 0.0;
  Mat3 P;
  Tangent A;
  for (size_t q = 0; q < table_.points.size(); ++q) {
    const double dV = table_.points[q].weight * physical_gradients(s.X, table_.dN[q], dN_dX);
    // F_iJ = delta_iJ + sum_a u_ai dN_a/dX_J
    Mat3 F = Mat3::Identity() + s.u.transpose() * dN_dX;
    if (F.determinant() <= 0.0) return std::numeric_limits<double>::infinity();
    if (grown) F = F * h.asDiagonal();  // F_e = F G^-1
    if (!g && !H) {
      energy += dV * det_G * material.energy(F);
      continue;
    }
    double W;
    material.evaluate(F, W, P, H ? &A : nullptr);
    if (grown) {
      W *= det_G;
      P = det_G * P * h.asDiagonal();
      if (H) A = det_G * column_scale.asDiagonal() * A * column_scale.asDiagonal();
    }
    energy += dV * W;
    deformation_gradient_map(dN_dX, B);
    if (g) {
      const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> P_rows = P;  // flatten as 3*i + J
      *g += dV * B.transpose() * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(P_rows.data());
    }
    if (H) H->noalias() += dV * B.transpose() * A * B;
  }
  return energy;
}

ElasticTerm::CellMeasures ElasticTerm::measures(int k, const PieceState& s) const {
  const Material& material = *materials_[mesh_.cell_region[cells_[k]]];
  Eigen::MatrixXd dN_dX;
  double volume = 0.0, J_sum = 0.0, J_min = std::numeric_limits<double>::infinity(), vm_sum = 0.0;
  for (size_t q = 0; q < table_.points.size(); ++q) {
    const double dV = table_.points[q].weight * physical_gradients(s.X, table_.dN[q], dN_dX);
    Mat3 F = Mat3::Identity() + s.u.transpose() * dN_dX;
    const double J = F.determinant();
    double W;
    Mat3 P;
    double vm = 0.0;
    if (J > 0) {
      // Cauchy stress from the elastic part F_e = F G^-1: sigma = P(F_e) F_e^T / det F_e [Pa].
      const Mat3 Fe = F * growth_stretch_[mesh_.cell_region[cells_[k]]].cwiseInverse().asDiagonal();
      material.evaluate(Fe, W, P, nullptr);
      Mat3 sigma = P * Fe.transpose() / Fe.determinant();
      Mat3 dev = sigma - sigma.trace() / 3.0 * Mat3::Identity();
      vm = std::sqrt(1.5 * dev.squaredNorm());
    }
    volume += dV;
    J_sum += dV * J;
    vm_sum += dV * vm;
    J_min = std::min(J_min, J);
  }
  return {J_sum / volume, J_min, vm_sum / volume};
}

std::vector<ElasticTerm::CellMeasures> ElasticTerm::measures_all(const RowMatrixXd& u) const {
  std::vector<CellMeasures> out;
  out.reserve(cells_.size());
  PieceState s;
  std::vector<int> nodes;
  for (int k = 0; k < n_pieces(); ++k) {
    piece_nodes(k, nodes);
    s.X.resize(nodes.size(), 3);
    s.u.resize(nodes.size(), 3);
    for (size_t a = 0; a < nodes.size(); ++a) {
      s.X.row(a) = mesh_.X.row(nodes[a]);
      s.u.row(a) = u.row(nodes[a]);
    }
    out.push_back(measures(k, s));
  }
  return out;
}

const std::map<std::string, ElasticTermFactory>& elastic_formulations() {
  static const std::map<std::string, ElasticTermFactory> registry{
      {"displacement",
       [](const Mesh& mesh, const Partition& partition, int rank,
          std::vector<std::shared_ptr<const Material>> materials,
          int degree) { return std::make_shared<ElasticTerm>(mesh, partition, rank, std::move(materials), degree); }},
      {"mean_dilatation",
       [](const Mesh& mesh, const Partition& partition, int rank,
          std::vector<std::shared_ptr<const Material>> materials, int degree) -> std::shared_ptr<ElasticTerm> {
         return std::make_shared<MeanDilatationTerm>(mesh, partition, rank, std::move(materials), degree);
       }},
  };
  return registry;
}

}  // namespace morphfem
