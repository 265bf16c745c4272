// Hard verification cases for gas-filled and volume-controlled cavities
// (../shared/VERIFICATION.md cases 3 and 5): limit points of inflated
// spheres and balloons traced with volume control, graceful failure of pressure
// control past a limit point, and the valve model's fill times. Built with the
// lower-level API (octant meshes, Assembler, IncrementalSolver) because scenes
// have no gas cavities yet. Each appends VerificationRecords; P/mu etc. are
// compared with the exact formulas at the stretch computed from the cavity volume.
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

#include "fem/solver.h"
#include "verify/verify.h"

namespace morphfem {

// (a) Thick incompressible neo-Hookean sphere A/B = 0.5 inflated under volume
// control through its pressure maximum (0.816424 mu at la = 1.82815) to la = 3.
void gas_thick_sphere_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out);
// (b) Thin neo-Hookean balloon (H/R = 1/20): maximum 1.239463 mu H/R at 7^(1/6), passed.
void gas_balloon_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out);
// (c) Thin Mooney-Rivlin balloon C2 = 0.1 C1: maximum and minimum (snap-through path).
void gas_mooney_balloon_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out);
// (d) The neo-Hookean balloon under pressure control beyond its maximum: the solver
// must stop with a diagnostic and keep the last converged state (throws
// SolveError if it does not fail, or fails without a usable state).
void gas_pressure_control_failure_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out);
// (e) Valve fill times of a rigid-walled gas cavity against tau ln(p_s/(p_s - p*)),
// tau = V/(C R T), for two conductances and two supply pressures, and the
// deflation time to a vacuum source.
void gas_valve_case(const VerifyOptions& opt, MPI_Comm comm, std::vector<VerificationRecord>& out);

// Result of the pressure-controlled balloon run behind case (d) (exposed for the test).
struct PressureControlFailure {
  RunStats stats;
  double last_pressure = 0;       // gauge pressure of the last converged state [Pa]
  double max_pressure_exact = 0;  // thin-balloon maximum 1.239463 mu H/R [Pa]
  double last_time = 0;           // time of the last converged state [s]
  bool state_finite = false;      // the kept solution has only finite entries
  double last_volume_ratio = 0;   // V/V_ref of the kept state (from the solution vector)
  long dofs = 0;
};
PressureControlFailure run_pressure_controlled_balloon(bool quick, MPI_Comm comm);

}  // namespace morphfem
