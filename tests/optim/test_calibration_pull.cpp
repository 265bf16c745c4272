// Pull-test analysis: synthetic pull tests built to match the published friction
// figures (ROBOT.md: wood 0.56 / 0.70, acrylic 0.38 / 0.51) with load-cell noise
// and stick-slip come back from the analysis within 2 %; statistics; the command.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "optim/pull_test.h"

namespace morphfem {
namespace {

TEST(CalibrationPull, PublishedFiguresComeBackWithinTwoPercent) {
  struct Case {
    const char* surface;
    double mu;
  };
  // Peak 10 % above the linear end, kinetic 15 % below it, load-cell noise 0.3 % of the
  // static force plus a 2 % stick-slip sawtooth; 10 repeats with their own noise. The
  // study reports one figure per surface and foot state (over 10 repeats): the median and
  // the mean of the repeats must be within 2 %; a single repeat's knee is resolved to
  // about +/- 4 % at this noise (see the break-point note in optim/pull_test.h).
  for (const Case& c : {Case{"wood uninflated", 0.56}, Case{"wood inflated", 0.70}, Case{"acrylic uninflated", 0.38},
                        Case{"acrylic inflated", 0.51}}) {
    SCOPED_TRACE(c.surface);
    std::vector<double> lin, peak, kin;
    for (unsigned seed = 1; seed <= 10; ++seed) {
      SyntheticPull p;
      p.weight_N = 1.2;
      p.mu_linear = c.mu;
      p.mu_peak = 1.10 * c.mu;
      p.mu_kinetic = 0.85 * c.mu;
      p.noise_N = 0.003 * p.weight_N * c.mu;
      p.seed = seed;
      const PullAnalysis a = analyse_pull(synthesize_pull(p), p.weight_N);
      EXPECT_NEAR(a.mu_linear, c.mu, 0.05 * c.mu) << "seed " << seed;
      EXPECT_NEAR(a.mu_peak, p.mu_peak, 0.02 * p.mu_peak) << "seed " << seed;
      EXPECT_NEAR(a.mu_kinetic, p.mu_kinetic, 0.02 * p.mu_kinetic) << "seed " << seed;
      EXPECT_NEAR(a.slope_N_per_m, p.stiffness_N_per_m, 0.05 * p.stiffness_N_per_m) << "seed " << seed;
      EXPECT_TRUE(a.knee_found);
      lin.push_back(a.mu_linear);
      peak.push_back(a.mu_peak);
      kin.push_back(a.mu_kinetic);
    }
    EXPECT_NEAR(summarize(lin).median, c.mu, 0.02 * c.mu);
    EXPECT_NEAR(summarize(lin).mean, c.mu, 0.02 * c.mu);
    EXPECT_NEAR(summarize(peak).median, 1.10 * c.mu, 0.02 * c.mu);
    EXPECT_NEAR(summarize(kin).mean, 0.85 * c.mu, 0.02 * c.mu);
  }
}

TEST(CalibrationPull, SharpSlipWithoutKneeEndsTheLinearRegimeAtThePeak) {
  SyntheticPull p;
  p.mu_linear = p.mu_peak = 0.5;
  p.mu_kinetic = 0.4;
  const PullAnalysis a = analyse_pull(synthesize_pull(p), p.weight_N);
  EXPECT_NEAR(a.mu_linear, 0.5, 0.01);
  EXPECT_NEAR(a.mu_peak, 0.5, 0.01);
  EXPECT_NEAR(a.mu_kinetic, 0.4, 0.008);
}

TEST(CalibrationPull, NoiseEstimateAndStatistics) {
  SyntheticPull p;
  p.noise_N = 0.004;
  p.stick_slip = 0.0;
  const PullAnalysis a = analyse_pull(synthesize_pull(p), p.weight_N);
  EXPECT_NEAR(a.noise_N, 0.004, 0.0006);

  const Summary s = summarize({4.0, 1.0, 3.0, 2.0, 5.0});
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.q1, 2.0);
  EXPECT_DOUBLE_EQ(s.q3, 4.0);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_NEAR(s.sd, std::sqrt(2.5), 1e-15);
  const Summary e = summarize({1.0, 2.0, 3.0, 4.0});
  EXPECT_DOUBLE_EQ(e.median, 2.5);
  EXPECT_DOUBLE_EQ(e.q1, 1.75);
}

TEST(CalibrationPull, ExportsRoundTripAndCommandGroupsBySurfaceAndFoot) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / ("morphfem_pull_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::ostringstream ignored;
  SyntheticPullSet acrylic;
  acrylic.out_dir = (dir / "a").string();
  acrylic.surface = "acrylic";
  acrylic.foot = "uninflated";
  acrylic.model.mu_linear = 0.38;
  acrylic.model.mu_peak = 0.40;
  acrylic.model.mu_kinetic = 0.33;
  acrylic.repeats = 3;
  acrylic.decimal_comma = true;
  ASSERT_EQ(write_synthetic_pulls(acrylic, ignored), 0);
  SyntheticPullSet wood;  // wood, inflated
  wood.out_dir = (dir / "b").string();
  wood.model.mu_linear = 0.70;
  wood.model.mu_peak = 0.74;
  wood.model.mu_kinetic = 0.60;
  wood.repeats = 2;
  ASSERT_EQ(write_synthetic_pulls(wood, ignored), 0);
  // The export reads back with surface and foot state from the header block.
  const auto blocks = read_test_machine_export((dir / "a" / "acrylic_uninflated_01.csv").string());
  const PullCurve c = pull_curve_from_export(blocks.at(0));
  EXPECT_EQ(c.surface, "acrylic");
  EXPECT_EQ(c.foot_state, "uninflated");
  EXPECT_NEAR(c.displacement.back(), 0.130, 1e-4);

  std::ostringstream out;
  PullTestsOptions both;
  both.weight_N = 1;
  both.inputs = {(dir / "a").string(), (dir / "b").string()};
  both.out_dir = (dir / "out").string();
  ASSERT_EQ(analyse_pull_tests(both, out), 0);
  EXPECT_NE(out.str().find("acrylic/uninflated"), std::string::npos) << out.str();
  EXPECT_NE(out.str().find("wood/inflated"), std::string::npos) << out.str();
  std::ifstream summary(dir / "out" / "pull_summary.json");
  std::stringstream text;
  text << summary.rdbuf();
  EXPECT_NE(text.str().find("\"tests\": 3"), std::string::npos) << text.str();
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "pull_tests.csv"));

  // Unknown options are refused by the command line (tests/app/test_cli.cpp).
  PullTestsOptions no_weight;
  no_weight.inputs = {(dir / "a").string()};
  EXPECT_THROW(analyse_pull_tests(no_weight, ignored), InputError);
  PullTestsOptions negative = no_weight;
  negative.weight_N = -1;
  EXPECT_THROW(analyse_pull_tests(negative, ignored), InputError);
  PullTestsOptions no_input;
  no_input.weight_N = 1;
  EXPECT_THROW(analyse_pull_tests(no_input, ignored), InputError);
  SyntheticPullSet nowhere;  // no --out
  nowhere.repeats = 2;
  EXPECT_THROW(write_synthetic_pulls(nowhere, ignored), InputError);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace morphfem
