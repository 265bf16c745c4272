#include "fem/profile.h"

#include <petsclog.h>
#include <petsctime.h>

#include <cstdio>

#include "core/log_event.h"
#include "fem/petsc_check.h"

namespace morphfem {

namespace {

// PETSc's events that show where a Newton iteration goes (fem/profile.h); each
// exists once its package has started (SNESCreate, ...).
const char* const kPetscEvents[] = {"SNESSolve",        "SNESFunctionEval", "SNESJacobianEval", "SNESLineSearch",
                                    "KSPSetUp",         "KSPSolve",         "PCSetUp",          "MatGetOrdering",
                                    "MatCholFctrSym",   "MatCholFctrNum",   "MatLUFactorSym",   "MatLUFactorNum",
                                    "PCApply",          "MatSolve",         "MatMult",          "MatSetValuesCOO",
                                    "MatAssemblyBegin", "MatAssemblyEnd",   "VecScatterBegin",  "VecScatterEnd"};

bool logging() {
  PetscBool on = PETSC_FALSE;
  return !PetscLogIsActive(&on) && on;
}

// Totals of `event` in the current stage; -1 seconds if it does not exist.
ProfileEvent read_event(PetscLogEvent event, const std::string& name, bool petsc, double now) {
  ProfileEvent e{name, petsc, 0.0, 0};
  PetscEventPerfInfo info;
  if (event < 0 || PetscLogEventGetPerfInfo(-1, event, &info)) return e;
  e.seconds = info.time;
  if (info.depth > 0) e.seconds += now + info.timeTmp;  // running: timeTmp = -(its start)
  e.count = info.count;
  return e;
}

}  // namespace

const ProfileEvent* ProfileSnapshot::find(const std::string& name) const {
  for (const auto& e : events)
    if (e.name == name) return &e;
  return nullptr;
}

double ProfileSnapshot::seconds(const std::string& name) const {
  const ProfileEvent* e = find(name);
  return e ? e->seconds : 0.0;
}

long ProfileSnapshot::count(const std::string& name) const {
  const ProfileEvent* e = find(name);
  return e ? e->count : 0;
}

bool start_profiling() {
  if (logging()) return true;
  PETSC_CHECK(PetscLogDefaultBegin());
  return false;
}

ProfileSnapshot profile_snapshot() {
  ProfileSnapshot s;
  PetscLogDouble now = 0;
  PETSC_CHECK(PetscTime(&now));
  s.wall_s = now;
  if (!logging()) return s;
  for (const std::string& name : log_event_names()) s.events.push_back(read_event(log_event(name), name, false, now));
  for (const char* name : kPetscEvents) {
    PetscLogEvent event = -1;
    if (PetscLogEventGetId(name, &event) || event < 0) continue;  // its package has not started
    s.events.push_back(read_event(event, name, true, now));
  }
  return s;
}

ProfileSnapshot operator-(const ProfileSnapshot& later, const ProfileSnapshot& earlier) {
  ProfileSnapshot d;
  d.wall_s = later.wall_s - earlier.wall_s;
  for (const auto& e : later.events) {
    ProfileEvent diff = e;
    if (const ProfileEvent* before = earlier.find(e.name)) {
      diff.seconds -= before->seconds;
      diff.count -= before->count;
    }
    d.events.push_back(diff);
  }
  return d;
}

std::string profile_table(const ProfileSnapshot& difference, const std::string& unit, long n_units) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-28s %10s %7s %8s", "event", "seconds", "share", "calls");
  out += line;
  if (n_units > 0) out += "  ms per " + unit;
  out += "\n";
  for (const auto& e : difference.events) {
    if (e.count <= 0) continue;
    const double share = difference.wall_s > 0 ? 100.0 * e.seconds / difference.wall_s : 0.0;
    std::snprintf(line, sizeof line, "%-28s %10.3f %6.1f%% %8ld", e.name.c_str(), e.seconds, share, e.count);
    out += line;
    if (n_units > 0) {
      std::snprintf(line, sizeof line, "  %10.2f", 1e3 * e.seconds / static_cast<double>(n_units));
      out += line;
    }
    out += "\n";
  }
  std::snprintf(line, sizeof line, "%-28s %10.3f %6.1f%%\n", "wall (between the snapshots)", difference.wall_s, 100.0);
  return out + line;
}

}  // namespace morphfem
