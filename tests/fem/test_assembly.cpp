// The assembler's two Hessian layouts give the same matrix: one n x n block per
// piece, and (sparse_pieces()) one 3 x 3 block per coupled node pair shared by the
// pieces that couple it, where only nonzero pieces are added.
#include <gtest/gtest.h>

#include <random>

#include "fem/assembly.h"
#include "tests/support/block_mesh.h"
#include "tests/support/petsc_environment.h"

using namespace morphfem;
using morphfem::testing::block_mesh;
using morphfem::testing::one_rank;

namespace {

// The other fem tests need no PETSc; these do (MPI, Vec, Mat): tests/support/petsc_environment.h.

// Pairs of nodes joined by one-sided springs (compression only, like a barrier:
// E = k/2 (L0 - l)^2 for l < L0, else 0) and triples joined by a three-node term
// E = k/2 |x_a + x_b - 2 x_c|^2 + k u_a,x u_b,y; many pieces share node pairs and most springs are
// slack (zero), as most contact candidates are beyond dhat. One piece is outside
// its domain (+inf) when `poisoned`.
class Springs : public EnergyTerm {
 public:
  Springs(std::vector<std::vector<int>> pieces, bool sparse, bool poisoned)
      : pieces_(std::move(pieces)), sparse_(sparse), poisoned_(poisoned) {}
  std::string name() const override { return "springs"; }
  int n_pieces() const override { return static_cast<int>(pieces_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override { nodes = pieces_[k]; }
  bool sparse_pieces() const override { return sparse_; }
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override {
    const int n = static_cast<int>(pieces_[k].size());
    if (g) g->setZero(3 * n);
    if (H) H->setZero(3 * n, 3 * n);
    const Eigen::MatrixXd x = s.X + s.u;
    if (poisoned_ && k == 3) return std::numeric_limits<double>::infinity();
    if (n == 2) {  // one-sided spring, rest length L0 [m], k [N/m]
      const double k_s = 2e3, L0 = 0.011;
      const Eigen::Vector3d d = (x.row(1) - x.row(0)).transpose();
      const double l = d.norm();
      if (l >= L0) return 0.0;
      const Eigen::Vector3d e = d / l;
      if (g) {
        g->segment<3>(0) = k_s * (L0 - l) * e;
        g->segment<3>(3) = -k_s * (L0 - l) * e;
      }
      if (H) {
        const Eigen::Matrix3d K =
            k_s * (e * e.transpose() - (L0 - l) / l * (Eigen::Matrix3d::Identity() - e * e.transpose()));
        H->block<3, 3>(0, 0) = K;
        H->block<3, 3>(3, 3) = K;
        H->block<3, 3>(0, 3) = -K;
        H->block<3, 3>(3, 0) = -K;
      }
      return 0.5 * k_s * (L0 - l) * (L0 - l);
    }
    const double k_t = 1e3;  // three nodes, always active
    const Eigen::Vector3d r = (x.row(0) + x.row(1) - 2 * x.row(2)).transpose();
    const double c[3] = {1, 1, -2};
    for (int a = 0; a < 3; ++a) {
      if (g) g->segment<3>(3 * a) = k_t * c[a] * r;
      if (H)
        for (int b = 0; b < 3; ++b) H->block<3, 3>(3 * a, 3 * b) = k_t * c[a] * c[b] * Eigen::Matrix3d::Identity();
    }
    // Plus k_t u_a,x u_b,y: its node blocks H_ab = H_ba^T are not symmetric, so a
    // transposed block would show.
    if (g) {
      (*g)(0) += k_t * s.u(1, 1);
      (*g)(4) += k_t * s.u(0, 0);
    }
    if (H) (*H)(0, 4) = (*H)(4, 0) = k_t;
    return 0.5 * k_t * r.squaredNorm() + k_t * s.u(0, 0) * s.u(1, 1);
  }

 private:
  std::vector<std::vector<int>> pieces_;
  bool sparse_, poisoned_;
};

Eigen::MatrixXd dense(Mat m) {
  PetscInt n;
  MatGetSize(m, &n, nullptr);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, n);
  for (PetscInt i = 0; i < n; ++i) {
    PetscInt ncols;
    const PetscInt* cols;
    const PetscScalar* vals;
    MatGetRow(m, i, &ncols, &cols, &vals);
    for (PetscInt c = 0; c < ncols; ++c) out(i, cols[c]) = vals[c];
    MatRestoreRow(m, i, &ncols, &cols, &vals);
  }
  return out;
}

struct Assembled {
  Eigen::MatrixXd H;
  double energy;
  std::vector<double> g;
};

Assembled assemble(const Mesh& mesh, const std::vector<std::vector<int>>& pieces, bool sparse, bool poisoned,
                   const RowMatrixXd& u_field) {
  const Partition part = one_rank(mesh);
  Assembler a(mesh, part, PETSC_COMM_SELF);
  a.add_term(std::make_shared<Springs>(pieces, sparse, poisoned));
  a.set_constrained({0, 1, 2, 7});  // node 0 and one component of node 2
  a.setup();
  Vec u = a.create_vector(), g = a.create_vector();
  a.scatter_all(u_field, u);
  Mat H = a.create_matrix();
  a.hessian(u, H);
  Assembled out{dense(H), a.gradient(u, g), {}};
  const PetscScalar* gv;
  VecGetArrayRead(g, &gv);
  out.g.assign(gv, gv + a.n_dofs());
  VecRestoreArrayRead(g, &gv);
  MatDestroy(&H);
  VecDestroy(&u);
  VecDestroy(&g);
  return out;
}

}  // namespace

TEST(Assembler, SharedNodeBlocksGiveTheSameHessianAsOneBlockPerPiece) {
  const Mesh mesh = block_mesh({0.04, 0.02, 0.02}, 0.01, 1);
  const int n = mesh.n_nodes();
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> node(0, n - 1);
  std::vector<std::vector<int>> pieces;
  for (int k = 0; k < 400; ++k) {  // springs, many repeated node pairs (also reversed)
    int a = node(rng), b = node(rng);
    if (a == b) continue;
    pieces.push_back({a, b});
    if (k % 5 == 0) pieces.push_back({b, a});
  }
  for (int k = 0; k < 60; ++k) {
    int a = node(rng), b = node(rng), c = node(rng);
    if (a == b || b == c || a == c) continue;
    pieces.push_back({a, b, c});
  }
  RowMatrixXd u = RowMatrixXd::Zero(n, 3);
  std::uniform_real_distribution<double> small(-1e-3, 1e-3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) u(i, j) = small(rng);

  const Assembled per_piece = assemble(mesh, pieces, false, false, u);
  const Assembled shared = assemble(mesh, pieces, true, false, u);
  // Some springs are compressed, most are slack: the sparse path skips those.
  int active = 0;
  for (const auto& p : pieces)
    if (p.size() == 2 && (mesh.X.row(p[1]) + u.row(p[1]) - mesh.X.row(p[0]) - u.row(p[0])).norm() < 0.011) ++active;
  ASSERT_GT(active, 20);
  ASSERT_LT(active, static_cast<int>(pieces.size()) / 2);
  const double scale = per_piece.H.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0.0);
  EXPECT_LE((per_piece.H - shared.H).cwiseAbs().maxCoeff(), 1e-13 * scale);
  EXPECT_DOUBLE_EQ(per_piece.energy, shared.energy);
  for (std::size_t d = 0; d < per_piece.g.size(); ++d) EXPECT_NEAR(per_piece.g[d], shared.g[d], 1e-13 * scale);
  // Constrained dofs: identity rows and columns in both.
  for (int d : {0, 1, 2, 7}) {
    EXPECT_EQ(shared.H(d, d), 1.0);
    EXPECT_EQ(shared.H.row(d).cwiseAbs().sum(), 1.0);
    EXPECT_EQ(shared.H.col(d).cwiseAbs().sum(), 1.0);
  }
  // A piece outside its domain contributes nothing to either Hessian.
  const Assembled poisoned_piece = assemble(mesh, pieces, false, true, u);
  const Assembled poisoned_shared = assemble(mesh, pieces, true, true, u);
  EXPECT_LE((poisoned_piece.H - poisoned_shared.H).cwiseAbs().maxCoeff(), 1e-13 * scale);
}
