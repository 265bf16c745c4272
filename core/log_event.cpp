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

}  // namespace

PetscLogEvent log_event(const std::string& name) {
  if (!petsc_running()) return -1;
  Registry& r = registry();
  if (auto it = r.events.find(name); it != r.events.end()) return it->second;
  if (r.class_id == 0 && PetscClassIdRegister("morphfem", &r.class_id)) return -1;
  PetscLogEvent event = -1;
  if (PetscLogEventRegister(name.c_str(), r.class_id, &event)) return -1;
  r.events.emplace(name, event);
  r.names.push_back(name);
  return event;
}

std::vector<std::string> log_event_names() { return registry().names; }

LogEventScope::LogEventScope(PetscLogEvent event) : event_(event) {
  if (event_ >= 0 && PetscLogEventBegin(event_, 0, 0, 0, 0)) event_ = -1;
}

LogEventScope::~LogEventScope() {
  if (event_ >= 0) PetscLogEventEnd(event_, 0, 0, 0, 0);
}

}  // namespace morphfem
