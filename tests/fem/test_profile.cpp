// fem/profile.h on a small solve (an elastic P2 beam clamped at x = 0, sagging under
// its weight): the events that ran are counted as often as the solver's counters
// say, and nested events take no longer than the events they run in.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <memory>

#include "core/log_event.h"
#include "core/params.h"
#include "fem/elastic.h"
#include "fem/loads.h"
#include "fem/material.h"
#include "fem/profile.h"
#include "fem/solver.h"
#include "tests/support/block_mesh.h"

using namespace morphfem;

namespace {

struct Profiled {
  RunStats stats;
  ProfileSnapshot spent;
};

Profiled sagging_beam() {
  const Mesh mesh = morphfem::testing::block_mesh({0.1, 0.02, 0.02}, 0.01, 2);
  const Partition part = morphfem::testing::one_rank(mesh);
  ParamSet p("test");
  p.set_string("model", "neo_hookean");
  p.set("mu", 1e5);
  p.set("kappa", 1e6);
  std::vector<std::shared_ptr<const Material>> materials(mesh.regions.size());
  materials.at(mesh.region("body", 3).id) = make_material(p);
  Assembler assembler(mesh, part, PETSC_COMM_SELF);
  assembler.add_term(std::make_shared<ElasticTerm>(mesh, part, 0, materials));
  const VectorField weight = [](const Eigen::Vector3d&, double t) {  // 1000 kg/m^3 under g, ramped [N/m^3]
    return Eigen::Vector3d(0, 0, -9.81e3 * t);
  };
  assembler.add_term(std::make_shared<BodyForceTerm>(mesh, part, 0, mesh.cells_of("body"), weight, 2));
  DirichletCondition clamp{
      "xmin", mesh.nodes_of_surface("xmin"), {true, true, true}, [](const Eigen::Vector3d&, double) {
        return Eigen::Vector3d::Zero();
      }};
  SolverOptions opt;
  opt.t_end = 1.0;
  opt.dt_initial = opt.dt_max = 0.25;
  IncrementalSolver solver(assembler, {clamp}, opt);
  Profiled r;
  const ProfileSnapshot before = profile_snapshot();
  r.stats = solver.run();
  r.spent = profile_snapshot() - before;
  return r;
}

}  // namespace

TEST(Profile, SolveEventsAreCountedAndNest) {
  start_profiling();
  const Profiled r = sagging_beam();
  ASSERT_TRUE(r.stats.completed) << r.stats.failure;
  ASSERT_EQ(r.stats.step_cuts, 0);
  const ProfileSnapshot& s = r.spent;
  const long its = r.stats.newton_its, hessians = its + r.stats.projection_fallbacks;
  ASSERT_GT(its, r.stats.steps);
  // One SNESSolve a step; per Newton iteration (and per re-solve with the projected
  // Hessian) one Hessian of each term, one numeric factorisation (MUMPS LDL^T:
  // MatCholFctrNum) and one solve; one symbolic factorisation for the one pattern.
  EXPECT_EQ(s.count("SNESSolve"), r.stats.steps);
  EXPECT_EQ(s.count("Predictor"), r.stats.steps);
  EXPECT_EQ(s.count("AsmHessian"), hessians);
  EXPECT_EQ(s.count("H:elastic"), hessians);
  EXPECT_EQ(s.count("H:body_force"), hessians);
  EXPECT_EQ(s.count("MatCholFctrNum"), hessians);
  EXPECT_EQ(s.count("MatCholFctrSym"), 1);
  EXPECT_EQ(s.count("MatSolve"), hessians);
  EXPECT_GE(s.count("LSEnergy"), 2 * its);                     // the start and at least one trial point
  EXPECT_EQ(s.count("MaxStep:elastic"), its + r.stats.steps);  // the line searches and the predictors
  EXPECT_GE(s.count("G:elastic"), its + r.stats.steps);        // a residual per iterate
  EXPECT_EQ(s.count("RefreshPieces"), r.stats.steps);
  // Inclusive times: a nested event takes at most the time of the one it runs in
  // (1 us of slack for the clock's resolution).
  const auto nests = [&](const std::string& inner, const std::string& outer) {
    EXPECT_GE(s.seconds(inner), 0.0) << inner;
    EXPECT_LE(s.seconds(inner), s.seconds(outer) + 1e-6) << inner << " in " << outer;
  };
  nests("H:elastic", "AsmHessian");
  nests("AsmHessian", "SNESJacobianEval");
  nests("MatCholFctrNum", "PCSetUp");
  nests("PCSetUp", "SNESSolve");  // PETSc 3.18 logs it outside KSPSetUp and KSPSolve
  nests("MatSolve", "KSPSolve");
  nests("LSEnergy", "SNESLineSearch");
  EXPECT_LE(s.seconds("H:elastic") + s.seconds("H:body_force") + s.seconds("MatSetValuesCOO"),
            s.seconds("AsmHessian") + 1e-6);
  EXPECT_LE(s.seconds("SNESJacobianEval") + s.seconds("PCSetUp") + s.seconds("KSPSolve") + s.seconds("SNESLineSearch"),
            s.seconds("SNESSolve") + 1e-6);
  EXPECT_LE(s.seconds("SNESSolve") + s.seconds("Predictor") + s.seconds("RefreshPieces"), s.wall_s + 1e-6);
  EXPECT_GT(s.seconds("SNESSolve"), 0.0);
  const std::string table = profile_table(s, "Newton it", its);
  EXPECT_NE(table.find("H:elastic"), std::string::npos) << table;
  EXPECT_NE(table.find("MatCholFctrNum"), std::string::npos) << table;
  if (std::getenv("MORPHFEM_PRINT_PROFILE")) std::fputs(table.c_str(), stdout);
}

TEST(Profile, RunningEventCountsItsTimeSoFar) {
  start_profiling();
  const ProfileSnapshot before = profile_snapshot();
  ProfileSnapshot during;
  {
    LogEventScope scope("ProfileTestRunning");
    volatile double x = 0;
    for (int i = 0; i < 1000000; ++i) x = x + 1e-9 * i;
    during = profile_snapshot();
  }
  const ProfileSnapshot after = profile_snapshot();
  const ProfileSnapshot part = during - before, whole = after - before;
  EXPECT_EQ(part.count("ProfileTestRunning"), 1);
  EXPECT_GT(part.seconds("ProfileTestRunning"), 0.0);
  EXPECT_LE(part.seconds("ProfileTestRunning"), whole.seconds("ProfileTestRunning"));
  EXPECT_LE(whole.seconds("ProfileTestRunning"), whole.wall_s);
}
