// Leak and rupture detection in pressure terms, per channel, on the player's
// samples (device time in s, gauge pressures in Pa).
//
// A channel is "off" when |setpoint - measured| > off_pa. It trips when it is off and
//  * falling: within the last window_s, the measured pressure moved away from
//    the setpoint by more than drop_pa from its best value while every command
//    in between held it (within hold_band_pa) or pushed it towards the setpoint
//    (a bladder that ruptures or leaks while held or inflating); or
//  * stalled: it has been off on the same side for at least window_s and
//    approached the setpoint at less than min_rate_pa_per_s over that time (a
//    ruptured bladder that cannot fill, a leak, a valve stuck closed).
// Detection bound: a trip comes at the first sample after the pressure fell
// (falling), or at the first sample at least window_s (plus the duration of one
// exchange) after the channel went off (stalled); with samples every h seconds
// both are within window_s + h of the first off sample, i.e. within window_s + 2h
// of the fault itself.
#pragma once
#include <deque>
#include <string>

namespace morphfem::hw {

struct WatchSettings {
  double window_s = 0.15;            // device seconds
  double off_pa = 5000;              // |setpoint - measured| that counts as off
  double drop_pa = 5000;             // fall away from the setpoint that trips
  double min_rate_pa_per_s = 20000;  // slowest acceptable approach to the setpoint
  double hold_band_pa = 1000;        // a setpoint this close to the reading holds it (noise, dead band)
};

class PressureWatch {
 public:
  explicit PressureWatch(WatchSettings s = {}) : s_(s) {}
  // Adds one exchange: the reading was taken between device times sent_t (request
  // about to be written) and read_t (reply received), with the setpoint commanded
  // then. Returns "" or, when the channel trips, what was seen ("pressure fell
  // 15.2 kPa ..."). Rates use the shortest interval the two readings can be apart,
  // so a stall of the host between a reading and its time stamp cannot fake a stall.
  std::string add(double sent_t, double read_t, double commanded_pa, double measured_pa);
  std::string add(double t, double commanded_pa, double measured_pa) { return add(t, t, commanded_pa, measured_pa); }
  // Forgets the history (after a reconnection: old samples are no evidence).
  void reset() { hist_.clear(); }

 private:
  struct Sample {
    double t0, t, cmd, meas;  // the reading was taken within [t0, t]
  };
  std::string falling(int side) const;
  std::string stalled(int side) const;
  WatchSettings s_;
  std::deque<Sample> hist_;  // the last window_s, and the newest sample before it
};

}  // namespace morphfem::hw
