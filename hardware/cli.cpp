#include "hardware/cli.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <set>
#include <thread>

#include "actuation/schedule.h"
#include "core/errors.h"
#include "hardware/channel_map.h"
#include "hardware/emulator.h"
#include "hardware/player.h"
#include "hardware/protocols.h"

namespace morphfem {

namespace {

using namespace hw;

const char* kUsage =
    "usage: morphfem hw check SCHEDULE [--map MAP [--allow-map-override]]\n"
    "       morphfem hw play SCHEDULE --map MAP [options]\n"
    "       morphfem hw emulate --map MAP [options]\n"
    "       morphfem hw COMMAND --help     options of one command\n"
    "Exit codes: 0 done, 2 refused or devices not reached (nothing sent), 3 device or pressure fault\n"
    "(all channels vented), 4 a pressurised channel could not be vented, 5 columns lost (all channels\n"
    "vented), 130 SIGINT, 143 SIGTERM. See hardware/README.md.\n";

const char* kCheckUsage =
    "usage: morphfem hw check SCHEDULE [--map MAP] [--allow-map-override]\n"
    "Reads the schedule and prints its matrix; with a map, the pressures commanded per channel and\n"
    "column after the map, and refuses (exit 2) pressures beyond the map's limits and, without\n"
    "--allow-map-override, a map that changes any of the schedule's pressures (as hw play would).\n"
    "  --map MAP               channel map (hardware/channel_map.h)\n"
    "  --allow-map-override    accept the map's changes; they are listed\n";

const char* kPlayUsage =
    "usage: morphfem hw play SCHEDULE --map MAP [options]\n"
    "  --port [DEVICE=]PATH           serial port of a device of the map (every device without DEVICE=)\n"
    "  --mode fixed|settle|step       fixed column times; advance when settled; Enter = next, q = stop\n"
    "                                 (default: the schedule's cadence.mode, else fixed)\n"
    "  --allow-map-override           play a schedule whose pressures the map changes (changes are listed)\n"
    "  --time-scale S                 schedule seconds per wall second (default 1; give the emulator the same)\n"
    "  --tick-ms N                    wall ms between exchanges (default 20 / S, at least 5)\n"
    "  --reply-timeout-ms N           wait for a reply (default 300)\n"
    "  --reconnect-s S                wait for a vanished port while playing (default 2)\n"
    "  --max-gap-s S                  schedule s without a completed exchange that lose columns (default 0.5)\n"
    "  --continue-after-gap           play on after lost columns (logged and summarised, exit 0)\n"
    "  --leak-window-s S              rupture/leak detection window, schedule s (default 0.15)\n"
    "  --leak-off-pa P                |setpoint - measured| that counts as off (default 5000)\n"
    "  --leak-drop-pa P               fall away from a held setpoint that trips (default 5000)\n"
    "  --min-fill-rate-pa-per-s R     slowest approach to a setpoint when off (default 20000; map key\n"
    "                                 min_fill_rate_pa_per_s per channel)\n"
    "  --tracking-fault-pa P          backstop: |measured - commanded| ... (default 15000)\n"
    "  --tracking-fault-s S           ... for this long, schedule s (default 1)\n"
    "  --tracking-fault-samples N     ... over this many consecutive exchanges (default 5)\n"
    "  --settle-timeout-s S           settle mode: longest column (default: cadence.timeout_s, else 30)\n"
    "  --min-hold-s S                 settle mode: shortest column (default: cadence.min_hold_s, else 0)\n"
    "  --log FILE.csv                 CSV log (format: actuation/schedule.h)\n"
    "  --dry-run                      print the command stream; open no port\n"
    "  --no-display                   no live pressure line on stderr\n";

const char* kEmulateUsage =
    "usage: morphfem hw emulate --map MAP [options]\n"
    "Serves every device of the map on a pseudo-terminal (path printed per device) until SIGINT/SIGTERM.\n"
    "  --link DEVICE=PATH        symlink to the device's pty (kept across reconnections)\n"
    "  --time-scale S            emulated seconds per wall second (default 1)\n"
    "  --seed N                  noise seed (default 1)\n"
    "  --noise-pa P              sensor noise, standard deviation (default 60)\n"
    "  --rupture-pa P            bladder rupture pressure (default 60000)\n"
    "  --valve-fill-time-s T     the simulator's valve law on a rigid chamber, time constant T (default:\n"
    "                            the regulator model; hardware/emulator.h)\n"
    "  --fault KIND@T[:ARG]      garble, drop, silence, delay, disconnect, stuck, rupture (hardware/emulator.h)\n"
    "  --duration-s S            stop after S wall seconds\n";

std::atomic<bool> g_emulate_stop{false};
extern "C" void on_emulate_signal(int) { g_emulate_stop = true; }

double number_arg(const std::string& opt, const std::string& v) {
  char* end = nullptr;
  double x = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || !std::isfinite(x))
    throw InputError(opt, "expected a number, got '" + v + "'");
  return x;
}

double positive_arg(const std::string& opt, const std::string& v) {
  const double x = number_arg(opt, v);
  if (!(x > 0)) throw InputError(opt, "must be positive, got '" + v + "'");
  return x;
}

double nonnegative_arg(const std::string& opt, const std::string& v) {
  const double x = number_arg(opt, v);
  if (!(x >= 0)) throw InputError(opt, "must not be negative, got '" + v + "'");
  return x;
}

int count_arg(const std::string& opt, const std::string& v) {
  const double n = number_arg(opt, v);
  if (!(n >= 1 && n == std::floor(n) && n < 1e9)) throw InputError(opt, "must be a positive integer, got '" + v + "'");
  return static_cast<int>(n);
}

// "DEVICE=PATH" -> {DEVICE, PATH}; without '=' the device is "" (allowed only if `bare_ok`).
std::pair<std::string, std::string> device_path(const std::string& opt, const std::string& v, bool bare_ok) {
  const auto eq = v.find('=');
  if (eq == std::string::npos) {
    if (!bare_ok) throw InputError(opt, "expected DEVICE=PATH, got '" + v + "'");
    if (v.empty()) throw InputError(opt, "expected a path");
    return {"", v};
  }
  std::pair<std::string, std::string> r{v.substr(0, eq), v.substr(eq + 1)};
  if (r.first.empty() || r.second.empty()) throw InputError(opt, "expected DEVICE=PATH, got '" + v + "'");
  return r;
}

struct Option {
  std::string name;
  bool takes_value;
  std::function<void(const std::string&)> set;
};

// Applies `args` (after the command) to the options; returns the positional arguments.
std::vector<std::string> parse_options(const std::string& cmd, const std::vector<std::string>& args,
                                       const std::vector<Option>& options) {
  std::vector<std::string> positional;
  std::set<std::string> seen;
  const std::set<std::string> repeatable = {"--port", "--link", "--fault"};
  for (std::size_t i = 1; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.empty() || a[0] != '-') {
      positional.push_back(a);
      continue;
    }
    const Option* o = nullptr;
    for (const Option& c : options)
      if (c.name == a) o = &c;
    if (!o) throw InputError(a, "unknown option for 'hw " + cmd + "' (see morphfem hw " + cmd + " --help)");
    if (!seen.insert(a).second && !repeatable.count(a)) throw InputError(a, "given twice");
    if (!o->takes_value) {
      o->set("");
    } else {
      if (i + 1 >= args.size()) throw InputError(a, "missing value");
      o->set(args[++i]);
    }
  }
  return positional;
}

