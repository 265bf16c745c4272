// The fast subset of the verification suite, with the acceptance tolerances.
#include <gtest/gtest.h>
#include <petscsys.h>

#include "verify/verify.h"

using namespace morphfem;

namespace {
std::vector<VerificationRecord> run(const std::string& name) {
  VerifyOptions options;
  options.cases = {name};
  options.quick = true;
  options.progress = false;
  return run_verification(options, PETSC_COMM_WORLD);
}
}  // namespace

TEST(Verification, PatchTestIsExactForP1AndP2) {
  auto records = run("patch");
  ASSERT_EQ(records.size(), 4u);
  for (const auto& r : records) EXPECT_LE(r.rel_error, 1e-8) << "order " << r.order << " level " << r.level;
}

TEST(Verification, ManufacturedSolutionConvergesAtTheoreticalRates) {
  auto records = run("mms");
  int checked = 0;
  for (const auto& r : records) {
    if (r.level == 0) continue;
    const double expected = (r.quantity == "L2_error" ? 1 : 0) + r.order;  // L2: k+1, H1: k
    EXPECT_NEAR(r.rate, expected, 0.25) << r.quantity << " P" << r.order;
    ++checked;
  }
  EXPECT_EQ(checked, 4);
}

TEST(Verification, ThickCylinderPressureWithinOnePercentOnCoarseP2) {
  auto records = run("cylinder");
  ASSERT_FALSE(records.empty());
  for (const auto& r : records)
    if (r.quantity.rfind("P/mu", 0) == 0) {
      EXPECT_LT(r.rel_error, 0.01);
    }
}

TEST(Verification, CantileverTipDeflectionWithinTwoPercentOnCoarseP2) {
  auto records = run("cantilever");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_LT(records[0].rel_error, 0.02);
}

TEST(Verification, UnknownCaseIsAnInputError) {
  VerifyOptions options;
  options.cases = {"nonsense"};
  EXPECT_THROW(run_verification(options, PETSC_COMM_WORLD), std::exception);
}

TEST(Verification, BlockOnSlopeSlidesThePredictedDistanceWithFirstOrderTimeError) {
  auto records = run("slope");
  ASSERT_EQ(records.size(), 2u);
  for (const auto& r : records) EXPECT_LT(r.rel_error, 0.02) << r.quantity;
  EXPECT_NEAR(records[1].rate, 1.0, 0.3);  // implicit Euler
}

TEST(Verification, FrictionSwitchingOnAScheduleMovesOnlyWhenLow) {
  auto records = run("friction_switch");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_LT(records[0].rel_error, 0.05) << records[0].quantity;  // predicted slide within 5 %
  EXPECT_LT(records[1].rel_error, 1e-3) << records[1].quantity;  // creep below 0.1 % of the block size
}
