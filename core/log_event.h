// PETSc log events of the class "morphfem": where a run's time goes, shown by
// -log_view beside PETSc's own events (SNESSolve, MatCholFctrNum, MatSolve, ...) and
// read by fem/profile.h. An event is registered by name at its first use; its time
// is inclusive (events nest: Hess:elastic runs inside Hessian, inside SNESJacobianEval).
//
// Without PETSc (not initialised, or already finalised) every call is a no-op, so
// code that also runs without PETSc (state files of the search) may log events.
#pragma once
#include <petsclog.h>

#include <string>
#include <vector>

namespace morphfem {

// The event named `name` (registered at the first call), or -1 without PETSc.
PetscLogEvent log_event(const std::string& name);
// Every morphfem event registered so far, in registration order.
std::vector<std::string> log_event_names();

// Logs the event from construction to destruction (also when an exception leaves
// the scope). Costs a branch while logging is off.
class LogEventScope {
 public:
  explicit LogEventScope(PetscLogEvent event);
  explicit LogEventScope(const std::string& name) : LogEventScope(log_event(name)) {}
  ~LogEventScope();
  LogEventScope(const LogEventScope&) = delete;
  LogEventScope& operator=(const LogEventScope&) = delete;

 private:
  PetscLogEvent event_;
};

}  // namespace morphfem