void print_matrix(const Schedule& s, std::ostream& o) {
  const char* names[] = {"b1", "b2", "b3", "b4", "b5", "b6", "b7", "b8", "foot_a", "foot_b"};
  for (int r = 0; r < kNumRows; ++r) {
    o << "  " << names[r] << (r < 8 ? "     " : " ");
    for (int v : s.matrix[r]) o << (v ? '1' : '.');
    o << "\n";
  }
}

int run_check(const std::vector<std::string>& args) {
  std::string map_path;
  bool allow_override = false;
  auto pos = parse_options("check", args,
                           {{"--map", true, [&](const std::string& v) { map_path = v; }},
                            {"--allow-map-override", false, [&](const std::string&) { allow_override = true; }}});
  if (pos.size() != 1) throw InputError("hw check", "expected one schedule file (see morphfem hw check --help)");
  Schedule s = read_schedule(pos[0]);
  std::cout << s.source << ": " << s.columns() << " columns x " << s.column_s << " s, " << s.repeats
            << " repeats = " << s.duration() << " s; orientation " << s.orientation_deg << " deg, core "
            << s.core_pressure_pa << " Pa\n";
  print_matrix(s, std::cout);
  if (map_path.empty()) {
    PressurePlan p = ChannelMap{}.plan(s);
    p.commanded_pa = p.schedule_pa;
    std::cout << "schedule pressures (no map given):\n" << p.table();
    return kExitOk;
  }
  ChannelMap m = read_channel_map(map_path);
  m.check_schedule(s);
  const PressurePlan plan = m.plan(s);
  std::cout << map_path << ": " << m.channels.size() << " channels on " << m.devices.size()
            << " devices; every pressure within limits\n"
            << "pressures commanded after the map (- = not driven):\n"
            << plan.table();
  for (const auto& d : m.devices)
    if (d.protocol == Protocol::booth)
      std::cout << "  (" << d.name << ": Booth setpoints in steps of "
                << booth::Sensor{d.sensor_min_pa, d.sensor_max_pa}.resolution_pa() << " Pa)\n";
  if (plan.changes.empty()) {
    std::cout << "the map plays the schedule's pressures unchanged\n";
    return kExitOk;
  }
  const std::string what =
      "the map changes " + std::to_string(plan.changes.size()) + " pressure(s) (channel and column) of the schedule";
  if (!allow_override)
    throw InputError(map_path, "hw play would refuse this schedule: " + what + ":\n" + plan.describe_changes() +
                                   "give --allow-map-override to play them as listed");
  std::cout << what << " (--allow-map-override):\n" << plan.describe_changes();
  return kExitOk;
}

