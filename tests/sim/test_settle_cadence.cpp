// One schedule in settle mode (cadence.mode: settle) played on the bench and in the
// model: the player against the emulator (hardware/) and the simulator (its
// schedule clock, actuation/schedule_clock.h) start the columns at the same times
// when they model the same plant; a compliant chamber fills later by what its
// pressure-volume curve says; the model's valve supply and foot friction follow
// its clock; bad settle input is refused naming its key.
//
// The plant. The scene feeds bladder b1, a quarter tube, through a valve with
// fill time tau = V_ref / (C R T) = 0.2 s; the emulator runs the same valve law on
// a rigid chamber (EmulatorConfig::valve_fill_time_s = tau). For a rigid chamber
// the gauge pressure approaches the setpoint as dp/dt = (p_s - p) / tau, so a
// swing of 25 kPa settles within the 2 kPa tolerance after
//   D = tau ln(25 / 2) = 0.505 s,
// and a column that changes nothing lasts min_hold_s = 0.35 s.
//
// Expected agreement (per column, all from the physics and the two clocks):
//  * the simulator steps the valve with backward Euler at dt = 5 ms: the pressure
//    falls short of the exponential by the factor (1 + dt/tau)^-n vs e^(-n dt/tau),
//    so it settles after ceil(ln(12.5) / ln(1 + dt/tau)) = 103 steps = 0.515 s, and
//    a held column after ceil(0.35 / dt) steps: its column lengths are these exactly
//    (to one step, the FE tube being rigid to 1e-5 in volume);
//  * the player sends a column's setpoints with its first exchange in the column
//    (one tick after the column started) and sees the settled pressure at its first
//    exchange after the pressure settled: its column lasts D plus that lag plus at
//    most the interval between two exchanges. Both are measured from its log, so a
//    host that stalls the player widens the bound instead of failing the test;
//  * so the two column lengths differ by the player's lag, its detection delay,
//    minus the backward-Euler excess (0.010 s) and one simulator step; the column
//    start times by the sum of these over the earlier columns.
// With a compliant tube (Dragon Skin 30) the chamber's volume grows with its
// pressure (by 10 % at 25 kPa) and the valve must fill that volume too:
// dn/dt = C (p_s - p) with n = p_abs V(p) / (R T) gives the settle time
//   D = tau / V_ref * integral of d(p_abs V) / (p_s - p)
// over the chamber's own pressure-volume curve, which the run records. The soft
// tube's columns last that long (to 3 %: the backward-Euler excess and one step),
// about 1.5 times the rigid chamber's (0.80 s against 0.515 s): the emulator,
// which models a rigid chamber, would start each column after a pressure change
// about 0.25-0.28 s earlier than this model, the lag adding up column by column.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "actuation/schedule.h"
#include "core/errors.h"
#include "hardware/channel_map.h"
#include "hardware/emulator.h"
#include "hardware/player.h"
#include "sim/model.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "tests/support/temp_dir.h"
#include "tests/support/tube_scene.h"

using namespace morphfem;

namespace {

constexpr double kTau = 0.2;          // valve fill time [s]
constexpr double kTolerance = 2000;   // b1's tolerance_pa in the channel map [Pa]
constexpr double kSwing = 25000;      // b1's inflate level [Pa]
constexpr double kHold = 0.35;        // min_hold_s [s]
constexpr double kStart = 0.2;        // settle_s and actuation.start [s]
constexpr double kStep = 0.005;       // the simulator's step [s]
constexpr double kAllowance = 0.006;  // exchange timing within a tick, sensor quantisation [s]

bool report() { return std::getenv("MORPHFEM_CADENCE_REPORT") != nullptr; }

// b1 inflates, holds (nothing changes: the hold decides), deflates, inflates; the
// gait ends when it has deflated again. The feet are not driven.
const char* kSchedule = R"(morphfem_schedule: 1
name: settle_check
column_s: 1.0
settle_s: 0.2
cadence: {mode: settle, min_hold_s: 0.35, timeout_s: 5}
matrix:
  - "1101"
  - "0000"
  - "0000"
  - "0000"
  - "0000"
  - "0000"
  - "0000"
  - "0000"
  - "0000"
  - "0000"
pressures:
  b1: {inflate_pa: 25000, deflate_pa: 0}
  feet: {inflate_pa: 0, deflate_pa: 0}
)";

std::string map_text(const std::string& dir) {
  return "morphfem_channel_map: 1\ndevices:\n  bus: {protocol: alicat, port: " + dir +
         "/bus}\nchannels:\n  b1: {device: bus, address: A, min_pa: -5000, max_pa: 35000, tolerance_pa: 2000}\n";
}

