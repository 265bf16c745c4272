// Membranes (fem/membrane.h): the laws' stress and tangent against finite differences,
// the incompressible plane-stress uniaxial closed form, tension-only fibres, the term's
// gradient and Hessian against finite differences (P1 and P2 faces), exact energy
// under a homogeneous deformation, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/errors.h"
#include "fem/membrane.h"
#include "tests/support/block_mesh.h"
#include "tests/support/finite_differences.h"

using namespace morphfem;

namespace {

std::shared_ptr<const MembraneLaw> law(const std::string& model, double fibre_modulus = 0.0,
                                       std::vector<double> fibres = {1, 0, 0, 0, 1, 0}) {
  ParamSet p("test membrane");
  p.set_string("model", model);
  p.set("mu", 2.0e5);
  if (model == "fabric") {
    p.set("fibre_modulus", fibre_modulus);
    p.set("fibres", fibres);
  }
  return make_membrane_law(p);
}

Mesh block(int order) { return morphfem::testing::block_mesh({0.1, 0.08, 0.02}, 0.04, order); }

// In-plane fibre directions of the (x, y) reference basis at 0 and 60 deg.
std::vector<Eigen::Vector2d> two_fibres() { return {Eigen::Vector2d(1, 0), Eigen::Vector2d(0.5, std::sqrt(0.75))}; }

// Surface deformation gradients: stretches and shears of both signs, rotated out of
// the plane, so that fibres are taut at some and slack at others (never at the kink).
std::vector<Mat32> test_gradients() {
  std::vector<Mat32> out;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < 12; ++k) {
    Mat32 F;
    F << 1 + 0.4 * unit(rng), 0.3 * unit(rng), 0.3 * unit(rng), 1 + 0.4 * unit(rng), 0.3 * unit(rng), 0.3 * unit(rng);
    out.push_back(F);
  }
  return out;
}

}  // namespace

TEST(MembraneLaw, StressAndTangentMatchFiniteDifferences) {
  const auto fibres = two_fibres();
  int checked = 0;
  for (const auto& m : {law("neo_hookean"), law("fabric", 5.0e6)}) {
    for (const Mat32& F : test_gradients()) {
      SCOPED_TRACE(m->name());
      Mat32 P;
      Mat6 A;
      const double psi = membrane_stress(*m, F, fibres, &P, &A);
      ASSERT_TRUE(std::isfinite(psi));
      EXPECT_NEAR(psi, membrane_stress(*m, F, fibres, nullptr, nullptr), 1e-12 * std::abs(psi));
      bool at_kink = false;  // the tangent jumps where a fibre goes slack
      for (const Eigen::Vector2d& a : fibres) at_kink = at_kink || std::abs((F * a).squaredNorm() - 1.0) < 1e-3;
      if (at_kink) continue;
      ++checked;
      const double h = 1e-6;
      Mat6 A_fd;
      double scale = 0.0;
      for (int b = 0; b < 6; ++b) {
        Mat32 Fp = F, Fm = F;
        Fp(b / 2, b % 2) += h;
        Fm(b / 2, b % 2) -= h;
        Mat32 Pp, Pm;
        const double dpsi =
            (membrane_stress(*m, Fp, fibres, &Pp, nullptr) - membrane_stress(*m, Fm, fibres, &Pm, nullptr)) / (2 * h);
        EXPECT_NEAR(P(b / 2, b % 2), dpsi, 1e-6 * (P.cwiseAbs().maxCoeff() + 2.0e5));
        for (int a = 0; a < 6; ++a) A_fd(a, b) = (Pp(a / 2, a % 2) - Pm(a / 2, a % 2)) / (2 * h);
        scale = std::max(scale, A.cwiseAbs().maxCoeff());
      }
      EXPECT_LE((A - A_fd).cwiseAbs().maxCoeff(), 1e-6 * scale);
      EXPECT_LE((A - A.transpose()).cwiseAbs().maxCoeff(), 1e-12 * scale);
    }
  }
  EXPECT_GE(checked, 20);
}

// Incompressible neo-Hookean sheet pulled along x, free across: the transverse stretch
// lambda_2 = lambda^(-1/2) makes S_22 = 0, and the nominal stress is the 3D
// incompressible uniaxial mu (lambda - lambda^-2). A taut fibre along x adds
// E_f/2 (lambda^2 - 1) lambda; in compression (lambda < 1) the fibre adds nothing.
TEST(MembraneLaw, UniaxialStretchMatchesTheIncompressibleClosedForm) {
  const double mu = 2.0e5, Ef = 5.0e6;
  for (double stretch : {0.7, 0.95, 1.05, 1.5, 2.5}) {
    Mat32 F = Mat32::Zero();
    F(0, 0) = stretch;
    F(1, 1) = 1.0 / std::sqrt(stretch);
    Mat32 P;
    membrane_stress(*law("neo_hookean"), F, {}, &P, nullptr);
    const double nominal = mu * (stretch - std::pow(stretch, -2));
    EXPECT_NEAR(P(0, 0), nominal, 1e-12 * mu) << "stretch " << stretch;
    EXPECT_NEAR(P(1, 1), 0.0, 1e-12 * mu) << "stretch " << stretch;
    Mat32 Pf;
    membrane_stress(*law("fabric", Ef, {1, 0, 0}), F, {Eigen::Vector2d(1, 0)}, &Pf, nullptr);
    const double fibre = stretch > 1 ? 0.5 * Ef * (stretch * stretch - 1) * stretch : 0.0;
    EXPECT_NEAR(Pf(0, 0), nominal + fibre, 1e-12 * (mu + Ef)) << "stretch " << stretch;
    EXPECT_NEAR(Pf(1, 1), 0.0, 1e-12 * mu) << "stretch " << stretch;
  }
}