std::vector<Option> play_options(PlayerOptions& po, std::string& map_path) {
  auto mode = [&](const std::string& m) {
    if (m == "fixed")
      po.mode = PlayerOptions::Mode::fixed;
    else if (m == "settle")
      po.mode = PlayerOptions::Mode::settle;
    else if (m == "step")
      po.mode = PlayerOptions::Mode::step;
    else
      throw InputError("--mode", "expected fixed, settle or step, got '" + m + "'");
  };
  auto flag = [](bool& b) { return [&b](const std::string&) { b = true; }; };
  auto pos = [](const char* o, double& x, double unit = 1) {
    return [o, &x, unit](const std::string& v) { x = positive_arg(o, v) * unit; };
  };
  return {
      {"--map", true, [&](const std::string& v) { map_path = v; }},
      {"--port", true,
       [&](const std::string& v) {
         auto [device, path] = device_path("--port", v, true);
         if (po.ports.count(device)) throw InputError("--port", "device '" + device + "' given twice");
         po.ports[device] = path;
       }},
      {"--mode", true, mode},
      {"--allow-map-override", false, flag(po.allow_map_override)},
      {"--time-scale", true, pos("--time-scale", po.time_scale)},
      {"--tick-ms", true, pos("--tick-ms", po.tick_s, 0.001)},
      {"--reply-timeout-ms", true, pos("--reply-timeout-ms", po.reply_timeout_s, 0.001)},
      {"--reconnect-s", true, pos("--reconnect-s", po.reconnect_s)},
      {"--max-gap-s", true, pos("--max-gap-s", po.max_gap_s)},
      {"--continue-after-gap", false, flag(po.continue_after_gap)},
      {"--leak-window-s", true, pos("--leak-window-s", po.watch.window_s)},
      {"--leak-off-pa", true, pos("--leak-off-pa", po.watch.off_pa)},
      {"--leak-drop-pa", true, pos("--leak-drop-pa", po.watch.drop_pa)},
      {"--min-fill-rate-pa-per-s", true, pos("--min-fill-rate-pa-per-s", po.watch.min_rate_pa_per_s)},
      {"--tracking-fault-pa", true, pos("--tracking-fault-pa", po.tracking_fault_pa)},
      {"--tracking-fault-s", true, pos("--tracking-fault-s", po.tracking_fault_s)},
      {"--tracking-fault-samples", true,
       [&](const std::string& v) { po.tracking_fault_samples = count_arg("--tracking-fault-samples", v); }},
      {"--settle-timeout-s", true, pos("--settle-timeout-s", po.settle_timeout_s)},
      {"--min-hold-s", true, [&](const std::string& v) { po.min_hold_s = nonnegative_arg("--min-hold-s", v); }},
      {"--log", true, [&](const std::string& v) { po.log_path = v; }},
      {"--dry-run", false, flag(po.dry_run)},
      {"--no-display", false, [&](const std::string&) { po.display = false; }},
  };
}

