// Self-contact between declared surface regions (or within one), e.g. the inner
// faces of a collapsing cavity: the same log barrier as the ground (barrier.h) on
// point-triangle and edge-edge distances (as in IPC),
//
//   E = sum_(p, T) A_p kappa dhat phi(d(p, T) / dhat)                    [J]
//     + sum_(e, e') A_ee' m(|e x e'|^2) kappa dhat phi(d(e, e') / dhat)
//
// p a surface node (P2: vertices and mid-nodes), T a triangle of the other
// surface (P2 faces split at their mid-nodes into four flat sub-triangles, so the
// contact geometry is the piecewise-linear surface through the nodes), d the
// Euclidean point-triangle distance [m] (closest feature: the face's plane, an
// edge's line or a vertex -- chosen in double precision, then differentiated
// exactly within that feature), A_p the nodal area weight [m^2] (as the ground's).
// A point whose nearest feature is an edge or vertex shared by k triangles counts
// k times there (a stiffer barrier near edges; admissibility is unaffected).
// Pairs whose point is a node of the triangle's own face are skipped.
//
// Edge-edge: e, e' edges of the two surfaces' (sub-)triangles, d their segment
// distance (closest features: line-line, point-line or point-point), weight
// A_ee' = (A_e + A_e')/2 with A_e a third of the reference area of the
// (sub-)triangles next to the edge [m^2]. Without them two edges could cross
// without a vertex reaching a face (coarse meshes of sharp folds). Near-parallel
// edges: the line-line distance is ill-conditioned there, so the energy is
// multiplied by IPC's mollifier
//   m(x) = (2 - x/eps) x/eps for x < eps, 1 otherwise,  x = |e x e'|^2 [m^4],
//   eps = 1e-3 |E|^2 |E'|^2 (reference edges):
// m is C1 and vanishes for parallel edges, whose contact the point-triangle pairs
// carry (an end point then meets a face or an edge). Edge pairs sharing a node or
// a parent face are skipped. A state with any candidate distance d <= 0 has +inf
// energy (edge-edge too, whatever m).
//
// Candidates (broad phase): pairs with d < dhat + r at the configuration u_c of
// construction (or of the last refresh), r = inflation [m], found with uniform
// grids of triangle and edge bounding boxes. Pieces are fixed between refreshes,
// so the term keeps every surface node within its trust radius rho (r/2, or more
// for far nodes, below) of u_c (energy +inf beyond, and max_step stops there): then
// no pair outside the candidate set can come closer than dhat (every distance is
// 1-Lipschitz in each node's position, so two nodes moving r/2 each change it by at
// most r). During a run refresh_pieces() (called by the solver before each step with
// the converged state) rebuilds the candidates once some surface node has used half
// of its trust radius (motion > rho/2, r/4 near contact); the
// solver then re-creates the assembly pattern. Motion is measured after removing the
// best-fit rigid motion of each group of surface pairs that share nodes (e.g. one
// chamber's walls): distances do not change under it, and the trust region moves with
// it, so a body that rolls, falls or curls without deforming its contact surfaces
// keeps its candidates.
//
// Far nodes move further. A node whose nearest feature outside the candidates was
// d_i away at the search (non-candidate pairs have d >= dhat + r) may move
//   rho_i = min((d_i - dhat) / 2, R)      (>= r/2; R = max_trust_radius >= r/2)
// before a rebuild: a non-candidate pair, its nodes each moving at most rho <=
// (d - dhat)/2, still keeps d >= dhat. The search measures pairs out to dhat + 2R for
// this (only the ones within dhat + r become candidates). An inflated chamber, its
// walls centimetres apart, then inflates and deflates with few rebuilds and no
// trust-region step cuts, while a collapsing one keeps the tight r/2. With R = r/2
// (the default) every node has r/2.
//
// max_step (conservative CCD): along u + alpha du the distance of a pair changes
// by at most alpha L, L = max_i |du_i - du_p| over the triangle's vertices i (the
// distance is 1-Lipschitz in each position, and a common translation leaves it
// unchanged); for an edge pair L = max_(i in e) |du_i - du_o| + max_(j in e')
// |du_j - du_o|, o the first node of e. So alpha <= s d / L keeps d >= (1 - s) d > 0.
#pragma once
#include <array>
#include <limits>
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
  double dhat = 0.0;              // barrier width [m]; <= 0: 1e-3 x bounding-box diagonal
  double kappa = 0.0;             // barrier stiffness [Pa]; <= 0: young_modulus
  double young_modulus = 0.0;     // [Pa], for the default kappa
  double inflation = 0.0;         // candidate radius r beyond dhat [m]; <= 0: 20 dhat
  double max_trust_radius = 0.0;  // largest trust radius R of a far node [m]; <= r/2: r/2
  double max_step_fraction = 0.9;
  bool project_hessian = true;  // per-pair PSD projection of the barrier Hessian
  bool edge_edge = true;        // include the edge-edge pairs
  // The barrier acts from this time on [s] (-inf: always). Before it the term has no
  // pieces: no candidates, no CCD bound, no trust region (a scene whose surfaces
  // meet only late, e.g. a core closing under vacuum after inflating, does not pay
  // for them earlier). It switches on at the first step starting at t >= start.
  double start = -std::numeric_limits<double>::infinity();
};

