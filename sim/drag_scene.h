// The simulated pull (drag) test: a block standing in for the robot's foot and body
// rests on the ground under gravity with the robot's weight, and a test machine
// pulls its front face (xmax) through a linear spring at constant crosshead speed
// (fem/pull_spring.h). Friction: the ground's smoothed Coulomb law with mu_static,
// mu_kinetic (contact/friction.h) on the bottom face; implicit-Euler dynamics
// (slip after the static peak is a dynamic event).
//
// Which parameter sets the pre-slip slope: the spring stiffness k. Before slip the
// measured force rises as F = k_eff a with 1/k_eff = 1/k + 1/k_body + creep, where the
// block is stiff (k_body = G A / h >> k) and the creep of the regularised friction is
// bounded by eps_v (kept << the pull speed, a numerical parameter, not fitted). k
// therefore stands for the machine, cable and robot compliance together: the
// physical compliance of the real set-up, which the fit identifies.
//
// Time step: dt = 0.05 s puts omega dt ~ 2.5 for a 0.1 kg robot on a 250 N/m spring,
// where implicit Euler's numerical damping removes the stick-slip limit cycle that
// the static-to-kinetic drop excites (with dt = 0.02 s the force saws between ~0.96
// mu_s W and ~0.83 mu_k W, and the fit's objective turns rugged). The model then
// predicts the static peak and the mean sliding force (= mu_k W), which is what the
// friction fit compares with the data's block means (optim/friction_fit.h). The
// smoothed law's peak lies a little below mu_s W (partial slip of the regularised
// contact: ~0.93 mu_s W for mu_k / mu_s = 0.86), so mu_static is a model parameter
// and the fitted value, not the raw peak / W, is the one scenes should use.
//
// Simulated speed: the curve F(x) is rate independent here (quasi-static stick, then
// steady sliding at any speed >> 2 eps_v), so the simulation pulls at
// model_speed_factor x the machine's speed: each step then adds k v dt / 4 to the
// force, which resolves the static peak to ~1 % of it (at full speed the peak is
// quantised in steps of k v dt ~ 5 % of it, and mu_static is poorly determined).
// Reported times are crosshead travel / machine speed.
#pragma once
#include <mpi.h>

#include <vector>

#include "sim/scene.h"
#include "sim/simulation.h"

namespace morphfem {

struct DragParameters {
  double mu_static = 0.56, mu_kinetic = 0.48;  // [-]
  double stiffness = 250.0;                    // pull spring k [N/m]
  double weight_N = 1.0;                       // robot weight W [N]
  double speed = 0.1 / 60.0;                   // crosshead speed [m/s] (100 mm/min)
  double model_speed_factor = 0.25;            // the simulated crosshead moves at this x speed (see the note)
  double travel = 0.008;                       // simulated crosshead travel [m]
  double settle = 0.1;                         // rest before the pull starts [s]
  double dt = 0.05;                            // time step [s] (see the note above)
  double eps_v = 2e-5;                         // friction smoothing velocity [m/s] (<< speed)
  double block_length = 0.04, block_width = 0.04, block_height = 0.01;  // [m]
  double shear_modulus = 1e6;                                           // [Pa] (stiff: k_body >> k)
};

struct DragCurve {
  std::vector<double> time;          // since the pull started [s]
  std::vector<double> displacement;  // crosshead travel [m]
  std::vector<double> force;         // spring (load-cell) force [N]
  bool completed = false;
  double wall_s = 0;
  double mass_kg = 0;       // of the pulled body
  SimulationResult result;  // the run (stats, dofs, output folder)
};

// Runs a scene with a test-machine pull (its first loads.pulls) and records the
// load-cell force against crosshead travel, one sample per step from the pull's start.
// Sample times are time_scale x (t - start) (a model pulling at a fraction of the
// machine's speed reports machine time). InputError if the scene has no pull.
DragCurve run_pull_scene(const Scene& scene, MPI_Comm comm, RunOptions options = {}, double time_scale = 1.0);

// The drag test as a Scene (built in code; checks the parameters -> InputError).
Scene drag_scene(const DragParameters& p);
// Runs it and returns the load-cell force against crosshead travel, one sample per
// step after the pull starts (plus the start).
DragCurve run_drag_test(const DragParameters& p, MPI_Comm comm);

}  // namespace morphfem