// The options apply over the schedule's cadence: read the schedule, then them.
int run_play(const std::vector<std::string>& args) {
  PlayerOptions checked;
  std::string map_path;
  auto pos = parse_options("play", args, play_options(checked, map_path));
  if (pos.size() != 1) throw InputError("hw play", "expected one schedule file (see morphfem hw play --help)");
  if (map_path.empty()) throw InputError("hw play", "--map MAP is required");
  Schedule s = read_schedule(pos[0]);
  PlayerOptions po;
  po.display = isatty(2);
  take_cadence(s.cadence, po);
  parse_options("play", args, play_options(po, map_path));
  ChannelMap m = read_channel_map(map_path);
  return play(s, m, po);
}

// Serves the emulator until SIGINT/SIGTERM or duration_s wall seconds (< 0: no limit).
void serve_emulator(Emulator& emu, double duration_s) {
  auto paths = emu.start();
  for (auto& [dev, path] : paths) std::cout << dev << " " << path << "\n";
  std::cout << std::flush;
  g_emulate_stop = false;
  struct sigaction sa {
  }, old_int{}, old_term{};
  sa.sa_handler = on_emulate_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  auto t0 = std::chrono::steady_clock::now();
  while (!g_emulate_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (duration_s > 0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > duration_s)
      break;
  }
  emu.stop();
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
}

int run_emulate(const std::vector<std::string>& args) {
  EmulatorConfig ec;
  std::string map_path;
  double duration_s = -1;
  auto pos = parse_options(
      "emulate", args,
      {{"--map", true, [&](const std::string& v) { map_path = v; }},
       {"--link", true,
        [&](const std::string& v) {
          auto [device, path] = device_path("--link", v, false);
          if (ec.links.count(device)) throw InputError("--link", "device '" + device + "' given twice");
          ec.links[device] = path;
        }},
       {"--time-scale", true, [&](const std::string& v) { ec.time_scale = positive_arg("--time-scale", v); }},
       {"--seed", true, [&](const std::string& v) { ec.seed = static_cast<std::uint64_t>(count_arg("--seed", v)); }},
       {"--noise-pa", true, [&](const std::string& v) { ec.noise_pa = nonnegative_arg("--noise-pa", v); }},
       {"--rupture-pa", true, [&](const std::string& v) { ec.rupture_pa = positive_arg("--rupture-pa", v); }},
       {"--valve-fill-time-s", true,
        [&](const std::string& v) { ec.valve_fill_time_s = positive_arg("--valve-fill-time-s", v); }},
       {"--fault", true, [&](const std::string& v) { ec.faults.push_back(parse_fault(v)); }},
       {"--duration-s", true, [&](const std::string& v) { duration_s = positive_arg("--duration-s", v); }}});
  if (!pos.empty())
    throw InputError("hw emulate", "unexpected argument '" + pos[0] + "' (see morphfem hw emulate --help)");
  if (map_path.empty()) throw InputError("hw emulate", "--map MAP is required");
  ChannelMap m = read_channel_map(map_path);
  for (auto& [device, path] : ec.links)
    if (!m.device(device))
      throw InputError("--link " + device + "=" + path,
                       "the map " + map_path + " has no device named '" + device + "'");
  Emulator emu(m, ec);
  serve_emulator(emu, duration_s);
  return kExitOk;
}

bool wants_help(const std::vector<std::string>& args) {
  for (std::size_t i = 1; i < args.size(); ++i)
    if (args[i] == "--help" || args[i] == "-h") return true;
  return false;
}

}  // namespace

int hardware_main(const std::vector<std::string>& args) {
  if (args.empty()) {
    std::cerr << kUsage;
    return kExitInput;
  }
  const std::string& cmd = args[0];
  if (cmd == "-h" || cmd == "--help") {
    std::cout << kUsage;
    return kExitOk;
  }
  try {
    if (cmd == "check") return wants_help(args) ? (std::cout << kCheckUsage, kExitOk) : run_check(args);
    if (cmd == "play") return wants_help(args) ? (std::cout << kPlayUsage, kExitOk) : run_play(args);
    if (cmd == "emulate") return wants_help(args) ? (std::cout << kEmulateUsage, kExitOk) : run_emulate(args);
    throw InputError("hw", "unknown command '" + cmd + "' (check, play, emulate; see morphfem hw --help)");
  } catch (const InputError& e) {
    std::cerr << "morphfem hw: " << e.what() << "\n";
    return kExitInput;
  } catch (const std::exception& e) {
    std::cerr << "morphfem hw: " << e.what() << "\n";
    return kExitFault;
  }
}

}  // namespace morphfem
