// The verification suite (../shared/VERIFICATION.md): each case runs on a ladder
// of mesh levels for P1 and P2 and reports one record per (case, quantity, level,
// order) with its error against the exact or published reference and its cost.
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

namespace morphfem {

struct VerificationRecord {
  std::string case_name, quantity;
  int level = 0, order = 1;
  double h = 0;  // mesh size [m]
  double value = 0, reference = 0, rel_error = 0;
  double rate = 0;  // observed convergence rate against the previous level (0: none)
  long dofs = 0;
  double wall_s = 0;
  int newton_its = 0, steps = 0, step_cuts = 0;
  std::string json() const;
  // Sets value, reference and rel_error = |value - reference| / |reference| (reference != 0).
  void compare(double measured, double exact);
};

// |value - reference| / |reference| [-].
double relative_error(double value, double reference);

struct VerifyOptions {
  std::vector<std::string> cases;  // empty: every core case (or every hard case with `hard`)
  bool hard = false;               // the hard-case suite instead of the core cases
  bool quick = false;              // coarse levels only (the ctest subset)
  bool progress = true;
};

// Registered case names: the core suite, or the hard-case suite.
std::vector<std::string> verification_case_names(bool hard = false);
// Runs the cases; throws InputError for an unknown case name.
std::vector<VerificationRecord> run_verification(const VerifyOptions& options, MPI_Comm comm);

}  // namespace morphfem
