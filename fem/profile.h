// Where a run's time goes, read from PETSc's log: every morphfem event
// (core/log_event.h) and PETSc's key events, as a snapshot of totals so far; the
// difference of two snapshots times what ran between them.
//
// Events nest and their times are inclusive: a Newton iteration is SNESJacobianEval
// (AsmHessian: H:NAME per term, then MatSetValuesCOO), PCSetUp (the factorisation:
// MatCholFctrSym once per pattern and MatCholFctrNum every time, or
// MatLUFactorSym/Num; PETSc 3.18 logs it outside KSPSetUp and KSPSolve), KSPSolve
// (PCApply: MatSolve), SNESLineSearch (LSEnergy: AsmEnergy with
// E:NAME; MaxStep:NAME; LSReproject) and SNESFunctionEval (AsmGradient: G:NAME).
// Outside SNESSolve: Predictor, StepHooks, RefreshPieces, PatternRebuild, OutputStep,
// OutputRow, SolverSave and StateFileWrite (checkpoints).
//
//   start_profiling();
//   const ProfileSnapshot before = profile_snapshot();
//   ... run ...
//   const ProfileSnapshot spent = profile_snapshot() - before;
//   std::fputs(profile_table(spent, "Newton it", stats.newton_its).c_str(), stdout);
#pragma once
#include <string>
#include <vector>

namespace morphfem {

struct ProfileEvent {
  std::string name;    // a morphfem event, or PETSc's (SNESSolve, MatCholFctrNum, ...)
  bool petsc = false;  // PETSc's own event
  double seconds = 0;  // inclusive wall time on this rank [s]
  long count = 0;      // calls (a call nested in itself counts once)
};

struct ProfileSnapshot {
  double wall_s = 0;  // PETSc's clock (PetscTime) [s]
  std::vector<ProfileEvent> events;
  const ProfileEvent* find(const std::string& name) const;  // nullptr if absent
  double seconds(const std::string& name) const;            // 0 if absent
  long count(const std::string& name) const;                // 0 if absent
};

// Switches PETSc's default log on (PetscLogDefaultBegin) unless it is already on
// (-log_view); returns whether it was. Events before this call are not timed.
bool start_profiling();
// This rank's totals so far (zeros without a running log). An event running at the
// snapshot counts its running time. Not collective.
ProfileSnapshot profile_snapshot();
// later - earlier, event by event (an event absent from `earlier` counts from zero).
ProfileSnapshot operator-(const ProfileSnapshot& later, const ProfileSnapshot& earlier);
// One line per event that ran: seconds, share of the wall time between the two
// snapshots [%], calls, and milliseconds per `unit` (e.g. "Newton it") if n_units > 0.
std::string profile_table(const ProfileSnapshot& difference, const std::string& unit = "", long n_units = 0);

}  // namespace morphfem
