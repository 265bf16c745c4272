// Morphing calibration: the times the core's valve takes to turn the flat
// robot into a cylinder and back, and the shapes it reaches.
//
// A morph run feeds the core from the line (supply gauge pressure p_s > 0) from
// t_inflate, then from the vacuum pump (p_s < 0) from t_deflate to t_end. The shape
// is the outer height h(t) of the mid-length cross-section (the robot's thickness)
// and its width w(t). Measures (the experimenter's stopwatch reading, made exact):
//   inflate time  = first t - t_inflate at which h has covered the fraction f of its
//                   change over the inflation phase, h(t_inflate) -> h(t_deflate);
//   deflate time  = the same over the vacuum phase, h(t_deflate) -> h(t_end);
//   inflated diameter = (w + h) / 2 at t_deflate (two caliper readings);
//   flat height   = h(t_end).
// Each phase counts as settled when h moved less than 1 % of the phase's change over
// its last 10 %; an unsettled phase makes its time depend on the phase length.
//
// Valve update: with the gas flow dn/dt = C (p_s - p) and a body that follows the
// gas quasi-statically, the history in t is the history in C t: a time scales as
// C^-1. With inertia and damping the exponent b in t ~ C^-b is fitted from the last
// two runs (log-log secant), b = 1 before that; C_next = C (t / t_target)^(1/b).
#pragma once
#include <string>
#include <vector>

namespace morphfem {

struct ShapeSample {
  double t = 0, width = 0, height = 0;  // [s], [m], [m]
};

struct MorphPhases {
  double inflate = 0, deflate = 0, end = 0;  // [s]: start of the supply, start of the vacuum, end
};

struct MorphMeasures {
  double inflate_time = 0, deflate_time = 0;       // [s] (NaN: the fraction was never reached)
  double inflated_diameter = 0, flat_height = 0;   // [m]
  double inflated_width = 0, inflated_height = 0;  // [m] at the end of the inflation
  double start_height = 0;                         // [m] at the start of the inflation
  bool inflate_settled = false, deflate_settled = false;
};

// Phases from a supply-pressure table (t, p_s): inflate = first time p_s > 0,
// deflate = first later time p_s < 0 before the end, NaN if none (an inflation-only
// run: the inflation phase lasts to the end; no deflate time, no flat height).
// Throws std::invalid_argument if there is no inflation. `end` is the run's end.
MorphPhases morph_phases(const std::vector<std::pair<double, double>>& supply, double end_time);

// First time after `from` at which h has covered `fraction` of the way from h(from)
// to h(to) (linear interpolation between samples); NaN if h(to) = h(from). Samples
// in increasing time.
double shape_change_time(const std::vector<ShapeSample>& samples, double from, double to, double fraction);

MorphMeasures measure_morphing(const std::vector<ShapeSample>& samples, const MorphPhases& phases, double fraction);

// One valve-conductance update towards the target time (see above). `history` holds
// the (C, t) pairs of the runs so far for this valve, the last one current.
double next_conductance(const std::vector<std::pair<double, double>>& history, double target_time);

}  // namespace morphfem
