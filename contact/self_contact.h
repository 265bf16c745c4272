// Self-contact between declared surface regions (or within one), e.g. the inner
// faces of a collapsing cavity: the same log barrier as the ground (barrier.h) on
// point-triangle distances,
//
//   E = sum_(p, T) A_p kappa dhat phi(d(p, T) / dhat)                    [J]
//
// p a surface node (P2: vertices and mid-nodes), T a triangle of the other
// surface (P2 faces split at their mid-nodes into four flat sub-triangles, so the
// contact geometry is the piecewise-linear surface through the nodes), d the
// Euclidean point-triangle distance [m] (closest feature: the face's plane, an
// edge's line or a vertex -- chosen in double precision, then differentiated
// exactly within that feature), A_p the nodal area weight [m^2] (as the ground's).
// A point whose nearest feature is an edge or vertex shared by k triangles counts
// k times there (a stiffer barrier near edges; admissibility is unaffected).
// Pairs whose point is a node of the triangle's own face are skipped. Edge-edge
// distances are NOT included: two edges can cross without a vertex touching a
// face (only likely with coarse meshes of sharp folds).
//
// Candidates (broad phase): pairs with d < dhat + r at the configuration u_c of
// construction (or of refresh()), r = inflation [m], found with a uniform grid of
// triangle bounding boxes. Pieces are fixed between refreshes, so the term keeps
// every surface node within r/2 of u_c (energy +inf beyond, and max_step stops
// there): then no pair outside the candidate set can come closer than dhat.
// A run whose motion exceeds r/2 needs refresh() + Assembler::setup() between
// steps (see the report: the solver needs a re-setup hook for that).
//
// max_step (conservative CCD): along u + alpha du the distance of a pair changes
// by at most alpha L, L = max_i |du_i - du_p| over the triangle's vertices i (the
// distance is 1-Lipschitz in each position, and a common translation leaves it
// unchanged), so alpha <= s d / L keeps d >= (1 - s) d > 0.
#pragma once
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "fem/assembly.h"
#include "fem/energy.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"

namespace morphfem {

struct SelfContactSpec {
  std::string name = "self";
  // Surface regions that can meet; the same name twice: within one surface.
  std::vector<std::pair<std::string, std::string>> pairs;
  double dhat = 0.0;           // barrier width [m]; <= 0: 1e-3 x bounding-box diagonal
  double kappa = 0.0;          // barrier stiffness [Pa]; <= 0: young_modulus
  double young_modulus = 0.0;  // [Pa], for the default kappa
  double inflation = 0.0;      // candidate radius r beyond dhat [m]; <= 0: 20 dhat
  double max_step_fraction = 0.9;
  bool project_hessian = true;  // per-pair PSD projection of the barrier Hessian
};

// Point-triangle barrier kernel: x is 4 x 3 (point, then triangle vertices a, b, c)
// [m]; returns A kappa dhat phi(d/dhat) [J] (+inf if d <= 0, 0 if d >= dhat) and
// optionally its gradient (12) and exact Hessian (12 x 12). Also the distance.
double point_triangle_distance(const Eigen::Matrix<double, 4, 3>& x);
double point_triangle_barrier(const Eigen::Matrix<double, 4, 3>& x, double area, double kappa, double dhat,
                              Eigen::VectorXd* g, Eigen::MatrixXd* H);

class SelfContactTerm : public EnergyTerm {
 public:
  // Candidates from the reference configuration. Throws InputError for unknown
  // surfaces, missing kappa or surfaces that touch at the start (d <= 0).
  SelfContactTerm(const Mesh& mesh, const Partition& partition, int rank, SelfContactSpec spec);

  std::string name() const override { return "self_contact:" + spec_.name; }
  int n_pieces() const override { return static_cast<int>(pairs_.size() + trust_nodes_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  double max_step(Assembler& assembler, Vec u, Vec du) override;

  // Rebuilds the candidate pairs at displacement u (collective) and moves the
  // trust anchor there. The pieces change: call assembler.setup() afterwards and
  // re-create matrices.
  void refresh(Assembler& assembler, Vec u);

  const SelfContactSpec& spec() const { return spec_; }
  int n_pairs() const { return static_cast<int>(pairs_.size()); }
  // Smallest point-triangle distance over the candidate pairs [m] (collective).
  double min_distance(Assembler& assembler, Vec u) const;

 private:
  struct Pair {
    int point;
    std::array<int, 3> triangle;
  };
  void build_candidates(const RowMatrixXd& x);  // x: current positions of every node

  const Mesh& mesh_;
  int rank_begin_ = 0, rank_end_ = 0;
  SelfContactSpec spec_;
  std::vector<double> weight_;  // nodal area weight [m^2] per mesh node
  // Per surface pair: points of side A against triangles of side B (and B vs A).
  struct Side {
    std::vector<int> points;
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> triangle_face;  // parent face of each triangle
  };
  std::vector<std::pair<Side, Side>> sides_;
  std::vector<Pair> pairs_;              // owned pairs (owner of the point)
  std::vector<int> trust_nodes_;         // owned surface nodes
  std::vector<Eigen::Vector3d> anchor_;  // per mesh node: displacement at the last refresh [m]
};

}  // namespace morphfem
