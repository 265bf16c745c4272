// Self-contact through the solver and the scene (VERIFICATION.md case 11):
// the candidate refresh between steps (SelfContactTerm::refresh_pieces and the
// solver's pattern rebuild), the scene key contact.self and its input errors, the
// brute-force distance check of the verification, and the quick tube-vacuum level:
// no interpenetration and no inverted element at any converged step, the faces in
// contact over the flattened region, contact pressure = vacuum within 5 %.
#include <gtest/gtest.h>
#include <petscvec.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "contact/self_contact.h"
#include "core/errors.h"
#include "core/state_file.h"
#include "fem/assembly.h"
#include "mesh/geometry.h"
#include "mesh/partition.h"
#include "sim/scene.h"
#include "verify/verify_self_contact.h"

using namespace morphfem;

namespace {

// A 40 x 40 x 4 mm plate (P1); its faces zmin and zmax may touch.
Mesh plate() {
  ParamSet p("plate");
  p.set_string("type", "block");
  p.set("lx", 0.04);
  p.set("ly", 0.04);
  p.set("lz", 0.004);
  p.set("mesh_size", 0.01);
  return build_geometry(p);
}

// The plate's faces as one contact pair: barrier 0.2 mm, candidate reach 3.2 mm < 4 mm
// (no pairs at the start).
SelfContactSpec across_the_plate() {
  SelfContactSpec spec;
  spec.pairs = {{"zmin", "zmax"}};
  spec.dhat = 2e-4;
  spec.kappa = 1e6;
  spec.inflation = 3e-3;
  return spec;
}

std::string write_scene(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / name).string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace

// refresh_pieces keeps the pieces while surface nodes moved at most r/4 since the
// last refresh and rebuilds them (at the new state) beyond; after the rebuild the
// assembler's pattern holds the new pairs and the moved state is admissible again.
TEST(SelfContactRefresh, RebuildsCandidatesOnceMotionUsesHalfTheTrustRadius) {
  Mesh mesh = plate();
  const Partition part = partition_mesh(mesh, 1);
  const SelfContactSpec spec = across_the_plate();
  auto term = std::make_shared<SelfContactTerm>(mesh, part, 0, spec);
  EXPECT_EQ(term->n_pairs() + term->n_edge_pairs(), 0);
  Assembler assembler(mesh, part, PETSC_COMM_WORLD);
  assembler.add_term(term);
  assembler.setup();
  Vec u = assembler.create_vector();
  // Squeeze: zmax moves down by `down` (a uniform field keeps the plate valid for
  // the contact term alone).
  const auto squeeze = [&](double down) {
    RowMatrixXd field = RowMatrixXd::Zero(mesh.n_nodes(), 3);
    for (int n : mesh.nodes_of_surface("zmax")) field(n, 2) = -down;
    assembler.scatter_all(field, u);
  };
  squeeze(0.2 * spec.inflation);  // below r/4: nothing changes
  EXPECT_FALSE(term->refresh_pieces(assembler, u));
  EXPECT_EQ(term->n_refreshes(), 0);
  squeeze(0.6 * spec.inflation);  // beyond r/2: outside the trust region until refreshed
  EXPECT_TRUE(std::isinf(assembler.energy(u)));
  EXPECT_TRUE(term->refresh_pieces(assembler, u));
  EXPECT_EQ(term->n_refreshes(), 1);
  EXPECT_GT(term->n_pairs(), 0);  // the faces are now 2.2 mm apart: within the reach
  assembler.setup();              // the solver does this when refresh_pieces returns true
  EXPECT_TRUE(std::isfinite(assembler.energy(u)));
  Mat H = assembler.create_matrix();
  EXPECT_NO_THROW(assembler.hessian(u, H));  // every new pair fits the new pattern
  MatDestroy(&H);
  EXPECT_FALSE(term->refresh_pieces(assembler, u));  // no motion since the refresh
  VecDestroy(&u);
}

// A checkpoint keeps where the candidates were searched and the trust region's centre
// after rigid moves: the restored term has the same pairs, in the same order, and the
// same energy (so a resumed run takes the same steps), and its trust region is where
// the saved one had moved, not where the search was.
TEST(SelfContactRefresh, CheckpointKeepsTheSearchAndTheRigidlyMovedTrustRegion) {
  Mesh mesh = plate();
  const Partition part = partition_mesh(mesh, 1);
  const SelfContactSpec spec = across_the_plate();
  auto term = std::make_shared<SelfContactTerm>(mesh, part, 0, spec);
  Assembler assembler(mesh, part, PETSC_COMM_WORLD);
  assembler.add_term(term);
  assembler.setup();
  Vec u = assembler.create_vector();
  // Squeezed 3.85 mm (zmax 0.15 mm above zmin: in the barrier), then turned 30 deg and moved 2 cm.
  RowMatrixXd field = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  for (int n : mesh.nodes_of_surface("zmax")) field(n, 2) = -3.85e-3;
  assembler.scatter_all(field, u);
  ASSERT_TRUE(term->refresh_pieces(assembler, u));
  ASSERT_GT(term->n_pairs(), 0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d(0, 1, 1).normalized()).matrix();
  for (int n = 0; n < mesh.n_nodes(); ++n)
    field.row(n) = (mesh.X.row(n) + field.row(n)) * R.transpose() + Eigen::RowVector3d(0.02, 0, 0) - mesh.X.row(n);
  assembler.scatter_all(field, u);
  ASSERT_FALSE(term->refresh_pieces(assembler, u));
  ASSERT_EQ(term->n_reanchors(), 1);
  const double energy = assembler.energy(u);
  ASSERT_TRUE(std::isfinite(energy) && energy > 0);

  StateRecord state;
  term->save_state(assembler, "self", state);
  auto restored = std::make_shared<SelfContactTerm>(mesh, part, 0, spec);
  Assembler other(mesh, part, PETSC_COMM_WORLD);
  other.add_term(restored);
  restored->load_state(other, "self", state);
  other.setup();
  EXPECT_EQ(restored->n_pairs(), term->n_pairs());
  EXPECT_EQ(restored->n_edge_pairs(), term->n_edge_pairs());
  EXPECT_EQ(restored->n_refreshes(), term->n_refreshes());
  EXPECT_EQ(restored->n_reanchors(), 1);
  std::vector<int> a, b;
  for (int k = 0; k < term->n_pieces(); ++k) {
    term->piece_nodes(k, a);
    restored->piece_nodes(k, b);
    ASSERT_EQ(a, b) << k;
  }
  EXPECT_EQ(other.energy(u), energy);  // finite: the restored trust region moved too
  VecDestroy(&u);
}

// The brute-force check sees faces that touch (so the verification's check can fail).
TEST(SelfContactVerification, BruteForceDistanceSeesTouchingFaces) {
  const Mesh mesh = plate();
  RowMatrixXd x = mesh.X;
  EXPECT_NEAR(brute_force_surface_distances(mesh, x, "zmin", "zmax").min(), 0.004, 1e-12);
  for (int n : mesh.nodes_of_surface("zmax")) x(n, 2) -= 0.004;  // zmax onto zmin
  EXPECT_LT(brute_force_surface_distances(mesh, x, "zmin", "zmax").min(), 1e-12);
}

TEST(SelfContactScene, ReadsTheSelfKeyAndRejectsBadInput) {
  const std::string head =
      "geometry: {type: block, lx: 0.04, ly: 0.04, lz: 0.004, mesh_size: 0.01}\n"
      "materials:\n  body: {model: neo_hookean, mu: 1e5, kappa: 1e6}\n";
  const std::string good = write_scene(
      "morphfem_self_good.yaml",
      head + "contact:\n  self: {pairs: [[zmin, zmax], [xmin, xmin]], dhat: 1e-4, kappa: 3e5, inflation: 1e-3}\n");
  const Scene scene = read_scene(good);
  EXPECT_TRUE(scene.self_contact);
  ASSERT_EQ(scene.self_contact->pairs.size(), 2u);
  EXPECT_EQ(scene.self_contact->pairs[0].first, "zmin");
  EXPECT_EQ(scene.self_contact->pairs[1].second, "xmin");
  EXPECT_DOUBLE_EQ(scene.self_contact->dhat, 1e-4);
  EXPECT_DOUBLE_EQ(scene.self_contact->kappa, 3e5);
  EXPECT_DOUBLE_EQ(scene.self_contact->inflation, 1e-3);
  std::filesystem::remove(good);
  EXPECT_FALSE(read_scene(write_scene("morphfem_self_none.yaml", head)).self_contact);
  std::filesystem::remove(std::filesystem::temp_directory_path() / "morphfem_self_none.yaml");

  // Each bad input names the file, line and column of the offending key.
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"  self: {pairs: [[zmin, zmax]], dhat: 1e-4, stiffness: 3}\n", ":5:"},  // unknown key
      {"  self: {pairs: [[zmin]]}\n", ":5:"},                                  // not a pair
      {"  self: {dhat: 1e-4}\n", ":5:"},                                       // no pairs
      {"  self: {pairs: [[zmin, zmax]], dhat: -1}\n", ":5:"},                  // negative
      {"  self: {pairs: [[zmin, zmax]], kappa: soft}\n", ":5:"},               // not a number
  };
  for (const auto& [line, where] : bad) {
    const std::string path = write_scene("morphfem_self_bad.yaml", head + "contact:\n" + line);
    try {
      read_scene(path);
      ADD_FAILURE() << "accepted: " << line;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path + where), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("contact.self"), std::string::npos) << e.what();
    }
    std::filesystem::remove(path);
  }
}

