// Quick runs of the hard cases and the mean-dilatation formulation inside
// full solves: patch test, agreement with the displacement element at moderate
// kappa, Cook's membrane (locking vs locking-free) and the end-moment cantilever.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <cmath>

#include "core/errors.h"
#include "fem/material.h"
#include "sim/simulation.h"
#include "verify/verify_cases.h"
#include "verify/verify_hard.h"

using namespace morphfem;

namespace {

VerifyOptions quick() {
  VerifyOptions o;
  o.quick = true;
  o.progress = false;
  return o;
}

// Cube of side 10 mm, P2, bonded at zmin, dead shear traction 0.2 mu on zmax.
Scene sheared_cube(const std::string& formulation, double nu, int order = 2, int divisions = 2) {
  const double L = 0.01, mu = 1e5;
  Scene s = verification_scene(
      "cube",
      verification_params(
          {{"lx", L}, {"ly", L}, {"lz", L}, {"mesh_size", L / divisions}, {"order", double(order)}, {"structured", 1}},
          "type", "block"),
      verification_params({{"mu", mu}, {"nu", nu}}, "model", "neo_hookean"));
  s.formulation = formulation;
  BoundarySpec clamp;
  clamp.surface = "zmin";
  clamp.components = {true, true, true};
  s.boundary.push_back(clamp);
  TractionSpec shear;
  shear.surface = "zmax";
  shear.traction = Eigen::Vector3d(0.2 * mu, 0, 0);
  shear.scale = TimeFunction::ramp(1.0, 1.0);
  s.tractions.push_back(shear);
  s.solver.dt_initial = 0.5;
  return s;
}

double mean_top_ux(const SimulationResult& r) {
  double ux = 0;
  const auto top = r.mesh.nodes_of_surface("zmax");
  for (int n : top) ux += r.u(n, 0) / top.size();
  return ux;
}

}  // namespace

TEST(MeanDilatationSolve, PatchTestIsExactOnADistortedP2Mesh) {
  const double L = 0.01;
  Mat3 F;
  F << 1.10, 0.05, 0.00, 0.02, 0.95, 0.03, 0.00, 0.04, 1.05;
  const Mat3 G = F - Mat3::Identity();
  Scene s = verification_scene(
      "patch_md",
      verification_params({{"lx", L}, {"ly", L}, {"lz", L}, {"mesh_size", L / 3}, {"order", 2}, {"distort", 0.25}},
                          "type", "block"),
      verification_params({{"mu", 1e5}, {"nu", 0.4999}}, "model", "neo_hookean"));
  s.formulation = "mean_dilatation";
  for (const char* face : {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}) {
    BoundarySpec b;
    b.surface = face;
    b.components = {true, true, true};
    b.field = [G](const Eigen::Vector3d& X, double t) { return Eigen::Vector3d(t * G * X); };
    s.boundary.push_back(b);
  }
  s.solver.dt_initial = 0.5;
  auto r = run_scene(s, PETSC_COMM_WORLD, {false, false});
  ASSERT_TRUE(r.stats.completed) << r.stats.failure;
  double err = 0;
  for (int n = 0; n < r.mesh.n_nodes(); ++n)
    err = std::max(err, (r.u.row(n).transpose() - G * r.mesh.X.row(n).transpose()).norm());
  EXPECT_LT(err, 1e-8 * G.norm() * L);
  EXPECT_NEAR(r.min_J, F.determinant(), 1e-8);
}

TEST(MeanDilatationSolve, ConvergesToTheDisplacementSolutionAtModerateKappaAndUnlocksNearIncompressible) {
  // nu = 0.3: both elements converge to the same solution; their difference
  // shrinks under refinement (mean dilatation is O(h) in H1, so it is the larger
  // error on coarse meshes).
  auto top_ux = [](const std::string& formulation, double nu, int divisions) {
    auto r = run_scene(sheared_cube(formulation, nu, 2, divisions), PETSC_COMM_WORLD, {false, false});
    EXPECT_TRUE(r.stats.completed) << r.stats.failure;
    return mean_top_ux(r);
  };
  const double d2 = top_ux("mean_dilatation", 0.3, 2), u2 = top_ux("displacement", 0.3, 2);
  const double d4 = top_ux("mean_dilatation", 0.3, 4), u4 = top_ux("displacement", 0.3, 4);
  EXPECT_LT(std::abs(d4 - u4), 0.5 * std::abs(d2 - u2));
  EXPECT_LT(std::abs(d4 - u4), 0.04 * std::abs(u4));
  // nu = 0.4999: the displacement element is stiffer (locks).
  EXPECT_GT(top_ux("mean_dilatation", 0.4999, 2), 1.1 * top_ux("displacement", 0.4999, 2));
}

TEST(MeanDilatationSolve, LinearTetrahedraAreRejectedWithAClearMessage) {
  try {
    run_scene(sheared_cube("mean_dilatation", 0.45, 1), PETSC_COMM_WORLD, {false, false});
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("P2"), std::string::npos) << e.what();
  }
}

TEST(HardVerification, CookCoarseMeanDilatationWithinFivePercentAndP1Locks) {
  std::vector<VerificationRecord> out;
  cook_case(quick(), PETSC_COMM_WORLD, out);
  ASSERT_EQ(out.size(), 2u);
  for (const auto& r : out) {
    if (r.order == 1) {
      EXPECT_LT(r.value, 0.8 * r.reference) << "P1 displacement should lock";  // measured 3.36 of 6.91 mm
    } else {
      EXPECT_LT(r.rel_error, 0.05) << r.quantity;  // measured 3.3 % on 4 divisions
    }
  }
}

TEST(HardVerification, EndMomentSmallAngleMatchesTheCircle) {
  std::vector<VerificationRecord> out;
  end_moment_case(quick(), PETSC_COMM_WORLD, out);
  int checked = 0;
  for (const auto& r : out) {
    if (r.quantity.rfind("section angle", 0) == 0) {
      EXPECT_LT(r.rel_error, 0.01) << r.quantity;
    } else if (r.quantity.rfind("tip displacement error", 0) == 0) {
      EXPECT_LT(r.value, 1e-3) << r.quantity;
    } else {
      EXPECT_GT(r.value, 0.0) << r.quantity;  // min J
    }
    ++checked;
  }
  EXPECT_EQ(checked, 3);
}
