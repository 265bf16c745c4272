// The settle cadence in a run (Scene::settle): the model's schedule clock
// (actuation/schedule_clock.h), the loads bound to it when the terms are built,
// and its advance after every accepted step (sim/stepper.cpp).
#pragma once
#include <memory>

#include "sim/model.h"

namespace morphfem {

// The clock of a scene in settle mode, null otherwise (before the terms are built).
std::shared_ptr<ScheduleClock> make_schedule_clock(const Scene& scene);

// The scene's gas cavity `index` as the model builds it: fed by a channel in
// settle mode, its supply is the clock's setpoint (the core's keeps its own, which
// does not depend on the column).
GasCavitySpec clocked_gas_cavity(const Scene& scene, const Model& model, std::size_t index);

// The ground friction as the model builds it: in settle mode the feet's
// coefficients follow the clock.
FrictionSpec clocked_friction(const Scene& scene, const Model& model);

// After the terms are built: the valve-fed chambers the clock watches.
void watch_valves(Model& model);

// After an accepted step ending at t [s]: the clock reads the watched chambers'
// pressures and supplies and starts the next column if they have settled. Every
// rank reads the same values (a cavity's volume is reduced over all ranks).
void advance_schedule_clock(Model& model, double t);

}  // namespace morphfem
