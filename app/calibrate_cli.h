// `morphfem calibrate ...`: test-machine exports -> friction coefficients, material
// parameters and calibration files that scenes load (optim/).
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

#include "app/drag_scene.h"
#include "optim/friction_fit.h"

namespace morphfem {

// Friction fit with the simulator: mu_static, mu_kinetic and the pull-spring
// stiffness k of the drag test (app/drag_scene.h) so that the simulated force
// reproduces every given curve up to `travel` (residuals and statistics in
// optim/friction_fit.h). Starts from the pull-test analysis of the curves (median
// peak and kinetic coefficients, median pre-slip slope) unless `start` is given.
struct FrictionFitOptions {
  DragParameters model;           // block, speed, dt, eps_v; weight_N is set from the argument
  double travel = 0.008;          // fitted crosshead travel [m]
  double split_after_peak = 0.0;  // pointwise residuals up to each curve's peak + this [m] ...
  double block = 2e-3;            // ... then block means of this width [m] (optim/friction_fit.h)
  int max_evaluations = 60;       // TAO function evaluations
  std::vector<double> start;      // optional {mu_static, mu_kinetic, k}
};
struct FrictionFitResult {
  LeastSquaresFit fit;  // names mu_static, mu_kinetic, stiffness_N_per_m
  DragCurve best;       // simulated curve at the optimum
  std::vector<double> start;
};
FrictionFitResult fit_friction(const std::vector<PullCurve>& curves, double weight_N, const FrictionFitOptions& options,
                               MPI_Comm comm);

// The morphing fit, `morphfem calibrate morphing ...` (app/calibrate_morphing.cpp).
int calibrate_morphing_main(const std::vector<std::string>& args, MPI_Comm comm);

// Shared by the calibrate commands: a numeric option in [lo, hi] (InputError naming
// the command and option otherwise), and the time stamp of calibration files.
double number_option(const std::string& command, const std::string& option, const std::string& text, double lo,
                     double hi);
std::string now_utc();

// Runs the calibrate command; returns the process exit status. Throws InputError on bad arguments.
int calibrate_main(const std::vector<std::string>& args, MPI_Comm comm);

}  // namespace morphfem
