// Shared pieces for verification cases. Each case is a function that appends
// records; cases are registered by name in one table (verify.cpp). Cases that
// stress the solver (near-incompressibility, limit points, large rotations,
// contact) are "hard" and run with `morphfem verify --hard`.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "app/scene.h"
#include "app/simulation.h"
#include "app/verify.h"

namespace morphfem {

using VerificationCase = std::function<void(const VerifyOptions&, MPI_Comm, std::vector<VerificationRecord>&)>;

// A ParamSet from numbers, with an optional text entry (e.g. "type", "block").
ParamSet verification_params(std::initializer_list<std::pair<const char*, double>> numbers,
                             const char* text_key = nullptr, const char* text = nullptr);
// The block [0, L]^3 at mesh size h [m] and element order, structured (a regular
// tetrahedral grid) or not, its interior nodes moved by `distort` (fraction of h).
ParamSet cube_geometry(double L, double h, int order, bool structured = false, double distort = 0.0);
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