// The tube with b1 its inner wall; `material` rigid or soft.
std::string scene_text(const std::string& material, const std::string& actuation_extra = "",
                       const std::string& valves = ",\n            valves: {fill_time_s: 0.2}") {
  return "name: settle_tube\n" +
         quarter_tube("inner_radius: 0.005, outer_radius: 0.01, height: 0.004, mesh_size: 0.004", material) +
         R"(actuation: {schedule: schedule.yaml, channel_map: map.yaml, start: 0.2, bladders: {b1: inner}, volume_axes: [x, y])" +
         valves + actuation_extra + R"(}
solver: {end_time: 3.5, initial_step: 0.005, max_step: 0.005}
)";
}

const char* kRigid = "{model: neo_hookean, mu: 1.0e9, nu: 0.3}";
const char* kSoft = "{model: dragon_skin_30}";

struct Files {
  std::filesystem::path dir;
  explicit Files(const std::string& name) : dir(temp_dir(name)) {
    std::ofstream(dir / "schedule.yaml") << kSchedule;
    std::ofstream(dir / "map.yaml") << map_text(dir.string());
  }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  }
};

// The simulator's run: its column starts in schedule time (0 = actuation.start)
// and its chamber's (gauge pressure, volume) after every step, at schedule times.
struct SimRun {
  std::vector<double> starts, times;
  std::vector<std::pair<double, double>> pressure_volume;
  SimulationResult result;
  double pressure_at(double t) const {
    for (std::size_t i = 0; i < times.size(); ++i)
      if (std::abs(times[i] - t) < 1e-9) return pressure_volume[i].first;
    ADD_FAILURE() << "no step ends at " << t;
    return NAN;
  }
};

SimRun simulate(const Files& files, const std::string& material) {
  SimRun run;
  const Scene scene = read_scene(files.write("scene.yaml", scene_text(material)));
  RunOptions options{false, false};
  options.on_step = [&](double t, const Mesh&, const RowMatrixXd&, const SimulationResult& r) {
    run.times.push_back(t - kStart);
    run.pressure_volume.emplace_back(r.cavity_pressure.at(0), r.cavity_volume.at(0));
  };
  run.result = run_scene(scene, PETSC_COMM_WORLD, options);
  EXPECT_TRUE(run.result.stats.completed) << run.result.stats.failure;
  for (double t : run.result.column_starts) run.starts.push_back(t - kStart);
  return run;
}

// The player's run, from its log: the column starts (the "settled; column N"
// events), and per column b1's pressure at its start, the lag until its setpoints
// went out (its first sample) and the interval before the sample that found it
// settled.
struct BenchRun {
  std::vector<double> starts, pressure, lag, gap;
};

BenchRun play_on_emulator(const Files& files) {
  const Schedule schedule = read_schedule((files.dir / "schedule.yaml").string());
  const hw::ChannelMap map = hw::read_channel_map((files.dir / "map.yaml").string());
  hw::EmulatorConfig emulated;
  emulated.valve_fill_time_s = kTau;
  emulated.noise_pa = 0;
  emulated.links = {{"bus", (files.dir / "bus").string()}};
  hw::Emulator emulator(map, emulated);
  emulator.start();
  hw::PlayerOptions options;
  hw::take_cadence(schedule.cadence, options);
  options.tick_s = 0.005;
  options.reply_timeout_s = 1.0;
  options.max_gap_s = 5.0;  // a loaded host stalls now and then; the bounds below widen with it
  options.log_path = (files.dir / "log.csv").string();
  options.handle_signals = false;
  std::ostringstream sink;
  options.out = options.err = &sink;
  const int code = hw::play(schedule, map, options);
  emulator.stop();
  EXPECT_EQ(code, hw::kExitOk) << sink.str();
  const PressureTrace trace = read_pressure_log(options.log_path);
  BenchRun bench;
  for (const auto& e : trace.events)
    if (e.message.rfind("settled", 0) == 0) bench.starts.push_back(e.t);
  for (std::size_t k = 0; k + 1 < bench.starts.size(); ++k) {
    double first = NAN, before_end = bench.starts[k];
    for (std::size_t i = 0; i < trace.t.size(); ++i) {
      if (trace.column[i] != static_cast<int>(k)) continue;
      if (std::isnan(first)) first = trace.t[i];
      if (trace.t[i] < bench.starts[k + 1]) before_end = std::max(before_end, trace.t[i]);
    }
    bench.pressure.push_back(trace.measured_at(0, bench.starts[k]));
    bench.lag.push_back(first - bench.starts[k]);
    bench.gap.push_back(bench.starts[k + 1] - before_end);
  }
  return bench;
}

