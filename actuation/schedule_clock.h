// The column clock of a schedule played in settle mode by the simulator (schedule
// key cadence.mode: settle, actuation/schedule.h): a column starts once the
// pressures of the previous one have settled, as `morphfem hw play --mode settle`
// starts it on the bench, so one schedule file gives one cadence in both.
//
// The clock holds the simulation times s_0 < s_1 < ... at which the columns began
// (s_K, K = total columns, is the end of the gait) and answers what the schedule
// commands at time t given them: from each column start on, a channel's setpoint
// moves towards the column's level at its ramp rate (a step rises over step_s, as
// channel_pressure in actuation/schedule_loads.h plays fixed columns) and a foot's
// friction coefficient switches over switch_s. Before s_0 and after s_K the
// schedule is at rest. Loads that query the clock (TimeFunction::of) follow the
// column starts as they are decided.
//
// After every accepted time step ending at t the simulation reports the pressures
// and setpoints of the channels it feeds through valves (end_of_step). The next
// column starts at t if every one of them has settled (channel_settled: the
// setpoint has reached the column's level and the pressure is within the
// channel's tolerance of it) and the column has lasted at least min_hold_s
// (Cadence::may_end; the rest phase, from t = 0, at least until `start`). A
// column thus starts at the end of an accepted step, never inside one: it begins
// less than one step after the moment the pressures settled, as the player's
// begins less than one exchange after it, and the next step is the first whose
// loads see the new column (a valve's backward-Euler step takes the supply at the
// step's end). A column that waits longer than timeout_s stops the clock: the
// gait does not complete (timed_out_column()).
#pragma once
#include <array>
#include <string>
#include <vector>

#include "actuation/schedule.h"
#include "core/state_file.h"

namespace morphfem {

class ScheduleClock {
 public:
  // `start`: the earliest simulation time of column 1 [s]; tolerance_pa: each
  // channel's settle tolerance [Pa] (a channel map's tolerance_pa).
  ScheduleClock(Schedule schedule, double start, const std::array<double, kNumChannels>& tolerance_pa,
                double step_s = 1e-3, double switch_s = 1e-3);

  // The setpoint [Pa] of a bladder or foot channel at simulation time t.
  double setpoint_pa(int channel, double t) const;
  // A foot's friction coefficient at t: mu_active while the schedule says the
  // foot is active (and at rest), mu_inactive otherwise.
  double foot_mu(int foot_channel, double t, double mu_active, double mu_inactive) const;

  // A channel fed through a valve at the end of a step: its gauge pressure and
  // its supply's setpoint [Pa].
  struct Reading {
    int channel = -1;
    double pressure_pa = 0, setpoint_pa = 0;
  };
  // After an accepted step ending at t [s]; true if a column (or the rest after
  // the last one) started at t.
  bool end_of_step(double t, const std::vector<Reading>& readings);

  // -1 during the rest phase, k during column k, K once the gait is over.
  int column() const { return static_cast<int>(starts_.size()) - 1; }
  // Simulation times at which the columns began so far; a (K+1)-th entry is the
  // end of the gait [s].
  const std::vector<double>& column_starts() const { return starts_; }
  double gait_start() const;                                  // s_0, NaN before it [s]
  double gait_end() const;                                    // s_K, NaN before it [s]
  int timed_out_column() const { return timed_out_column_; }  // -1: none
  double tolerance_pa(int channel) const { return tolerance_pa_[channel]; }
  const Schedule& schedule() const { return schedule_; }
  double start() const { return start_; }

  // Checkpoints: the column starts and a timeout, under keys starting with `prefix`.
  void save(StateRecord& state, const std::string& prefix) const;
  void load(const StateRecord& state, const std::string& prefix, const std::string& where);

 private:
  Schedule schedule_;
  double start_;
  std::array<double, kNumChannels> tolerance_pa_;
  std::array<ChannelLevels, kNumChannels> levels_;  // with the steps' ramps (load_levels)
  double switch_s_;
  std::vector<double> starts_;
  int timed_out_column_ = -1;
};

}  // namespace morphfem
