// Friction from pull tests: the robot is dragged across a surface by a materials
// testing machine (Instron 3343, 100 mm/min over 130 mm; ROBOT.md) and the load
// cell records the pulling force F(x) against the crosshead displacement x.
//
// Coefficients, with W [N] the robot's weight:
//   mu_linear  = F(x_L) / W   the study's static coefficient: force at the upper end
//                x_L of the initial linear (pre-slip) regime;
//   mu_peak    = F_max / W    ASTM D1894 static coefficient: peak force before slip;
//   mu_kinetic = mean F / W   ASTM D1894 kinetic coefficient: mean force over the
//                sliding part (the last 75 % of the travel after the peak).
//
// Finding the pre-slip linear regime (robust to noise):
//   1. noise sigma [N] from second differences of F (insensitive to the trend):
//      sigma = 1.4826 MAD(F[i+1] - 2F[i] + F[i-1]) / sqrt(6);
//   2. smoothed force (5-point running median, then 5-point running mean); the static
//      peak p = the maximum of the smoothed force before it first falls by more than
//      max(4 sigma, 3 % of the running maximum) (the slip); no drop: its global maximum;
//   3. the window is from the first point above 5 % of the peak force (skips the
//      slack "toe" before the machine takes up the load) to p;
//   4. on the window, a hinge model by least squares: a line that turns C1-smoothly
//      into a saturating knee at the break point b,
//        F = a + k x - A l^2 g((x - b)/l),  g(u) = max(0, u) - 1 + exp(-max(0, u)),  A >= 0,
//      (a, k, A) by linear least squares for each candidate (b, l), b over the data
//      points and l over a geometric grid from 1 % to 3 window lengths (large l: the
//      parabola A (x - b)^2 / 2, the leading order of any smooth knee); the pair with
//      the least sum of squares over every point of the window wins. b is thus where
//      the curve starts to bend away from the line, not where it has bent by some
//      threshold (a threshold biases x_L to the right by the knee's curvature).
//      If the bend is not significant (the hinge lowers the sum of squares by less
//      than 25 s^2, s = max(sigma, 0.1 % of the peak force): many (b, l) are tried, so
//      noise alone lowers it by ~10 sigma^2; the floor is what a load cell resolves, and
//      keeps a noise-free simulated curve's gradual creep from passing for a knee)
//      the whole window is linear: b = x_p.
//   x_L = b and F(x_L) = a + k b, the fitted line there (denoised), so mu_linear
//   does not carry the noise of one sample.
// Resolution: a smooth knee of curvature c = A/2 [N/m^2] locates b only to about
// sqrt(sigma / c): at 0.3 % load noise a single test's mu_linear scatters by a few
// per cent (bias < 1 %), so the per-surface figure is the median of the repeats.
// A two-segment fit with a free second line was the alternative; it puts the break
// inside the knee (biased by the knee's length); a pure parabola knee biased mu_linear
// by -1 % on exponential knees, the (b, l) family by < 1 %.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "core/test_machine_export.h"

namespace morphfem {

struct PullCurve {
  std::string file, label;
  std::string surface;               // e.g. wood, acrylic, gravel
  std::string foot_state;            // e.g. inflated, uninflated
  std::vector<double> time;          // [s] (may be empty)
  std::vector<double> displacement;  // crosshead [m]
  std::vector<double> force;         // load cell [N]
};

// Surface and foot state: header keys containing "surface" and "foot" (or "state"),
// else from the file name SURFACE_FOOTSTATE_NN.csv (first token = surface; a token
// inflated / uninflated / deflated = foot state), else "unknown". Needs a force and a
// displacement column; InputError otherwise. Displacement starts at 0 (first value
// subtracted).
PullCurve pull_curve_from_export(const SpecimenExport& specimen);

struct PullAnalysis {
  double noise_N = 0;                   // sigma of the load signal [N]
  double linear_start_m = 0;            // where the window starts (after the toe) [m]
  double linear_end_m = 0;              // x_L [m]
  double linear_end_force_N = 0;        // F(x_L) from the fitted line [N]
  double slope_N_per_m = 0;             // pre-slip slope k [N/m]
  bool knee_found = false;              // a significant bend before the peak
  double peak_m = 0, peak_force_N = 0;  // static peak [m], [N]
  double kinetic_force_N = 0;           // mean sliding force [N]
  double kinetic_from_m = 0;            // start of the sliding window [m]
  double mu_linear = 0, mu_peak = 0, mu_kinetic = 0;
};

PullAnalysis analyse_pull(const PullCurve& curve, double weight_N);

// Statistics of one coefficient over repeats (quartiles: linear interpolation
// between order statistics, "type 7"; sd with n - 1).
struct Summary {
  int n = 0;
  double median = 0, q1 = 0, q3 = 0, mean = 0, sd = 0, min = 0, max = 0;
};
Summary summarize(std::vector<double> values);

// Synthetic pull test with known coefficients (a generator for tests and for users to
// see the export format): toe of `slack_m`, linear rise with slope `stiffness` up to
// mu_linear W, an exponential knee F = F_L + k l (1 - exp(-(x - x_L)/l)),
// l = 1.5 (F_peak - F_L)/k, up to mu_peak W, slip: exponential drop (length
// `drop_m`) to mu_kinetic W with a zero-mean stick-slip sawtooth of relative
// amplitude `stick_slip`, plus Gaussian load-cell noise of sd `noise_N`.
struct SyntheticPull {
  double mu_linear = 0.56, mu_peak = 0.60, mu_kinetic = 0.48;
  double weight_N = 1.0;
  double stiffness_N_per_m = 250.0;   // pre-slip slope
  double speed_m_per_s = 0.1 / 60.0;  // 100 mm/min
  double travel_m = 0.130;
  double rate_Hz = 50.0;
  double slack_m = 0.3e-3;
  double drop_m = 0.4e-3;
  double stick_slip = 0.02;
  double stick_slip_period_m = 2.0e-3;
  double noise_N = 0.005;
  unsigned seed = 1;
};
PullCurve synthesize_pull(const SyntheticPull& p);

// An Instron-like export of a curve (';' separated, decimal commas if asked,
// header block with surface / foot state / weight / machine / speed, names row, units row).
std::string pull_export_text(const PullCurve& curve, double weight_N, bool decimal_comma,
                             const std::string& machine = "Instron 3343 (synthetic)", double speed_mm_per_min = 100.0);

// `morphfem calibrate pull-tests`: the coefficients of every test, a table, and per
// group (surface, foot state) their statistics; with out_dir, pull_tests.csv (one row
// per test), pull_summary.json and (if /usr/bin/python3 and `plot_script` exist)
// pull_boxplot.png. InputError if the weight is not > 0 or no input is given.
struct PullTestsOptions {
  double weight_N = 0;              // the robot's weight [N]
  std::vector<std::string> inputs;  // export files or folders
  std::string out_dir;              // empty: print only
  std::string plot_script;          // scripts/plot_calibration.py ("" : no plot)
  std::string command_arguments;    // recorded in pull_summary.json
};
int analyse_pull_tests(const PullTestsOptions& options, std::ostream& out);

// `morphfem calibrate synth-pull`: `repeats` synthetic exports (seeds seed+1, ...) of
// one surface and foot state in out_dir, their paths printed to `out`.
struct SyntheticPullSet {
  SyntheticPull model;
  std::string out_dir, surface = "wood", foot = "inflated";
  int repeats = 10;
  bool decimal_comma = false;
};
int write_synthetic_pulls(const SyntheticPullSet& set, std::ostream& out);

}  // namespace morphfem