// A column of the rigid chamber whose pressure starts `off` [Pa] from the column's
// level: the exponential's settle time or the hold, and the simulator's: the
// backward-Euler steps to settle, or the hold's.
double exponential_column(double off) {
  return std::max(off > kTolerance ? kTau * std::log(off / kTolerance) : 0.0, kHold);
}
double backward_euler_column(double off) {
  const double settle = off > kTolerance ? std::ceil(std::log(off / kTolerance) / std::log(1 + kStep / kTau)) : 0;
  return std::max(settle, std::ceil(kHold / kStep - 1e-9)) * kStep;
}

// The time a chamber with the recorded pressure-volume curve takes to go from
// p_from to within the tolerance of p_to through the valve: tau / V_ref times the
// integral of d(p_abs V) / (p_to - p), over the curve's samples between them.
double compliant_settle_time(std::vector<std::pair<double, double>> curve, double p_from, double p_to) {
  const double p_atm = 101325, v_ref = curve.front().second;
  std::sort(curve.begin(), curve.end());
  const double lo = std::min(p_from, p_to) + (p_to < p_from ? kTolerance : 0);
  const double hi = std::max(p_from, p_to) - (p_to > p_from ? kTolerance : 0);
  double time = 0;
  for (std::size_t i = 1; i < curve.size(); ++i) {
    const auto& [p0, v0] = curve[i - 1];
    const auto& [p1, v1] = curve[i];
    if (p0 < lo || p1 > hi || p1 <= p0) continue;
    const double gas = (p_atm + p1) * v1 - (p_atm + p0) * v0;  // d(p_abs V) [J]
    time += kTau / v_ref * gas / std::abs(p_to - 0.5 * (p0 + p1));
  }
  return time;
}

const double kLevel[] = {kSwing, kSwing, 0, kSwing};  // b1's level per column [Pa]

}  // namespace

// The rigid tube in the simulator against the emulator's valve law: each column
// length within the bound the physics and the player's log give, and so each
// column start within the sum of the earlier bounds.
TEST(SettleCadence, EmulatorAndSimulatorStartTheColumnsTogether) {
  const Files files("settle_rigid");
  const SimRun sim = simulate(files, kRigid);
  ASSERT_TRUE(sim.result.gait_complete);
  const BenchRun bench = play_on_emulator(files);
  ASSERT_EQ(sim.starts.size(), 5u) << "4 columns and the gait's end";
  ASSERT_EQ(bench.starts.size(), 5u);
  // The rest phase: the chamber starts settled; both wait settle_s = actuation.start.
  EXPECT_NEAR(sim.starts[0], 0.0, 1e-12);
  EXPECT_GE(bench.starts[0], -1e-9);
  double allowed = std::max(0.0, bench.starts[0]) + kAllowance, worst = std::abs(bench.starts[0] - sim.starts[0]);
  for (int k = 0; k < 4; ++k) {
    const double sim_length = sim.starts[k + 1] - sim.starts[k];
    const double bench_length = bench.starts[k + 1] - bench.starts[k];
    const double sim_off = std::abs(kLevel[k] - sim.pressure_at(sim.starts[k]));
    const double bench_off = std::abs(kLevel[k] - bench.pressure[k]);
    EXPECT_NEAR(sim_length, backward_euler_column(sim_off), kStep + 1e-9) << "column " << k + 1;
    // The bench: the exponential (or the hold) after the player's lag, found within
    // its interval between samples.
    const bool held = exponential_column(bench_off) == kHold;
    const double lag = held ? 0.0 : bench.lag[k];
    EXPECT_GE(bench_length, exponential_column(bench_off) + lag - kAllowance) << "column " << k + 1;
    EXPECT_LE(bench_length, exponential_column(bench_off) + lag + bench.gap[k] + kAllowance) << "column " << k + 1;
    // Together: the lengths differ by at most the player's lag and interval, the
    // backward-Euler excess, a simulator step and the difference of the starting
    // pressures (each side settles the previous column within its own step).
    const double bound = lag + bench.gap[k] + std::abs(backward_euler_column(sim_off) - exponential_column(sim_off)) +
                         std::abs(exponential_column(sim_off) - exponential_column(bench_off)) + kStep + kAllowance;
    EXPECT_LE(std::abs(bench_length - sim_length), bound) << "column " << k + 1;
    allowed += bound;
    worst = std::max(worst, std::abs(bench.starts[k + 1] - sim.starts[k + 1]));
    EXPECT_NEAR(bench.starts[k + 1], sim.starts[k + 1], allowed) << "start of column " << k + 2;
    if (report())
      std::cout << "column " << k + 1 << ": simulator " << sim_length << " s (off " << sim_off << " Pa), bench "
                << bench_length << " s (off " << bench_off << " Pa, lag " << bench.lag[k] << " s, interval "
                << bench.gap[k] << " s), exponential " << exponential_column(bench_off) << " s, bound " << bound
                << " s\n";
  }
  if (report()) {
    std::cout << "column starts, simulator / bench [s]:";
    for (int k = 0; k < 5; ++k) std::cout << " " << sim.starts[k] << "/" << bench.starts[k];
    std::cout << "; largest difference " << worst << " s, allowed " << allowed << " s\n";
  }
  // The run reports its cadence with its speed.
  EXPECT_EQ(sim.result.cadence.mode, Cadence::Mode::settle);
  EXPECT_EQ(sim.result.cadence.min_hold_s, kHold);
  EXPECT_NEAR(sim.result.gait_s, sim.starts[4] - sim.starts[0], 1e-12);
}