TEST(MembraneTerm, GradientAndHessianMatchFiniteDifferences) {
  for (int order : {1, 2}) {
    const Mesh mesh = block(order);
    const Partition part = morphfem::testing::one_rank(mesh);
    const MembraneTerm term(mesh, part, 0, {"zmax", 5e-4, law("fabric", 5.0e6, {1, 1, 0, 0, 1, 0}), "test"});
    ASSERT_GT(term.n_pieces(), 0);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<int> nodes;
    for (int k = 0; k < std::min(4, term.n_pieces()); ++k) {
      SCOPED_TRACE("order " + std::to_string(order) + " face " + std::to_string(k));
      term.piece_nodes(k, nodes);
      PieceState s;
      s.X.resize(nodes.size(), 3);
      for (size_t a = 0; a < nodes.size(); ++a) s.X.row(a) = mesh.X.row(nodes[a]);
      s.u = s.X * 0.15 * Eigen::Matrix3d::Random();  // a non-uniform stretch of the face
      for (int a = 0; a < s.u.rows(); ++a)
        for (int i = 0; i < 3; ++i) s.u(a, i) += 1e-3 * unit(rng);
      Eigen::VectorXd g, g_fd;
      Eigen::MatrixXd H, H_fd;
      const double E = term.piece(k, s, &g, &H);
      ASSERT_TRUE(std::isfinite(E));
      morphfem::testing::piece_finite_differences(term, k, s, 1e-8, g_fd, H_fd);
      EXPECT_LE((g - g_fd).cwiseAbs().maxCoeff(), 1e-6 * g.cwiseAbs().maxCoeff());
      EXPECT_LE((H - H_fd).cwiseAbs().maxCoeff(), 1e-5 * H.cwiseAbs().maxCoeff());
      EXPECT_LE((H - H.transpose()).cwiseAbs().maxCoeff(), 1e-12 * H.cwiseAbs().maxCoeff());
    }
  }
}

// x = F X on every node: the sheet on the top face z = lz (tangent basis x, y) has
// C = F_s^T F_s with F_s the first two columns of F, and its energy is exactly
// t A psi(C) for P1 and P2 faces.
TEST(MembraneTerm, HomogeneousDeformationEnergyIsExact) {
  Eigen::Matrix3d F;
  F << 1.3, 0.2, 0.05, -0.1, 0.9, 0.0, 0.15, 0.1, 1.1;
  const auto m = law("fabric", 5.0e6, {1, 0, 0, 0, 1, 0});
  const Mat32 Fs = F.leftCols<2>();
  const double psi = membrane_stress(*m, Fs, {Eigen::Vector2d(1, 0), Eigen::Vector2d(0, 1)}, nullptr, nullptr);
  const double t = 5e-4, area = 0.1 * 0.08;
  for (int order : {1, 2}) {
    const Mesh mesh = block(order);
    const Partition part = morphfem::testing::one_rank(mesh);
    const MembraneTerm term(mesh, part, 0, {"zmax", t, m, "test"});
    double E = 0.0;
    std::vector<int> nodes;
    for (int k = 0; k < term.n_pieces(); ++k) {
      term.piece_nodes(k, nodes);
      PieceState s;
      s.X.resize(nodes.size(), 3);
      for (size_t a = 0; a < nodes.size(); ++a) s.X.row(a) = mesh.X.row(nodes[a]);
      s.u = s.X * (F - Eigen::Matrix3d::Identity()).transpose();
      E += term.piece(k, s, nullptr, nullptr);
    }
    EXPECT_NEAR(E, t * area * psi, 1e-12 * t * area * psi) << "order " << order;
  }
}

TEST(MembraneTerm, RejectsBadInput) {
  const Mesh mesh = block(1);
  const Partition part = morphfem::testing::one_rank(mesh);
  EXPECT_THROW(MembraneTerm(mesh, part, 0, {"nowhere", 5e-4, law("neo_hookean"), "test"}), InputError);
  EXPECT_THROW(MembraneTerm(mesh, part, 0, {"zmax", 0.0, law("neo_hookean"), "test"}), InputError);
  // A fibre along the sheet's normal cannot lie in it.
  EXPECT_THROW(MembraneTerm(mesh, part, 0, {"zmax", 5e-4, law("fabric", 1e6, {0, 0, 1}), "test"}), InputError);
  ParamSet p("test membrane");
  p.set_string("model", "rubber");
  EXPECT_THROW(make_membrane_law(p), InputError);
  p.set_string("model", "fabric");
  p.set("mu", 1e5);
  EXPECT_THROW(make_membrane_law(p), InputError);  // no fibre_modulus
}
