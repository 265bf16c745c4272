// Elastic strain energy  E = sum_cells int_cell W(F) dV  (reference volume),
// F = I + grad_X u. One piece per cell owned by this rank; the material is chosen
// by the cell's volume region.
//
// Prescribed growth (active strain), optional per volume region: F = F_e G with
// G = diag(g_x, g_y, g_z)(t) along the reference axes (the voxel study's
// per-axis "external scale factor" of a bladder block), stress-free when F = G.
// The energy per reference volume is  W_G(F) = det G W(F G^-1), so
//   P_G(F)_iJ        = det G P(F_e)_iJ / g_J                       [Pa]
//   A_G(F)_iJkL      = det G A(F_e)_iJkL / (g_J g_L)
// (no sum; G diagonal). Growth changes with time through set_time(t).
#pragma once
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fem/element.h"
#include "fem/energy.h"
#include "fem/material.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

class ElasticTerm : public EnergyTerm {
 public:
  // materials[region id] (nullptr for regions that are not volumes). Cells of
  // part `rank` are this rank's pieces. quadrature_degree: 0 picks the default
  // (1 for P1, where F is constant; 2 for P2, exact for the linearised stiffness).
  ElasticTerm(const Mesh& mesh, const Partition& partition, int rank,
              std::vector<std::shared_ptr<const Material>> materials, int quadrature_degree = 0);

  std::string name() const override { return "elastic"; }
  int n_pieces() const override { return static_cast<int>(cells_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;

  // Per owned cell: volume-averaged J = det F and von Mises Cauchy stress [Pa].
  struct CellMeasures {
    double J_mean, J_min, von_mises;
  };
  CellMeasures measures(int k, const PieceState& s) const;
  // measures() of every owned cell (in piece order) for a full displacement
  // field u (n_nodes x 3).
  std::vector<CellMeasures> measures_all(const RowMatrixXd& u) const;
  int cell_of_piece(int k) const { return cells_[k]; }

  // Growth stretches (g_x, g_y, g_z)(t) > 0 of one volume region (replaces an
  // earlier one). Formulations that cannot grow refuse it (std::invalid_argument).
  using GrowthFunction = std::function<Eigen::Vector3d(double t)>;
  virtual void set_growth(int region, GrowthFunction growth);
  void set_time(double t) override;

 protected:
  const Mesh& mesh_;
  std::vector<int> cells_;
  std::vector<std::shared_ptr<const Material>> materials_;
  ShapeTable table_;
  std::vector<GrowthFunction> growth_;           // per region (empty: no growth)
  std::vector<Eigen::Vector3d> growth_stretch_;  // per region, at the current time
  bool has_growth_ = false;
};

// Element formulations of the elastic energy, registered by name in one table
// (elastic.cpp): "displacement" (pure displacement, this file) and
// "mean_dilatation" (P2/P0 locking-free, fem/mean_dilatation.h). Scenes choose one
// with `solver: {formulation: NAME}`.
using ElasticTermFactory = std::function<std::shared_ptr<ElasticTerm>(
    const Mesh&, const Partition&, int rank, std::vector<std::shared_ptr<const Material>>, int quadrature_degree)>;
const std::map<std::string, ElasticTermFactory>& elastic_formulations();

}  // namespace morphfem