// The Dragon Skin tube: its columns last what its own pressure-volume curve says,
// longer than the rigid chamber's (and the emulator's) by the gas its growth takes.
TEST(SettleCadence, ACompliantChamberSettlesAsItsPressureVolumeCurveSays) {
  const Files files("settle_soft");
  const SimRun soft = simulate(files, kSoft);
  ASSERT_EQ(soft.starts.size(), 5u);
  const double v_ref = soft.pressure_volume.front().second;
  double grown = v_ref;
  for (const auto& [p, v] : soft.pressure_volume) grown = std::max(grown, v);
  EXPECT_GT(grown, 1.05 * v_ref) << "the soft tube should grow markedly at 25 kPa";
  for (int k = 0; k < 4; ++k) {
    const double length = soft.starts[k + 1] - soft.starts[k];
    const double from = soft.pressure_at(soft.starts[k]), off = std::abs(kLevel[k] - from);
    const double rigid = backward_euler_column(off);
    const double predicted =
        off > kTolerance ? std::max(compliant_settle_time(soft.pressure_volume, from, kLevel[k]), kHold) : kHold;
    EXPECT_NEAR(length, predicted, 0.03 * predicted + kStep) << "column " << k + 1;
    if (off > kTolerance) {
      EXPECT_GT(length, 1.2 * rigid) << "column " << k + 1;
    }
    if (report())
      std::cout << "soft column " << k + 1 << ": " << length << " s, from its p-V curve " << predicted << " s, rigid "
                << rigid << " s\n";
  }
  if (report()) std::cout << "soft tube: largest V / V_ref = " << grown / v_ref << "\n";
}

// The model binds the loads to its clock: the bladder's supply is the clock's
// setpoint, and the feet's friction regions (after a region of contact.friction
// itself) follow their rows of the columns the clock starts.
TEST(SettleCadence, TheModelsLoadsFollowItsClock) {
  const Files files("settle_model");
  std::string schedule = kSchedule;
  const std::string feet_rows = "\"0000\"\n  - \"0000\"\npressures";
  schedule.replace(schedule.find(feet_rows), feet_rows.size(), "\"1010\"\n  - \"0101\"\npressures");
  files.write("schedule.yaml", schedule);
  const Scene scene = read_scene(files.write(
      "scene.yaml", scene_text(kRigid, ", feet: {foot_a: zmin, foot_b: zmax, mu_active: 0.7, mu_inactive: 0.56}") +
                        "contact:\n  ground: {point: [0, 0, -1], normal: [0, 0, 1], surfaces: [zmin, zmax, outer]}\n"
                        "  friction: {regions: [{surface: outer, mu: 0.3}]}\n"));
  Mesh mesh = build_scene_mesh(scene, PETSC_COMM_WORLD);
  const std::unique_ptr<Model> model = build_model(scene, mesh, PETSC_COMM_WORLD);
  ASSERT_TRUE(model->schedule_clock);
  ScheduleClock& clock = *model->schedule_clock;
  ASSERT_EQ(model->watched_valves.size(), 1u);
  EXPECT_EQ(model->watched_valves[0].first, 0);  // b1
  ASSERT_TRUE(clock.end_of_step(kStart, {}));    // column 1 at 0.2 s
  ASSERT_TRUE(clock.end_of_step(0.7, {}));       // column 2 at 0.7 s
  const GasCavitySpec& b1 = model->watched_valves[0].second->spec();
  const auto& regions = model->friction->spec().regions;
  ASSERT_EQ(regions.size(), 3u);
  for (double t : {0.1, 0.3, 0.69, 0.75, 1.5}) {
    EXPECT_EQ(b1.supply_gauge_pressure(t), clock.setpoint_pa(0, t)) << t;
    EXPECT_EQ(regions[0].mu_static(t), 0.3) << t;
    EXPECT_EQ(regions[1].mu_static(t), clock.foot_mu(kChannelFootA, t, 0.7, 0.56)) << t;
    EXPECT_EQ(regions[2].mu_kinetic(t), clock.foot_mu(kChannelFootB, t, 0.7, 0.56)) << t;
  }
  EXPECT_EQ(b1.supply_gauge_pressure(0.3), kSwing);  // column 1 inflates b1
  EXPECT_EQ(regions[1].mu_static(0.3), 0.7);         // foot A active in column 1
  EXPECT_EQ(regions[2].mu_static(0.3), 0.56);
  EXPECT_EQ(regions[1].mu_static(0.75), 0.56);  // and inactive in column 2, from its start at 0.7 s
  EXPECT_EQ(regions[2].mu_static(0.75), 0.7);
  EXPECT_EQ(regions[1].mu_static(0.1), 0.7) << "every foot is active at rest";
}

