// Verification case 11 (../shared/VERIFICATION.md): a flat tube
// flattened by cavity vacuum until its inner faces meet and press on each other.
//
// Geometry (plane strain, half by symmetry x = 0): a slab |z| <= g/2 + t,
// 0 <= x <= W + g/2 + s, one element layer thick in y, with a slot cavity |z| <= g/2,
// x <= W closed by a half-round end of radius g/2 (a lay-flat tube of wall t).
// Surfaces: cavity_top / cavity_bottom (the cavity wall above / below z = 0),
// sym_x, ymin, ymax, edge (x = W + g/2 + s), outer. Conditions: u_x = 0 on sym_x,
// u_y = 0 on ymin and ymax (plane strain), u_z = 0 on edge (the tube's edge held
// in a frame; it also removes the rigid z translation). The cavity pressure ramps
// to -p (vacuum). Self-contact: the scene key contact.self with the pair
// [cavity_top, cavity_bottom].
//
// Checks after every converged step (every output step):
//  * no interpenetration: the smallest point-triangle and edge-edge distance
//    between the two cavity faces, by brute force over every pair of the
//    piecewise-linear surfaces (independent of the term's candidate set), > 0;
//  * no inverted element: min det F > 0.
// At the end:
//  * the faces touch over the flattened region (every cavity_top node with
//    X <= X2 has a self-contact gap below dhat);
//  * the contact pressure balances the vacuum. Statics: in the flattened region the
//    top wall lies flat on the bottom wall and its outer face is traction-free, so
//    the wall's vertical equilibrium (d sigma_zz/dz = -d sigma_xz/dx = 0 where
//    nothing varies along x) gives sigma_zz = 0 through the wall, i.e. contact
//    pressure q = vacuum p on its inner face. Measured by virtual work with the
//    virtual displacement dv = w(X) e_z on the top face, w = 1 for X <= X1, linear
//    to 0 at X2 (X1 = W/4, X2 = W/2, inside the flattened zone):
//      ratio = sum_n w_n f_contact,z(n) / (-sum_n w_n f_vacuum,z(n))  -> 1,
//    f the nodal forces of the self-contact term and of the cavity's vacuum load
//    (the same discrete load the solver sees); the remainder is the wall's internal
//    virtual work int P_zX w' dV over X1..X2, which vanishes where the wall is flat.
//
// Solver: exact barrier Hessians (no per-pair PSD projection: with it Newton
// converged only linearly, ~0.7 per iteration, and most contact steps hit the
// iteration limit), at most 15 Newton iterations before a step cut, growth after
// up to 12. Known limitation: Newton can still stall (residual cycling near
// 1e-4 N after starting from a converged state, a sign of an indefinite total
// Hessian) -- measured on the 0.75 mm level at t = 0.92 and with 2 ranks on the
// quick level at t = 0.76; a level that stops is reported as "run completed" = 0.
#pragma once
#include <mpi.h>

#include <string>
#include <utility>
#include <vector>

#include "fem/solver.h"
#include "mesh/mesh.h"
#include "verify/verify.h"

namespace morphfem {

// Smallest point-triangle and edge-edge distances [m] between two surface regions
// of `mesh` at current positions x (n_nodes x 3), by brute force over every pair
// of their piecewise-linear surfaces (P2 faces split at the mid-nodes), skipping
// only pairs that share a node or a face. With the same name twice: within one
// surface.
struct SurfaceDistances {
  double point_triangle = 0, edge_edge = 0;
  double min() const { return std::min(point_triangle, edge_edge); }
};
SurfaceDistances brute_force_surface_distances(const Mesh& mesh, const RowMatrixXd& x, const std::string& first,
                                               const std::string& second);

struct TubeVacuumResult {
  RunStats stats;
  long dofs = 0;
  int steps_checked = 0;           // converged states checked (every step and t = 0)
  double min_distance = 0;         // smallest brute-force surface distance over all steps [m]
  double min_J = 0;                // smallest det F over all steps
  double vacuum = 0;               // final vacuum p [Pa]
  double pressure_ratio = 0;       // contact / vacuum load in the flattened region (-> 1)
  double contact_fraction = 0;     // of the top face's nodes with X <= X2 in contact (-> 1)
  double max_surface_motion = 0;   // largest cavity-wall node displacement [m]
  double inflation = 0, dhat = 0;  // of the self-contact term [m]
};

// The barrier's Hessian in Newton: exact per pair (the verification case), or
// projected per pair to PSD until Newton takes full steps
// (SolverOptions::hessian_projection "adaptive").
enum class BarrierHessian { exact, adaptive };

// One run at mesh size h [m] and element order.
TubeVacuumResult run_tube_vacuum(double h, int order, MPI_Comm comm, bool progress,
                                 BarrierHessian hessian = BarrierHessian::exact);

// The ladder of mesh levels (P2; quick: the coarsest).
void tube_vacuum_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out);

}  // namespace morphfem
