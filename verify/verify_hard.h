// Hard verification cases (`morphfem verify --hard`): near-incompressibility,
// extreme compression and large rotations. Each appends VerificationRecord's with
// their cost (Newton iterations, step cuts, wall time); references from
// ../shared/VERIFICATION.md or closed forms stated in verify_hard.cpp.
#pragma once
#include <mpi.h>

#include <vector>

#include "verify/verify.h"

namespace morphfem {

// Cook's membrane (VERIFICATION.md case 6, nu = 0.4999): tip vertical displacement
// vs 6.9083 mm on a mesh ladder for P1 displacement, P2 displacement and P2
// mean_dilatation.
void cook_case(const VerifyOptions& options, MPI_Comm comm, std::vector<VerificationRecord>& out);

// A block at nu = 0.4999 (P2 mean_dilatation): homogeneous uniaxial tension against
// its closed form, and a bonded block under a shear traction on a ladder (P2
// displacement beside it to show the locking).
void incompressible_block_case(const VerifyOptions& options, MPI_Comm comm, std::vector<VerificationRecord>& out);

// 50 % compression of a block: frictionless platens (homogeneous, closed-form force)
// and bonded platens (barrelling) on a ladder; records the platen force and min J.
void compression_case(const VerifyOptions& options, MPI_Comm comm, std::vector<VerificationRecord>& out);

// A cantilever closed into a full circle by a conservative end moment
// M = 2 pi E I / L (VERIFICATION.md case 7): the tip returns to the root.
void end_moment_case(const VerifyOptions& options, MPI_Comm comm, std::vector<VerificationRecord>& out);

}  // namespace morphfem
