// Rupture and leak detection on synthetic pressure traces (device time, Pa).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include "hardware/pressure_watch.h"

using morphfem::hw::PressureWatch;
using morphfem::hw::WatchSettings;

namespace {

// Feeds samples every h s from t0 to t1; returns the time of the first trip or NaN.
double first_trip(PressureWatch& w, double t0, double t1, double h, const std::function<double(double)>& cmd,
                  const std::function<double(double)>& meas, std::string* why = nullptr) {
  for (double t = t0; t <= t1 + 1e-9; t += h) {
    std::string r = w.add(t, cmd(t), meas(t));
    if (!r.empty()) {
      if (why) *why = r;
      return t;
    }
  }
  return std::nan("");
}

// First-order approach to the setpoint (time constant tau) after a step at t = 0 from p0.
std::function<double(double)> approach(double p0, double target, double tau) {
  return [=](double t) { return t < 0 ? p0 : target + (p0 - target) * std::exp(-t / tau); };
}

}  // namespace

TEST(PressureWatch, NormalFillsAndVentsDoNotTrip) {
  for (double h : {0.02, 0.05, 0.2}) {
    PressureWatch fill;
    EXPECT_TRUE(std::isnan(first_trip(
        fill, -1, 5, h, [](double t) { return t < 0 ? 0.0 : 25000.0; }, approach(0, 25000, 0.12))))
        << h;
    PressureWatch vent;
    EXPECT_TRUE(std::isnan(first_trip(
        vent, -1, 5, h, [](double t) { return t < 0 ? 25000.0 : 0.0; }, approach(25000, 0, 0.06))))
        << h;
    // A foot from -80 kPa to +50 kPa and back, stepped.
    PressureWatch foot;
    EXPECT_TRUE(std::isnan(first_trip(
        foot, -1, 5, h, [](double t) { return t < 0 ? -80000.0 : 50000.0; }, approach(-80000, 50000, 0.12))))
        << h;
  }
}

TEST(PressureWatch, NoiseAtAHeldSetpointDoesNotTrip) {
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 60);
  PressureWatch w;
  EXPECT_TRUE(std::isnan(first_trip(
      w, 0, 20, 0.02, [](double) { return 25000.0; }, [&](double) { return 25000 + noise(rng); })));
}

TEST(PressureWatch, PressureFallingWhileHeldTripsAtTheNextSample) {
  for (double h : {0.02, 0.05}) {
    PressureWatch w;
    std::string why;
    // Held at 25 kPa; at t = 1 the bladder ruptures and the pressure collapses to 4.8 kPa.
    double t = first_trip(
        w, 0, 3, h, [](double) { return 25000.0; }, [](double t) { return t < 1 ? 25000.0 : 4800.0; }, &why);
    EXPECT_GE(t, 1.0);
    EXPECT_LE(t, 1.0 + h + 1e-9) << why;
    EXPECT_NE(why.find("fell 20.2 kPa"), std::string::npos) << why;
  }
}

TEST(PressureWatch, AFillThatStallsTripsWithinTheWindowPlusOneSample) {
  const WatchSettings s;
  for (double h : {0.02, 0.05}) {
    // Commanded 25 kPa from t = 0; a ruptured bladder stays at 4.8 kPa.
    PressureWatch w;
    std::string why;
    double t = first_trip(
        w, -0.5, 3, h, [](double t) { return t < 0 ? 0.0 : 25000.0; }, [](double t) { return t < 0 ? 0.0 : 4800.0; },
        &why);
    EXPECT_GE(t, s.window_s - 1e-9) << why;
    EXPECT_LE(t, s.window_s + h + 1e-9) << why;
    EXPECT_NE(why.find("approaching it at"), std::string::npos) << why;
    // Rising at 100 kPa/s until 4.8 kPa (t = 0.048), then stalled: the window counts from the stall.
    PressureWatch w2;
    t = first_trip(
        w2, -0.5, 3, h, [](double t) { return t < 0 ? 0.0 : 25000.0; },
        [](double t) { return t < 0 ? 0.0 : std::min(4800.0, 100000 * t); }, &why);
    EXPECT_LE(t, 0.048 + s.window_s + h + 1e-9) << why;
  }
}

TEST(PressureWatch, AStuckValveAboveItsSetpointTrips) {
  PressureWatch w;
  std::string why;
  double t = first_trip(
      w, -0.5, 2, 0.02, [](double t) { return t < 0 ? 25000.0 : 0.0; }, [](double) { return 25000.0; }, &why);
  EXPECT_LE(t, WatchSettings{}.window_s + 0.02 + 1e-9) << why;
}

TEST(PressureWatch, AVacuumLeakTrips) {
  PressureWatch w;
  std::string why;
  // Held at -80 kPa; a leak lets the pressure rise towards atmosphere at 100 kPa/s from t = 1.
  double t = first_trip(
      w, 0, 3, 0.02, [](double) { return -80000.0; },
      [](double t) { return t < 1 ? -80000.0 : std::min(0.0, -80000 + 100000 * (t - 1)); }, &why);
  EXPECT_GE(t, 1.0);
  EXPECT_LE(t, 1.0 + 0.15) << why;
  EXPECT_NE(why.find("rose"), std::string::npos) << why;
}

TEST(PressureWatch, ASlowButSteadyFillDoesNotTrip) {
  // A big volume filling at 40 kPa/s, twice the default minimum rate.
  PressureWatch w;
  EXPECT_TRUE(std::isnan(first_trip(
      w, -0.5, 3, 0.02, [](double t) { return t < 0 ? 0.0 : 50000.0; },
      [](double t) { return t < 0 ? 0.0 : std::min(50000.0, 40000 * t); })));
}

TEST(PressureWatch, ResetForgetsTheHistory) {
  PressureWatch w;
  EXPECT_EQ(w.add(0, 25000, 25000), "");
  w.reset();
  // Without the 25 kPa sample there is no fall to see; one off sample is no stall.
  EXPECT_EQ(w.add(0.05, 25000, 4800), "");
}

TEST(PressureWatch, AReadingBehindARampingSetpointIsNoStall) {
  // A setpoint ramps down 25 -> 0 kPa; the regulator holds each command until the
  // next, and a reading shows the pressure before the command sent with it acts.
  // With readings 0.35 s apart (a stalled host at 10x) the pressure followed the
  // previous command, not the current one: no trip.
  PressureWatch w;
  EXPECT_EQ(w.add(0.0, 0.0, 14900, 25000), "");   // command 14.9 kPa, reading still 25 kPa
  EXPECT_EQ(w.add(0.01, 0.01, 9900, 15000), "");  // the regulator reached 14.9 kPa; now 9.9 kPa
  EXPECT_EQ(w.add(0.36, 0.36, 0, 9900), "");      // held 9.9 kPa for 0.35 s; now 0 kPa
  EXPECT_EQ(w.add(0.40, 0.40, 0, 0), "");
}