// Point-triangle barrier kernel: x is 4 x 3 (point, then triangle vertices a, b, c)
// [m]; returns A kappa dhat phi(d/dhat) [J] (+inf if d <= 0, 0 if d >= dhat) and
// optionally its gradient (12) and exact Hessian (12 x 12). Also the distance.
double point_triangle_distance(const Eigen::Matrix<double, 4, 3>& x);
double point_triangle_barrier(const Eigen::Matrix<double, 4, 3>& x, double area, double kappa, double dhat,
                              Eigen::VectorXd* g, Eigen::MatrixXd* H);

// Edge-edge kernels: x is 4 x 3 (edge a0-a1, then edge b0-b1) [m]. The segment
// distance [m]; the mollifier threshold eps = 1e-3 |a1 - a0|^2 |b1 - b0|^2 [m^4]
// of a (reference) configuration; the barrier A m(|e_a x e_b|^2) kappa dhat
// phi(d/dhat) [J] (+inf if d <= 0, 0 if d >= dhat) with optional gradient (12)
// and exact Hessian (12 x 12).
double edge_edge_distance(const Eigen::Matrix<double, 4, 3>& x);
double edge_edge_mollifier_threshold(const Eigen::Matrix<double, 4, 3>& x_reference);
double edge_edge_barrier(const Eigen::Matrix<double, 4, 3>& x, double area, double kappa, double dhat, double eps,
                         Eigen::VectorXd* g, Eigen::MatrixXd* H);

// Per-node self-contact data (every mesh node; n_nodes rows): force on the node
// from the barrier, -dE/dx [N], and the smallest candidate distance of a pair the
// node belongs to [m] (+inf if none).
struct SelfContactNodal {
  RowMatrixXd force;
  std::vector<double> gap;
};

class SelfContactTerm : public EnergyTerm {
 public:
  // Candidates from the reference configuration. Throws InputError for unknown
  // surfaces, missing kappa or surfaces that touch at the start (d <= 0).
  SelfContactTerm(const Mesh& mesh, const Partition& partition, int rank, SelfContactSpec spec);

