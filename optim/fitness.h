// Fitness functions for the search, registered by name:
//   speed [BL/s] = fitness(genome, environment, fidelity, communicator)
// A simulation-backed fitness (the finite-element robot, registered from app/ as
// "robot") and the cheap analytic "synthetic" fitness used by tests share this
// signature. Register with one line:
//   register_fitness("robot", robot_speed, "finite-element robot scene");
// The fidelity is a free-form level string passed through from --fidelity
// (e.g. "0", "coarse"); each fitness documents the levels it accepts.
#pragma once
#include <mpi.h>

#include <functional>
#include <string>
#include <vector>

#include "actuation/schedule.h"

namespace morphfem {

// Where the robot moves.
struct Environment {
  std::string name = "flat";  // "flat" or "hill" (labels only)
  double slope_deg = 0;       // ground inclination; uphill is the heading's reference direction
};

// Speed in body lengths per second of `genome` in `env`, computed at `fidelity` by
// all ranks of `comm` together (the result must be the same on every rank of comm).
// A failed evaluation returns NaN or -inf, or throws SolveError (all counted as -inf:
// never kept); any other exception stops the search.
using FitnessFunction =
    std::function<double(const Genome& genome, const Environment& env, const std::string& fidelity, MPI_Comm comm)>;

// Adds (or replaces) a fitness under `name`.
void register_fitness(const std::string& name, FitnessFunction fn, const std::string& description = "");
// Throws InputError naming the known fitnesses if `name` is not registered.
const FitnessFunction& find_fitness(const std::string& name);
bool has_fitness(const std::string& name);
// "name: description" lines, sorted by name.
std::vector<std::string> fitness_descriptions();

// The built-in analytic fitness ("synthetic"), with a known optimum.
//   target(env): flat (slope < 7.5 deg): theta* = 0, p* = 12000 Pa, rows = rolling_genome();
//                otherwise:              theta* = 90, p* = 0,       rows = inching_genome().
//   d_theta = (theta - theta*) / 90, d_p = (p - p*) / 12000,
//   d_rows  = (1/20) sum over the 20 row genes of (circular distance on 0..8 / 4)^2,
//   penalty = 0.3 d_theta^2 + 0.3 d_p^2 + 0.4 d_rows                    (in 0..1)
//   speed   = v_max - (v_max + v_back) * penalty + bias(level)
// with v_max = 0.2 BL/s flat / 0.03 BL/s hill, v_back = 0.02 flat / 0.06 hill (the
// worst genome slides back). Fidelity level L (integer >= 0, default "0"; "exact"
// = no bias) adds a genome-dependent discretisation-like error
//   bias(L) = 0.02 * 2^-L * sin(0.37 theta + 0.0011 p + sum_r (1.3 f_r + 0.7 phi_r) (r + 1)),
// so low levels are cheap and biased, high levels converge to the exact value.
// Maximum at the target genome: speed = v_max exactly when L = "exact".
double synthetic_speed(const Genome& g, const Environment& env, const std::string& fidelity);
Genome synthetic_optimum(const Environment& env);

}  // namespace morphfem
