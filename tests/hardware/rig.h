// Test rig shared by the hardware tests: temporary directories, channel maps,
// the emulator on pseudo-terminals with a player configured against it, and
// the CLI with its output captured.
#pragma once
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "actuation/schedule.h"
#include "hardware/channel_map.h"
#include "hardware/cli.h"
#include "hardware/emulator.h"
#include "hardware/player.h"

namespace hwtest {

using namespace morphfem;
using namespace morphfem::hw;

inline const std::string kExamples = std::string(MORPHFEM_SOURCE_DIR) + "/examples/schedules/";

inline std::string temp_dir(const std::string& name) {
  std::string d = std::string(MORPHFEM_BINARY_DIR) + "/test_hw_" + name + "_" + std::to_string(getpid());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// Mixed map: bladders on Booth regulators, core and feet on an Alicat line.
// all_alicat: every channel on the Alicat line (unit IDs A..K). core_override:
// the map holds the core at 30 kPa whatever the schedule says.
inline std::string map_text(const std::string& dir, bool all_alicat, double bladder_max = 35000,
                            bool core_override = true) {
  std::ostringstream m;
  m << "morphfem_channel_map: 1\ndevices:\n"
    << "  bus: {protocol: alicat, port: " << dir << "/bus}\n";
  if (!all_alicat) m << "  bridge: {protocol: booth, port: " << dir << "/bridge, half_band_pa: 300}\n";
  m << "channels:\n";
  for (int b = 0; b < 8; ++b) {
    m << "  b" << b + 1 << ": {device: " << (all_alicat ? "bus" : "bridge") << ", address: ";
    if (all_alicat)
      m << char('D' + b);
    else
      m << "0x" << std::hex << 0x11 + b << std::dec;
    m << ", min_pa: -5000, max_pa: " << bladder_max << "}\n";
  }
  m << "  core: {device: bus, address: A, " << (core_override ? "inflated_pa: 30000, " : "")
    << "min_pa: -85000, max_pa: 55000}\n"
    << "  foot_a: {device: bus, address: B, min_pa: -85000, max_pa: 55000}\n"
    << "  foot_b: {device: bus, address: C, min_pa: -85000, max_pa: 55000}\n";
  return m.str();
}

struct RigSetup {
  bool all_alicat = false;
  bool core_override = true;  // the map holds the core at 30 kPa (played with --allow-map-override)
  double time_scale = 10;
  // Wall seconds between exchanges. 0.02 (0.2 s of schedule time at 10x) for the
  // gait and fault tests of test_player.cpp; 0 = the player's default (0.02 / time
  // scale, at least 5 ms) for the detection-bound tests. On a loaded 2-core host
  // the 5 ms tick at 10x is preempted more often: the gait tests' column
  // evidence failed 4 in 12 runs at load average 12 with it, 0 in 12 with 0.02.
  double tick_s = 0.02;
};

// The emulator on pseudo-terminals (links dir/bus, dir/bridge) and player options
// against it (the map's changes allowed when the map holds the core).
struct Rig {
  std::string dir;
  ChannelMap map;
  std::unique_ptr<Emulator> emu;
  PlayerOptions opt;
  std::ostringstream out, err;

  Rig(const std::string& name, bool all_alicat, EmulatorConfig cfg = {}, RigSetup setup = {}) {
    setup.all_alicat = all_alicat;
    dir = temp_dir(name);
    map = parse_channel_map(map_text(dir, setup.all_alicat, 35000, setup.core_override), dir + "/map.yaml");
    cfg.time_scale = setup.time_scale;
    cfg.seed = 7;
    cfg.links = {{"bus", dir + "/bus"}, {"bridge", dir + "/bridge"}};
    emu = std::make_unique<Emulator>(map, cfg);
    emu->start();
    opt.time_scale = setup.time_scale;
    opt.tick_s = setup.tick_s;
    opt.reply_timeout_s = 1.0;
    // Columns are lost after 0.5 s of wall time without an exchange: the player's
    // default, 0.5 s of schedule time, at 1x; 5 s at 10x, where a loaded test host
    // (load average 16 on 2 cores seen) stalls the player for 50-500 ms now and
    // then. The gap tests disconnect for 0.8-1 s of wall time.
    opt.max_gap_s = 0.5 * setup.time_scale;
    opt.allow_map_override = setup.core_override;
    opt.log_path = dir + "/log.csv";
    opt.handle_signals = false;
    opt.out = &out;
    opt.err = &err;
  }
  ~Rig() {
    emu->stop();
    std::filesystem::remove_all(dir);
  }
  int play(const Schedule& s) { return hw::play(s, map, opt); }
};

struct CliResult {
  int code = -1;
  std::string out, err;
  double wall_s = 0;
};

// Runs `morphfem hw ARGS` with standard output and error captured.
inline CliResult run_cli(const std::vector<std::string>& args) {
  CliResult r;
  std::ostringstream out, err;
  auto* old_out = std::cout.rdbuf(out.rdbuf());
  auto* old_err = std::cerr.rdbuf(err.rdbuf());
  auto t0 = std::chrono::steady_clock::now();
  r.code = hardware_main(args);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout.rdbuf(old_out);
  std::cerr.rdbuf(old_err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

}  // namespace hwtest
