// Schedules as simulator loads: the same schedule files the hardware player uses
// become time functions of simulation time. The gait starts at `start` [s]
// (before it the robot settles at rest: bladders deflated, feet active, core at
// its pressure, as in the voxel study).
#pragma once
#include "actuation/schedule.h"
#include "fem/time_function.h"

namespace morphfem {

// Pressure setpoint [Pa] of `channel` (0..10, see schedule.h) over simulation time.
// Setpoints are piecewise linear (steps become ramps at the channel's ramp rate),
// so the function is exact: its breakpoints are the column boundaries and the ends
// of every ramp. A bladder or foot step (zero ramp time) is given `step_s` [s] to
// rise; the core holds its pressure from before the gait (it is reached during
// the simulation's settle phase, where the solver's load steps ramp into it).
TimeFunction channel_pressure(const Schedule& schedule, int channel, double start, double step_s = 1e-3);

// The schedule's levels as the loads play them: a bladder or foot step (zero ramp
// time) rises over `step_s` [s]; the core keeps its own ramp.
std::array<ChannelLevels, kNumChannels> load_levels(const Schedule& schedule, double step_s);

// Friction coefficient of a foot channel (kChannelFootA / kChannelFootB) over
// simulation time: mu_active while the schedule says active, mu_inactive
// otherwise, switching linearly over `switch_s` [s] at column boundaries.
TimeFunction foot_friction(const Schedule& schedule, int foot_channel, double start, double mu_active,
                           double mu_inactive, double switch_s = 1e-3);

}  // namespace morphfem
