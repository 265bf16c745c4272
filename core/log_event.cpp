#include "core/log_event.h"

#include <map>

namespace morphfem {

namespace {

bool petsc_running() {
  PetscBool initialised = PETSC_FALSE, finalised = PETSC_FALSE;
  if (PetscInitialized(&initialised) || PetscFinalized(&finalised)) return false;
  return initialised && !finalised;
}

struct Registry {
  PetscClassId class_id = 0;
  std::map<std::string, PetscLogEvent> events;
  std::vector<std::string> names;  // registration order
};

Registry& registry() {
  static Registry r;
  return r;
}

PetscLogEvent register_event(Registry& r, const std::string& name) {
  PetscLogEvent event = -1;
  if (PetscLogEventRegister(name.c_str(), r.class_id, &event)) return -1;
  r.events.emplace(name, event);
  r.names.push_back(name);
  return event;
}

}  // namespace

// -log_view with several ranks combines events by their id, so every rank must
// register them in the same order: the events that only rank 0 logs (output,
// checkpoint files) or that start late (pattern rebuilds) are registered with the
// first event, which every rank asks for (the assembler's terms, in add_term).
PetscLogEvent log_event(const std::string& name) {
  if (!petsc_running()) return -1;
  Registry& r = registry();
  if (auto it = r.events.find(name); it != r.events.end()) return it->second;
  if (r.class_id == 0) {
    if (PetscClassIdRegister("morphfem", &r.class_id)) return -1;
    for (const char* fixed :
         {"AsmEnergy", "AsmGradient", "AsmHessian", "Predictor", "StepHooks", "RefreshPieces", "PatternRebuild",
          "LowRank", "LSEnergy", "LSReproject", "SolverSave", "OutputStep", "OutputRow", "StateFileWrite"})
      register_event(r, fixed);
    if (auto it = r.events.find(name); it != r.events.end()) return it->second;
  }
  return register_event(r, name);
}

std::vector<std::string> log_event_names() { return registry().names; }

LogEventScope::LogEventScope(PetscLogEvent event) : event_(event) {
  if (event_ >= 0 && PetscLogEventBegin(event_, 0, 0, 0, 0)) event_ = -1;
}

LogEventScope::~LogEventScope() {
  if (event_ >= 0) PetscLogEventEnd(event_, 0, 0, 0, 0);
}

}  // namespace morphfem
