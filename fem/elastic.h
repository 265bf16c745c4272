// Elastic strain energy  E = sum_cells int_cell W(F) dV  (reference volume),
// F = I + grad_X u. One piece per cell owned by this rank; the material is chosen
// by the cell's volume region.
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

 protected:
  const Mesh& mesh_;
  std::vector<int> cells_;
  std::vector<std::shared_ptr<const Material>> materials_;
  ShapeTable table_;
};

// Element formulations of the elastic energy, registered by name in one table
// (elastic.cpp): "displacement" (pure displacement, this file) and
// "mean_dilatation" (P2/P0 locking-free, fem/mean_dilatation.h). Scenes choose one
// with `solver: {formulation: NAME}`.
using ElasticTermFactory = std::function<std::shared_ptr<ElasticTerm>(
    const Mesh&, const Partition&, int rank, std::vector<std::shared_ptr<const Material>>, int quadrature_degree)>;
const std::map<std::string, ElasticTermFactory>& elastic_formulations();

}  // namespace morphfem
