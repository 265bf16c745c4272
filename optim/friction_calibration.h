// Friction calibration with the simulator: the drag test (sim/drag_scene.h) fitted
// to measured pull-test curves.
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

#include "optim/friction_fit.h"
#include "sim/drag_scene.h"

namespace morphfem {

// Friction fit with the simulator: mu_static, mu_kinetic and the pull-spring
// stiffness k of the drag test (sim/drag_scene.h) so that the simulated force
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

// `morphfem calibrate drag`: one simulated pull test (the friction fit's model) written
// as a test-machine export, with Gaussian force noise of standard deviation noise_N.
struct SimulatedPullOptions {
  DragParameters model;
  std::string out_file;
  std::string surface = "simulated", foot = "unknown";
  double noise_N = 0;  // [N]
  unsigned seed = 1;
};
int write_simulated_pull(const SimulatedPullOptions& options, MPI_Comm comm);

// `morphfem calibrate friction`: one group (surface, foot state) of pull tests -> the
// fitted mu_static, mu_kinetic and stiffness with their confidence intervals; with
// out_dir, a calibration file, the overlay CSV and its plot.
struct FrictionCalibrationOptions {
  double weight_N = 0;              // the robot's weight [N]
  std::vector<std::string> inputs;  // export files or folders
  std::string surface, foot;        // keep only this group (empty: any)
  std::string out_dir;              // empty: print only
  FrictionFitOptions fit;           // travel, time step, start, evaluations
  std::string command_arguments;    // recorded in the calibration file
};
int calibrate_friction(const FrictionCalibrationOptions& options, MPI_Comm comm);

}  // namespace morphfem
