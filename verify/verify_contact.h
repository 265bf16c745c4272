// Contact verification cases (../shared/VERIFICATION.md cases 9 and 10),
// each on a ladder of mesh and time-step levels, appending VerificationRecord's
// (value, reference, rel_error, cost) like every other case.
#pragma once
#include <mpi.h>

#include <vector>

#include "mesh/mesh.h"
#include "verify/verify.h"

namespace morphfem {

// Case 9: a solid cylinder (radius 20 mm, P2, stiff neo-Hookean) released on a
// 30 deg slope with implicit-Euler dynamics and smoothed Coulomb friction. Large mu:
// rolling, centre acceleration (2/3) g sin(theta); small mu (0.1 < tan(theta)/3):
// slipping, g (sin(theta) - mu cos(theta)). The acceleration is the quadratic
// coefficient of a least-squares fit of the centre-of-mass travel. Ladders: time
// step (implicit Euler's numerical damping) and mesh; the slope as tilted gravity
// and as an inclined ground plane at one level; a thick-walled tube (full run only).
void rolling_case(const VerifyOptions& options, MPI_Comm comm, std::vector<VerificationRecord>& out);

// Case 10: Hertz contact of a sphere (R = 10 mm, E = 1 MPa, nu = 0.49) pressed by
// d = 0.1 mm (d/R = 0.01) on a rigid frictionless plane: a quarter hemisphere
// refined at its pole, quasi-static. Total contact force F against
// (4/3) E* sqrt(R) d^(3/2), 1/E* = (1 - nu^2)/E, and contact radius against
// sqrt(R d), on a ladder of contact-zone element sizes; F against the barrier width
// dhat; and F at d/R = 0.0025 (the model error of a finite sphere shrinks with d/R).
void hertz_case(const VerifyOptions& options, MPI_Comm comm, std::vector<VerificationRecord>& out);

// Building blocks, exposed for tests.
// Node weights w_a = int N_a dV [m^3] (sum = volume): the centre-of-mass
// displacement of the body is sum_a w_a u_a / sum_a w_a for uniform density.
std::vector<double> nodal_volume_weights(const Mesh& mesh);
// Least-squares fit s(t) ~ c0 + c1 t + a t^2 / 2; returns a [m/s^2]. Needs >= 3 distinct times.
double fitted_acceleration(const std::vector<double>& t, const std::vector<double>& s);

}  // namespace morphfem