// Settle mode needs what it reads: valves (the pressures), chambers to watch, the
// schedule timing, a map that drives them at the schedule's pressures; a map with
// a fixed cadence is an error too. Each names the key.
TEST(SettleCadence, BadSettleInputNamesItsKey) {
  const Files files("settle_bad");
  auto error_of = [&](const std::string& text) -> std::string {
    try {
      read_scene(files.write("bad.yaml", text));
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  std::string e = error_of(scene_text(kRigid, "", ""));
  EXPECT_NE(e.find("bad.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("actuation.valves"), std::string::npos) << e;
  EXPECT_NE(e.find("schedule.yaml plays in settle mode"), std::string::npos) << e;
  e = error_of(scene_text(kRigid, ", timing: voxel"));
  EXPECT_NE(e.find("actuation.timing"), std::string::npos) << e;
  std::string text = scene_text(kRigid);
  e = error_of(text.replace(text.find("bladders: {b1: inner}, "), 23, ""));
  EXPECT_NE(e.find("no chamber"), std::string::npos) << e;
  // A map that does not drive b1, or changes its pressures.
  files.write("other.yaml",
              "morphfem_channel_map: 1\ndevices:\n  bus: {protocol: alicat, port: x}\nchannels:\n"
              "  b2: {device: bus, address: A, min_pa: -5000, max_pa: 35000}\n");
  text = scene_text(kRigid);
  e = error_of(text.replace(text.find("map.yaml"), 8, "other.yaml"));
  EXPECT_NE(e.find("actuation.channel_map"), std::string::npos) << e;
  EXPECT_NE(e.find("drives channel b1 but the map has no such channel"), std::string::npos) << e;
  text = map_text(files.dir.string());
  files.write("other.yaml", text.replace(text.find("tolerance_pa"), 0, "inflated_pa: 20000, "));
  text = scene_text(kRigid);
  e = error_of(text.replace(text.find("map.yaml"), 8, "other.yaml"));
  EXPECT_NE(e.find("does not play the schedule's pressures"), std::string::npos) << e;
  EXPECT_NE(e.find("b1 columns 1-2: schedule 25.0 kPa, commanded 20.0 kPa (inflated_pa of"), std::string::npos) << e;
  // A fixed cadence: the map has nothing to do.
  std::string schedule = kSchedule;
  files.write("schedule.yaml", schedule.replace(schedule.find("mode: settle"), 12, "mode: fixed"));
  e = error_of(scene_text(kRigid));
  EXPECT_NE(e.find("actuation.channel_map"), std::string::npos) << e;
  EXPECT_NE(e.find("cadence.mode fixed"), std::string::npos) << e;
  // An unknown mode, a negative hold: the schedule file's line and key.
  schedule = kSchedule;
  files.write("schedule.yaml", schedule.replace(schedule.find("mode: settle"), 12, "mode: eager"));
  e = error_of(scene_text(kRigid));
  EXPECT_NE(e.find("schedule.yaml:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("cadence.mode"), std::string::npos) << e;
  schedule = kSchedule;
  files.write("schedule.yaml", schedule.replace(schedule.find("min_hold_s: 0.35"), 16, "min_hold_s: -1"));
  e = error_of(scene_text(kRigid));
  EXPECT_NE(e.find("schedule.yaml:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("cadence.min_hold_s"), std::string::npos) << e;
}
