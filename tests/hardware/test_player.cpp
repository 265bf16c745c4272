// The player against the emulator over real pseudo-terminals: both protocols,
// both hand-designed gaits, every injected fault, safety refusals, dry run,
// settle and step modes, and the log replayed through the schedule reader.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "actuation/schedule.h"
#include "core/errors.h"
#include "hardware/channel_map.h"
#include "hardware/cli.h"
#include "hardware/emulator.h"
#include "hardware/player.h"
#include "tests/hardware/rig.h"

using namespace morphfem;
using namespace morphfem::hw;

using namespace hwtest;

namespace {

// Measured pressures at the last sample of every column match the commands within
// tol. A column is evidence only if its last sample came at least 0.5 column_s
// = 0.62 s after its first (when its commands went out; the valves settle in
// about 5 tau = 0.6 s; a tick is 0.05 s of schedule time at 10x): after a
// stall of the host longer than a column (124 ms wall at 10x) its only sample
// is the one that sent the commands. Nine in ten columns must be evidence.
void expect_tracking(const PressureTrace& tr, const Schedule& s, double tol) {
  int checked = 0;
  for (int k = 0; k < s.total_columns(); ++k) {
    std::size_t first = tr.t.size(), last = tr.t.size();
    for (std::size_t i = 0; i < tr.t.size(); ++i)
      if (tr.column[i] == k) {
        if (first == tr.t.size()) first = i;
        last = i;
      }
    if (last == tr.t.size() || tr.t[last] - tr.t[first] < 0.5 * s.column_s) continue;
    ++checked;
    for (std::size_t c = 0; c < tr.channels.size(); ++c)
      EXPECT_NEAR(tr.measured[c][last], tr.commanded[c][last], tol)
          << channel_name(tr.channels[c]) << " column " << k + 1 << " t " << tr.t[last];
  }
  EXPECT_GE(checked, 0.9 * s.total_columns()) << "columns sampled near their end (a starved host?)";
}

std::string last_event(const PressureTrace& tr) { return tr.events.empty() ? "" : tr.events.back().message; }

bool has_fault(const PressureTrace& tr, const std::string& text) {
  for (auto& e : tr.events)
    if (e.kind == "fault" && e.message.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(ChannelMapFile, ExampleParsesAndAcceptsTheGaits) {
  ChannelMap m = read_channel_map(kExamples + "channel_map.yaml");
  EXPECT_EQ(m.devices.size(), 2u);
  EXPECT_EQ(m.channels.size(), 11u);
  EXPECT_EQ(m.find(0)->address, 0x11);
  EXPECT_EQ(m.find(kChannelCore)->address, 'A');
  m.check_schedule(read_schedule(kExamples + "rolling.yaml"));
  m.check_schedule(read_schedule(kExamples + "inching.yaml"));
  auto lv = m.effective_levels(read_schedule(kExamples + "rolling.yaml"));
  EXPECT_EQ(lv[kChannelCore].inflate_pa, 50000);
}

TEST(ChannelMapFile, ErrorsNameFileLineAndReason) {
  auto err = [](const std::string& text) {
    try {
      parse_channel_map(text, "map.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  std::string head = "morphfem_channel_map: 1\ndevices:\n  bus: {protocol: alicat, port: /dev/null}\nchannels:\n";
  std::string e = err(head + "  b1: {device: bus, address: AB, min_pa: 0, max_pa: 1}\n");
  EXPECT_NE(e.find("map.yaml:5:"), std::string::npos) << e;
  EXPECT_NE(e.find("channels.b1.address"), std::string::npos) << e;
  e = err(head + "  b1: {device: bus, address: A, min_pa: 0}\n");
  EXPECT_NE(e.find("max_pa"), std::string::npos) << e;
  e = err(head + "  b9: {device: bus, address: A, min_pa: 0, max_pa: 1}\n");
  EXPECT_NE(e.find("unknown channel 'b9'"), std::string::npos) << e;
  e = err(
      head +
      "  b1: {device: bus, address: A, min_pa: 0, max_pa: 1}\n  b2: {device: bus, address: A, min_pa: 0, max_pa: 1}\n");
  EXPECT_NE(e.find("map.yaml:6:"), std::string::npos) << e;
  EXPECT_NE(e.find("already used"), std::string::npos) << e;
  e = err(head + "  b1: {device: bus, address: A, min_pa: 0, max_pa: 100, inflated_pa: 200}\n");
  EXPECT_NE(e.find("outside this channel's limits"), std::string::npos) << e;
  e = err(head + "  b1: {device: nope, address: A, min_pa: 0, max_pa: 1}\n");
  EXPECT_NE(e.find("no device named 'nope'"), std::string::npos) << e;
  e = err("morphfem_channel_map: 1\ndevices:\n  bus: {protocol: can}\nchannels: {}\n");
  EXPECT_NE(e.find("map.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown protocol 'can'"), std::string::npos) << e;
}

TEST(Player, RefusesPressuresBeyondLimitsBeforeSendingAnything) {
  std::string dir = temp_dir("refuse");
  // Bladder limit below the schedule's 25 kPa inflate level.
  ChannelMap m = parse_channel_map(map_text(dir, true, 20000), dir + "/map.yaml");
  EmulatorConfig cfg;
  cfg.links = {{"bus", dir + "/bus"}};
  Emulator emu(m, cfg);
  emu.start();
  PlayerOptions opt;
  std::ostringstream sink;
  opt.out = opt.err = &sink;
  opt.handle_signals = false;
  opt.log_path = dir + "/log.csv";
  try {
    play(read_schedule(kExamples + "rolling.yaml"), m, opt);
    ADD_FAILURE() << "schedule beyond limits was accepted";
  } catch (const InputError& e) {
    std::string w = e.what();
    EXPECT_NE(w.find("refused before sending anything"), std::string::npos) << w;
    EXPECT_NE(w.find("25000"), std::string::npos) << w;
    EXPECT_NE(w.find("channels.b1"), std::string::npos) << w;
  }
  EXPECT_EQ(emu.requests(), 0);
  EXPECT_FALSE(std::filesystem::exists(dir + "/log.csv"));
  // A map level beyond the channel's own limit is refused when the map is read.
  EXPECT_THROW(parse_channel_map("morphfem_channel_map: 1\ndevices:\n  bus: {protocol: alicat}\nchannels:\n"
                                 "  b1: {device: bus, address: A, min_pa: 0, max_pa: 30000, inflated_pa: 40000}\n",
                                 "m.yaml"),
               InputError);
  // Through the CLI: exit code 2, message names the file.
  std::ofstream(dir + "/map.yaml") << map_text(dir, true, 20000);
  std::ostringstream cli_out, cli_err;
  auto* old_out = std::cout.rdbuf(cli_out.rdbuf());
  auto* old_err = std::cerr.rdbuf(cli_err.rdbuf());
  int cli_code = hardware_main({"check", kExamples + "rolling.yaml", "--map", dir + "/map.yaml"});
  // The example map holds the core at 50 kPa: accepted only with --allow-map-override.
  int ok_code = hardware_main(
      {"check", kExamples + "inching.yaml", "--map", kExamples + "channel_map.yaml", "--allow-map-override"});
  std::cout.rdbuf(old_out);
  std::cerr.rdbuf(old_err);
  EXPECT_EQ(cli_code, kExitInput);
  EXPECT_NE(cli_err.str().find(dir + "/map.yaml:"), std::string::npos) << cli_err.str();
  EXPECT_EQ(ok_code, 0) << cli_err.str();
  EXPECT_NE(cli_out.str().find("every pressure within limits"), std::string::npos);
  emu.stop();
  std::filesystem::remove_all(dir);
}

TEST(Player, CliRefusesABadTrackingFaultSampleCount) {
  for (const std::string bad : {"0", "2.5", "many"}) {
    std::ostringstream cli_err;
    auto* old_err = std::cerr.rdbuf(cli_err.rdbuf());
    int code = hardware_main({"play", kExamples + "rolling.yaml", "--map", kExamples + "channel_map.yaml",
                              "--tracking-fault-samples", bad, "--dry-run"});
    std::cerr.rdbuf(old_err);
    EXPECT_EQ(code, kExitInput) << bad;
    EXPECT_NE(cli_err.str().find("--tracking-fault-samples"), std::string::npos) << cli_err.str();
  }
}

// `hw play` takes the mode and the hold from the schedule's cadence block; its
// options override them (a dry run advances a settle column once its hold is over).
TEST(Player, CliTakesTheCadenceFromTheSchedule) {
  const std::string dir = temp_dir("cadence_cli");
  Schedule s = read_schedule(kExamples + "rolling.yaml");
  s.repeats = 1;
  s.cadence = {Cadence::Mode::settle, 0.3, 30};
  std::ofstream(dir + "/settle.yaml") << s.to_yaml();
  auto column_starts = [&](const std::vector<std::string>& options) {
    std::vector<std::string> args{
        "play",  dir + "/settle.yaml", "--map", kExamples + "channel_map.yaml", "--allow-map-override", "--dry-run",
        "--log", dir + "/log.csv"};
    args.insert(args.end(), options.begin(), options.end());
    const CliResult r = run_cli(args);
    EXPECT_EQ(r.code, kExitOk) << r.err;
    std::vector<double> starts;
    for (const auto& e : read_pressure_log(dir + "/log.csv").events)
      if (e.message.rfind("settled; column", 0) == 0) starts.push_back(e.t);
    return starts;
  };
  std::vector<double> settle = column_starts({});
  ASSERT_EQ(settle.size(), 9u) << "the rest phase and 8 columns";
  for (std::size_t k = 1; k < settle.size(); ++k) EXPECT_NEAR(settle[k] - settle[k - 1], 0.3, 0.021) << k;
  std::vector<double> longer = column_starts({"--min-hold-s", "0.5"});
  ASSERT_EQ(longer.size(), 9u);
  EXPECT_NEAR(longer[8] - longer[1], 7 * 0.5, 7 * 0.021);
  EXPECT_TRUE(column_starts({"--mode", "fixed"}).empty()) << "fixed columns are not settled";
  std::filesystem::remove_all(dir);
}

TEST(Player, DryRunPrintsTheCommandStream) {
  ChannelMap m = read_channel_map(kExamples + "channel_map.yaml");
  PlayerOptions opt;
  std::ostringstream out, err;
  opt.out = &out;
  opt.err = &err;
  opt.dry_run = true;
  opt.handle_signals = false;
  opt.allow_map_override = true;  // the example map holds the core at 50 kPa
  ASSERT_EQ(play(read_schedule(kExamples + "rolling.yaml"), m, opt), kExitOk);
  std::string s = out.str();
  // b8 inflates in column 1 (ramp-limited to 500 kPa/s by the map): setpoint counts
  // for 25 kPa = 1023*(0.1+0.8*0.625) = 614 -> left-justified 0x9980.
  EXPECT_NE(s.find("t=0.000 b8 bridge tx A5 57 18 10 03 80 00 01"), std::string::npos) << s.substr(0, 2000);
  EXPECT_NE(s.find("t=0.200 b8 bridge tx A5 57 18 10 03 99 80 01"), std::string::npos) << s.substr(0, 2000);
  EXPECT_NE(s.find("core alicat tx AS 50.000\\r"), std::string::npos);
  EXPECT_NE(s.find("vent foot_b alicat tx CS 0.000\\r"), std::string::npos);
  // The map's change is printed: the schedule's 12 kPa core is held at 50 kPa.
  EXPECT_NE(err.str().find("core rest and columns 1-8: schedule 12.0 kPa, commanded 50.0 kPa"), std::string::npos)
      << err.str();
}

class GaitTest : public ::testing::TestWithParam<std::tuple<std::string, bool>> {};

TEST_P(GaitTest, PlaysAgainstTheEmulatorAndTracks) {
  auto [gait, all_alicat] = GetParam();
  Rig rig(gait + (all_alicat ? "_alicat" : "_mixed"), all_alicat);
  Schedule s = read_schedule(kExamples + gait + ".yaml");
  auto t0 = std::chrono::steady_clock::now();
  int code = rig.play(s);
  double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(code, kExitOk) << rig.err.str();
  EXPECT_LT(wall, 8.0);  // 19.8 s schedule at time scale 10
  EXPECT_TRUE(rig.emu->all_vented());
  for (auto& c : rig.emu->snapshot()) {
    EXPECT_FALSE(c.ruptured) << channel_name(c.channel);
    EXPECT_LE(c.max_pressure_pa, 55000 + 1000) << channel_name(c.channel);
  }
  PressureTrace tr = read_pressure_log(rig.opt.log_path);
  EXPECT_EQ(tr.channels.size(), 11u);
  EXPECT_NEAR(tr.duration(), s.duration(), 0.5);
  expect_tracking(tr, s, 2500);
  EXPECT_EQ(last_event(tr), "all channels vented");
  // Real-to-sim replay: the log's commands give back the schedule's matrix.
  ScheduleMatrix m = tr.to_matrix(s.column_s, s.columns(), rig.map.effective_levels(s));
  EXPECT_EQ(m, s.matrix);
  // The core held the map's pressure during the gait.
  EXPECT_NEAR(tr.measured_at(kChannelCore, 10.0), 30000, 1500);
}

INSTANTIATE_TEST_SUITE_P(BothProtocols, GaitTest,
                         ::testing::Combine(::testing::Values("rolling", "inching"), ::testing::Bool()));

TEST(Player, SettleModeAdvancesWhenPressuresSettle) {
  Rig rig("settle", false);
  Schedule s = read_schedule(kExamples + "inching.yaml");
  s.repeats = 1;
  rig.opt.mode = PlayerOptions::Mode::settle;
  ASSERT_EQ(rig.play(s), kExitOk) << rig.err.str();
  PressureTrace tr = read_pressure_log(rig.opt.log_path);
  int settled = 0;
  for (auto& e : tr.events) settled += e.message.rfind("settled", 0) == 0;
  EXPECT_EQ(settled, 9);                   // rest + 8 columns
  EXPECT_LT(tr.duration(), s.duration());  // faster than fixed 1.237 s columns
  EXPECT_TRUE(rig.emu->all_vented());
}

TEST(Player, StepModeWaitsForKeys) {
  Rig rig("step", true);
  Schedule s = read_schedule(kExamples + "rolling.yaml");
  s.repeats = 1;
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  rig.opt.mode = PlayerOptions::Mode::step;
  rig.opt.step_fd = fds[0];
  std::thread keys([&] {
    for (int i = 0; i < 3; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      ASSERT_EQ(write(fds[1], "\n", 1), 1);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    ASSERT_EQ(write(fds[1], "q", 1), 1);
  });
  int code = rig.play(s);
  keys.join();
  close(fds[0]);
  close(fds[1]);
  EXPECT_EQ(code, kExitOk) << rig.err.str();
  PressureTrace tr = read_pressure_log(rig.opt.log_path);
  int steps = 0;
  for (auto& e : tr.events) steps += e.message.rfind("step to column", 0) == 0;
  EXPECT_EQ(steps, 3);
  EXPECT_EQ(tr.column.back(), 2);
  EXPECT_TRUE(rig.emu->all_vented());
}

TEST(Player, ReconnectsWhenThePortComesBack) {
  EmulatorConfig cfg;
  cfg.faults.push_back(parse_fault("disconnect@5:0.8"));  // back after 0.8 s wall, longer than the rig's max gap
  Rig rig("reconnect", false, cfg);
  rig.opt.reconnect_s = 5;
  // 0.8 s wall at 10x is 8 s of schedule time without readings: the columns it
  // overlaps are lost; --continue-after-gap plays on and ends with exit 0.
  rig.opt.continue_after_gap = true;
  Schedule s = read_schedule(kExamples + "rolling.yaml");  // 19.8 s: plays on after the gap
  ASSERT_EQ(rig.play(s), kExitOk) << rig.err.str();
  PressureTrace tr = read_pressure_log(rig.opt.log_path);
  bool lost = false, back = false;
  for (auto& e : tr.events) {
    lost |= e.message.find("port " + rig.dir + "/bridge lost") != std::string::npos;
    back |= e.message.find("reconnected") != std::string::npos;
  }
  EXPECT_TRUE(lost && back);
  EXPECT_TRUE(has_fault(tr, "lost columns")) << rig.err.str();
  EXPECT_NE(rig.err.str().find("schedule played to the end with lost columns"), std::string::npos) << rig.err.str();
  EXPECT_TRUE(rig.emu->all_vented());
}

// ---- One test per injected fault: vented, clear message, non-zero exit, log complete.
// The communication faults (garbled, missing, truncated replies, disconnect) must be
// reported as themselves. On a loaded machine the emulator's valve model can lag the
// commands by more than the default 1 s of schedule time, and the tracking fault then
// fires first (seen once in CI: "tracking fault on b1 ... for 1.19 s" before "reply
// timeout"). These tests therefore give that backstop 10 s. Rupture and leak
// detection (pressure_watch.h) keeps its defaults here; it and the backstop are
// tested by Rupture, StuckValve and test_player_safety.cpp.
constexpr double kCommsTrackingS = 10.0;

void expect_fault_handled(Rig& rig, int code, int expect_code, const std::string& text) {
  EXPECT_EQ(code, expect_code) << rig.err.str();
  EXPECT_NE(rig.err.str().find(text), std::string::npos) << rig.err.str();
  EXPECT_NE(rig.err.str().find("all channels vented"), std::string::npos) << rig.err.str();
  EXPECT_TRUE(rig.emu->all_vented());
  PressureTrace tr = read_pressure_log(rig.opt.log_path);
  EXPECT_TRUE(has_fault(tr, text)) << text;
  EXPECT_EQ(last_event(tr), "all channels vented");
  EXPECT_GE(tr.t.size(), 2u);  // samples up to the fault (a rupture is caught within 0.3 s: a few samples)
}

TEST(PlayerFault, GarbledReply) {
  EmulatorConfig cfg;
  cfg.faults.push_back(parse_fault("garble@3"));
  Rig rig("garble", false, cfg);
  rig.opt.tracking_fault_s = kCommsTrackingS;
  int code = rig.play(read_schedule(kExamples + "rolling.yaml"));
  expect_fault_handled(rig, code, kExitFault, "garbled reply");
}

TEST(PlayerFault, NoReply) {
  EmulatorConfig cfg;
  cfg.faults.push_back(parse_fault("silence@3:3"));  // 0.3 s wall of silence
  Rig rig("silence", true, cfg);
  rig.opt.tracking_fault_s = kCommsTrackingS;
  rig.opt.reply_timeout_s = 0.5;
  int code = rig.play(read_schedule(kExamples + "inching.yaml"));
  expect_fault_handled(rig, code, kExitFault, "reply timeout");
}

TEST(PlayerFault, TruncatedReply) {
  EmulatorConfig cfg;
  cfg.faults.push_back(parse_fault("drop@3"));
  Rig rig("drop", false, cfg);
  rig.opt.tracking_fault_s = kCommsTrackingS;
  rig.opt.reply_timeout_s = 0.3;
  int code = rig.play(read_schedule(kExamples + "rolling.yaml"));
  EXPECT_EQ(code, kExitFault);
  EXPECT_TRUE(rig.emu->all_vented());
}

TEST(PlayerFault, Disconnect) {
  EmulatorConfig cfg;
  cfg.faults.push_back(parse_fault("disconnect@3:1.0"));  // returns after 1 s wall, too late
  Rig rig("disconnect", false, cfg);
  rig.opt.tracking_fault_s = kCommsTrackingS;
  rig.opt.reconnect_s = 0.2;
  rig.opt.vent_reconnect_s = 10;
  int code = rig.play(read_schedule(kExamples + "rolling.yaml"));
  expect_fault_handled(rig, code, kExitFault, "device disconnected");
}

TEST(PlayerFault, PermanentDisconnectCannotVent) {
  EmulatorConfig cfg;
  cfg.faults.push_back(parse_fault("disconnect@3"));
  Rig rig("gone", true, cfg);
  rig.opt.reconnect_s = 0.2;
  rig.opt.vent_reconnect_s = 0.2;
  int code = rig.play(read_schedule(kExamples + "rolling.yaml"));
  EXPECT_EQ(code, kExitVentFailed);
  EXPECT_NE(rig.err.str().find("COULD NOT VENT"), std::string::npos) << rig.err.str();
}

TEST(PlayerFault, Rupture) {
  EmulatorConfig cfg;
  cfg.rupture_pa = 20000;  // below the 25 kPa the gait asks for: every bladder ruptures when inflated
  Rig rig("rupture", false, cfg);
  // The gait's own 1.237 s columns: b8 (column 1) ruptures on its ramp and is
  // caught by its pressure (hardware/pressure_watch.h) before b7 is inflated.
  int code = rig.play(read_schedule(kExamples + "rolling.yaml"));
  expect_fault_handled(rig, code, kExitFault, "tracking fault on b8");
  EXPECT_NE(rig.err.str().find("ruptured bladder"), std::string::npos);
  EXPECT_TRUE(rig.emu->channel(7).ruptured);
  for (int b = 0; b < 7; ++b) EXPECT_FALSE(rig.emu->channel(b).ruptured) << channel_name(b);
}

TEST(PlayerFault, StuckValve) {
  EmulatorConfig cfg;
  // With 3 s columns b1 is inflated in column 8 (21-24 s); its valve sticks
  // closed at 22.5 s, so it stays inflated when column 9 asks for 0 kPa. The
  // 1.5 s margins are 150 ms of wall time at the rig's 10x (with the gait's
  // 1.237 s columns they were 60 ms, too little on a loaded machine).
  cfg.faults.push_back(parse_fault("stuck@22.5:b1"));
  Rig rig("stuck", true, cfg);
  Schedule s = read_schedule(kExamples + "rolling.yaml");
  s.column_s = 3.0;
  int code = rig.play(s);
  EXPECT_TRUE(rig.emu->channel(0).stuck);
  EXPECT_EQ(code, kExitFault) << rig.err.str();
  EXPECT_NE(rig.err.str().find("tracking fault on b1"), std::string::npos) << rig.err.str();
  PressureTrace tr = read_pressure_log(rig.opt.log_path);
  EXPECT_TRUE(has_fault(tr, "tracking fault on b1"));
  EXPECT_EQ(last_event(tr), "all channels vented");  // every vent command was acknowledged
}

TEST(PlayerFault, Sigint) {
  Rig rig("sigint", false);
  rig.opt.handle_signals = true;
  int code = -1;
  std::atomic<bool> playing{true};
  std::thread player([&] {
    code = rig.play(read_schedule(kExamples + "rolling.yaml"));
    playing = false;
  });
  auto t0 = std::chrono::steady_clock::now();
  while (playing && rig.emu->requests() < 400 && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(20))
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  // Only while the player's handler is installed: after it returns, SIGINT would kill the test.
  bool sent = playing;
  if (sent) kill(getpid(), SIGINT);
  player.join();
  ASSERT_TRUE(sent) << "the player returned before SIGINT was sent: " << rig.err.str();
  expect_fault_handled(rig, code, kExitSigint, "stopped by SIGINT");
}

TEST(PlayerFault, ErrorReplyFromMissingUnit) {
  // The map names an I2C address no regulator answers: NACK at start-up.
  std::string dir = temp_dir("nack");
  ChannelMap real = parse_channel_map(map_text(dir, false), dir + "/map.yaml");
  std::string text = map_text(dir, false);
  text.replace(text.find("0x18"), 4, "0x30");
  ChannelMap wrong = parse_channel_map(text, dir + "/map.yaml");
  EmulatorConfig cfg;
  cfg.links = {{"bus", dir + "/bus"}, {"bridge", dir + "/bridge"}};
  Emulator emu(real, cfg);
  emu.start();
  PlayerOptions opt;
  std::ostringstream sink;
  opt.out = opt.err = &sink;
  opt.handle_signals = false;
  opt.reply_timeout_s = 1.0;
  opt.allow_map_override = true;
  // Refused at start-up, before any setpoint: exit 2, nothing to vent.
  EXPECT_EQ(play(read_schedule(kExamples + "rolling.yaml"), wrong, opt), kExitInput);
  EXPECT_NE(sink.str().find("no regulator at this address"), std::string::npos) << sink.str();
  EXPECT_NE(sink.str().find("nothing was sent"), std::string::npos) << sink.str();
  EXPECT_EQ(sink.str().find("COULD NOT VENT"), std::string::npos) << sink.str();
  for (auto& c : emu.snapshot()) EXPECT_EQ(c.max_pressure_pa, 0) << channel_name(c.channel);
  emu.stop();
  std::filesystem::remove_all(dir);
}
