// Shared pieces for verification cases. Each case is a function that appends
// records; cases are registered by name in one table (verify.cpp). Cases that
// stress the solver (near-incompressibility, limit points, large rotations,
// contact) are "hard" and run with `morphfem verify --hard`.
#pragma once
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "sim/scene.h"
#include "sim/simulation.h"
#include "verify/verify.h"

namespace morphfem {

using VerificationCase = std::function<void(const VerifyOptions&, MPI_Comm, std::vector<VerificationRecord>&)>;

// A ParamSet from numbers, with an optional text entry (e.g. "type", "block").
ParamSet verification_params(std::initializer_list<std::pair<const char*, double>> numbers,
                             const char* text_key = nullptr, const char* text = nullptr);
// The block [0, L]^3 at mesh size h [m] and element order, structured (a regular
// tetrahedral grid) or not, its interior nodes moved by `distort` (fraction of h).
ParamSet cube_geometry(double L, double h, int order, bool structured = false, double distort = 0.0);
// The observed order of convergence along a ladder of levels:
// rate = log(e_prev / e) / log(h_prev / h) [-], h the mesh size or time step; next()
// returns it for the new level and remembers the level; 0 at the first level and where
// an error is 0.
class ConvergenceRate {
 public:
  double next(double error, double h) {
    const double rate = error_ > 0 && error > 0 && h_ > 0 ? std::log(error_ / error) / std::log(h_ / h) : 0.0;
    error_ = error;
    h_ = h;
    return rate;
  }

 private:
  double error_ = 0, h_ = 0;
};
// A scene with one volume region "body" of the given material.
Scene verification_scene(const std::string& name, ParamSet geometry, ParamSet material);
// A record filled with the run's cost (dofs, wall time, Newton iterations, steps, cuts).
VerificationRecord verification_record(const std::string& case_name, const std::string& quantity, int level, int order,
                                       double h, const SimulationResult& r);
// The same from a run's size and statistics (cases that run their own solver loop).
VerificationRecord verification_record(const std::string& case_name, const std::string& quantity, int level, int order,
                                       double h, long dofs, const RunStats& stats);
// Throws SolveError naming the case if the run did not complete.
void require_completed(const SimulationResult& r, const std::string& what);

}  // namespace morphfem