  std::string name() const override { return "self_contact:" + spec_.name; }
  int n_pieces() const override {
    return active_ ? static_cast<int>(pairs_.size() + edge_pairs_.size() + trust_nodes_.size()) : 0;
  }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  // Candidates beyond dhat (most of them) and trust-region pieces are zero.
  bool sparse_pieces() const override { return true; }
  // With project_hessian, the exact pair Hessians while set (the solver's adaptive projection).
  void set_exact_hessian(bool exact) override { exact_hessian_ = exact; }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;
  double max_step(Assembler& assembler, Vec u, Vec du) override;
  // Rebuilds the candidates at u0 once a surface node moved more than half its trust
  // radius (r/4 near contact) since the last refresh, rigid motion removed (returns true: the solver re-creates the
  // pattern); otherwise moves the trust region with the rigid motion. Collective.
  bool refresh_pieces(Assembler& assembler, Vec u0) override;
  // Whether contact has started, the displacement of the last candidate search (the
  // candidates are rebuilt from it on load) and the trust-region centre.
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) override;
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) override;
  // The same decision from the whole displacement field (identical on every rank);
  // also switches the term on at its start time.
  bool refresh_pieces(const RowMatrixXd& u);
  void set_time(double t) override { time_ = t; }
  bool active() const { return active_; }

  // Rebuilds the candidate pairs at displacement u (collective) and moves the
  // trust anchor there. The pieces change: call assembler.setup() afterwards and
  // re-create matrices.
  void refresh(Assembler& assembler, Vec u);
  // The same from the whole displacement field (n_nodes x 3, identical on every rank).
  void refresh(const RowMatrixXd& u);

  const SelfContactSpec& spec() const { return spec_; }
  int n_pairs() const { return static_cast<int>(pairs_.size()); }
  int n_edge_pairs() const { return static_cast<int>(edge_pairs_.size()); }
  int n_refreshes() const { return n_refreshes_; }
  // How often refresh_pieces moved the trust region rigidly instead of rebuilding.
  int n_reanchors() const { return n_reanchors_; }
  // Trust radius rho of a mesh node since the last search [m] (0 off the surfaces).
  double trust_radius(int node) const { return trust_radius_[node]; }
  // Smallest point-triangle / edge-edge distance over the candidate pairs [m] (collective).
  double min_distance(Assembler& assembler, Vec u) const;
  // Nodal forces and gaps of this rank's pairs at the whole displacement field u
  // (no communication; with one rank, or summed over ranks, the full field).
  SelfContactNodal nodal_contact(const RowMatrixXd& u) const;
  // The same for every node, reduced over the ranks (collective).
  SelfContactNodal nodal_contact(Assembler& assembler, Vec u) const;

 private:
  struct Pair {
    int point;
    std::array<int, 3> triangle;
  };
  struct EdgePair {
    std::array<int, 4> nodes;  // a0 a1 b0 b1
    double weight;             // A_ee' [m^2]
    double eps;                // mollifier threshold [m^4]
  };
  void build_candidates(const RowMatrixXd& x);  // x: current positions of every node
  Eigen::Matrix<double, 4, 3> positions(const std::array<int, 4>& nodes, const RowMatrixXd& u) const;

  const Mesh& mesh_;
  int rank_begin_ = 0, rank_end_ = 0;
  SelfContactSpec spec_;
  bool exact_hessian_ = false;
  std::vector<double> weight_;  // nodal area weight [m^2] per mesh node
  // Per surface pair: points of side A against triangles of side B (and B vs A),
  // edges of A against edges of B.
  struct Side {
    std::vector<int> points;
    std::vector<std::array<int, 3>> triangles;
    std::vector<int> triangle_face;            // parent face of each triangle
    std::vector<std::array<int, 2>> edges;     // unique edges of the triangles (sorted node ids)
    std::vector<std::vector<int>> edge_faces;  // parent faces of each edge
    std::vector<double> edge_weight;           // A_e [m^2]
  };
  struct CandidateSearch;  // the state of one build_candidates (self_contact.cpp)
  void point_triangle_candidates(const Side& points, const Side& tris, const RowMatrixXd& x, CandidateSearch& search);
  void edge_edge_candidates(const Side& side_a, const Side& side_b, const RowMatrixXd& x, CandidateSearch& search);
  std::vector<std::pair<Side, Side>> sides_;
  std::vector<Pair> pairs_;                     // owned pairs (owner of the point)
  std::vector<EdgePair> edge_pairs_;            // owned edge pairs (owner of the smallest node)
  std::vector<int> trust_nodes_;                // owned surface nodes
  std::vector<int> surface_nodes_;              // every surface node
  std::vector<std::vector<int>> rigid_groups_;  // surface nodes of pairs sharing nodes, merged
  std::vector<Eigen::Vector3d> anchor_;         // per mesh node: trust-region centre (displacement) [m]
  // Per mesh node: displacement at the last candidate search [m]; the anchor is this
  // moved rigidly. Checkpoints keep both, so a resumed run searches from the same
  // positions and finds the same candidates in the same order.
  std::vector<Eigen::Vector3d> searched_;
  std::vector<double> trust_radius_;  // per mesh node: rho [m], the same on every rank
  int n_refreshes_ = 0;
  int n_reanchors_ = 0;
  bool active_ = true;
  double time_ = 0.0;  // the solver's current time [s] (set_time)
};

}  // namespace morphfem