// The quick level of `morphfem verify --case tube_vacuum`, with the exact barrier
// Hessian (the verification case) and with adaptive projection
// (SolverOptions::hessian_projection), where iterations after a full Newton step use
// the exact Hessian: both pass the same checks, and adaptive projection converges
// in no more than a quarter more Newton iterations than the exact Hessian
// throughout (per-pair projection in every iteration stalls at linear convergence).
TEST(SelfContactVerification, QuickTubeVacuumLevelPassesItsChecks) {
  const auto check = [](const TubeVacuumResult& t, const char* hessian) {
    SCOPED_TRACE(hessian);
    ASSERT_TRUE(t.stats.completed) << t.stats.failure;
    EXPECT_GE(t.steps_checked, t.stats.steps + 1);  // every converged step and the start
    EXPECT_GT(t.min_distance, 0.0);                 // no face passed through another, at any step
    EXPECT_GT(t.min_J, 0.0);                        // no inverted element, at any step
    EXPECT_EQ(t.contact_fraction, 1.0);             // the flattened region is in contact
    EXPECT_NEAR(t.pressure_ratio, 1.0, 0.05);       // contact pressure balances the vacuum
    // The walls moved far beyond the trust radius r/2 of one candidate set: only
    // possible through refreshes during the run.
    EXPECT_GT(t.max_surface_motion, t.inflation);
  };
  const TubeVacuumResult e = run_tube_vacuum(1e-3, 2, PETSC_COMM_WORLD, false, BarrierHessian::exact);
  check(e, "exact Hessian");
  const TubeVacuumResult a = run_tube_vacuum(1e-3, 2, PETSC_COMM_WORLD, false, BarrierHessian::adaptive);
  check(a, "adaptive projection");
  EXPECT_EQ(e.stats.exact_hessian_its, 0);                       // "always": nothing to switch
  EXPECT_GT(a.stats.exact_hessian_its, a.stats.newton_its / 2);  // the exact Hessian did most of the work
  EXPECT_LE(a.stats.newton_its, 1.25 * e.stats.newton_its);
  std::cout << "tube vacuum: adaptive " << a.stats.newton_its << " Newton its / " << a.stats.steps << " steps ("
            << a.stats.exact_hessian_its << " exact, " << a.stats.projection_fallbacks << " fallbacks), exact "
            << e.stats.newton_its << " / " << e.stats.steps << "\n";
}
