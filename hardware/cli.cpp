#include "hardware/cli.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <thread>

#include "actuation/schedule.h"
#include "core/errors.h"
#include "hardware/channel_map.h"
#include "hardware/emulator.h"
#include "hardware/player.h"

namespace morphfem {

namespace {

const char* kUsage =
    "usage: morphfem hw check SCHEDULE [--map MAP]\n"
    "       morphfem hw play SCHEDULE --map MAP [--port [DEVICE=]PATH]... [--mode fixed|settle|step]\n"
    "                        [--time-scale S] [--tick-ms N] [--reply-timeout-ms N] [--reconnect-s S]\n"
    "                        [--settle-timeout-s S] [--min-hold-s S] [--tracking-fault-pa P] [--tracking-fault-s S]\n"
    "                        [--tracking-fault-samples N]\n"
    "                        [--log FILE.csv] [--dry-run] [--no-display]\n"
    "       morphfem hw emulate --map MAP [--link DEVICE=PATH]... [--time-scale S] [--seed N]\n"
    "                        [--noise-pa P] [--rupture-pa P] [--fault KIND@T[:ARG]]... [--duration-s S]\n";

std::atomic<bool> g_emulate_stop{false};
extern "C" void on_emulate_signal(int) { g_emulate_stop = true; }

double number_arg(const std::string& opt, const std::string& v) {
  char* end = nullptr;
  double x = std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size()) throw InputError(opt, "expected a number, got '" + v + "'");
  return x;
}

void print_matrix(const Schedule& s, std::ostream& o) {
  const char* names[] = {"b1", "b2", "b3", "b4", "b5", "b6", "b7", "b8", "foot_a", "foot_b"};
  for (int r = 0; r < kNumRows; ++r) {
    o << "  " << names[r] << (r < 8 ? "     " : " ");
    for (int v : s.matrix[r]) o << (v ? '1' : '.');
    o << "\n";
  }
}

}  // namespace

int hardware_main(const std::vector<std::string>& args) {
  using namespace hw;
  if (args.empty() || args[0] == "-h" || args[0] == "--help") {
    std::cerr << kUsage;
    return args.empty() ? kExitInput : 0;
  }
  const std::string cmd = args[0];
  std::vector<std::string> pos;
  std::string map_path;
  PlayerOptions po;
  po.display = isatty(2);
  EmulatorConfig ec;
  double duration_s = -1;
  try {
    for (std::size_t i = 1; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= args.size()) throw InputError(a, "missing value");
        return args[++i];
      };
      auto split = [](const std::string& v, std::string& key, std::string& val) {
        auto eq = v.find('=');
        if (eq == std::string::npos) {
          key = "";
          val = v;
        } else {
          key = v.substr(0, eq);
          val = v.substr(eq + 1);
        }
      };
      if (a == "--map")
        map_path = value();
      else if (a == "--port") {
        std::string k, v;
        split(value(), k, v);
        po.ports[k] = v;
      } else if (a == "--mode") {
        std::string m = value();
        if (m == "fixed")
          po.mode = PlayerOptions::Mode::fixed;
        else if (m == "settle")
          po.mode = PlayerOptions::Mode::settle;
        else if (m == "step")
          po.mode = PlayerOptions::Mode::step;
        else
          throw InputError("--mode", "expected fixed, settle or step, got '" + m + "'");
      } else if (a == "--time-scale") {
        po.time_scale = ec.time_scale = number_arg(a, value());
        if (!(po.time_scale > 0)) throw InputError(a, "must be positive");
      } else if (a == "--tick-ms")
        po.tick_s = number_arg(a, value()) / 1000;
      else if (a == "--reply-timeout-ms")
        po.reply_timeout_s = number_arg(a, value()) / 1000;
      else if (a == "--reconnect-s")
        po.reconnect_s = number_arg(a, value());
      else if (a == "--settle-timeout-s")
        po.settle_timeout_s = number_arg(a, value());
      else if (a == "--tracking-fault-pa")
        po.tracking_fault_pa = number_arg(a, value());
      else if (a == "--tracking-fault-s")
        po.tracking_fault_s = number_arg(a, value());
      else if (a == "--tracking-fault-samples") {
        const double n = number_arg(a, value());
        if (!(n >= 1 && n == static_cast<int>(n))) throw InputError(a, "must be a positive integer");
        po.tracking_fault_samples = static_cast<int>(n);
      } else if (a == "--min-hold-s")
        po.min_hold_s = number_arg(a, value());
      else if (a == "--log")
        po.log_path = value();
      else if (a == "--dry-run")
        po.dry_run = true;
      else if (a == "--no-display")
        po.display = false;
      else if (a == "--link") {
        std::string k, v;
        split(value(), k, v);
        ec.links[k] = v;
      } else if (a == "--seed")
        ec.seed = static_cast<std::uint64_t>(number_arg(a, value()));
      else if (a == "--noise-pa")
        ec.noise_pa = number_arg(a, value());
      else if (a == "--rupture-pa")
        ec.rupture_pa = number_arg(a, value());
      else if (a == "--fault")
        ec.faults.push_back(parse_fault(value()));
      else if (a == "--duration-s")
        duration_s = number_arg(a, value());
      else if (!a.empty() && a[0] == '-')
        throw InputError(a, "unknown option");
      else
        pos.push_back(a);
    }

    if (cmd == "check") {
      if (pos.size() != 1) throw InputError("check", "expected one schedule file");
      Schedule s = read_schedule(pos[0]);
      std::cout << s.source << ": " << s.columns() << " columns x " << s.column_s << " s, " << s.repeats
                << " repeats = " << s.duration() << " s; orientation " << s.orientation_deg << " deg, core "
                << s.core_pressure_pa << " Pa\n";
      print_matrix(s, std::cout);
      if (!map_path.empty()) {
        ChannelMap m = read_channel_map(map_path);
        m.check_schedule(s);
        std::cout << map_path << ": " << m.channels.size() << " channels on " << m.devices.size()
                  << " devices; every pressure within limits\n";
      }
      return 0;
    }
    if (cmd == "play") {
      if (pos.size() != 1) throw InputError("play", "expected one schedule file");
      if (map_path.empty()) throw InputError("play", "--map MAP is required");
      Schedule s = read_schedule(pos[0]);
      ChannelMap m = read_channel_map(map_path);
      return play(s, m, po);
    }
    if (cmd == "emulate") {
      if (map_path.empty()) throw InputError("emulate", "--map MAP is required");
      ChannelMap m = read_channel_map(map_path);
      Emulator emu(m, ec);
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
      return 0;
    }
    throw InputError("hw", "unknown subcommand '" + cmd + "' (check, play, emulate)");
  } catch (const InputError& e) {
    std::cerr << "morphfem hw: " << e.what() << "\n";
    return kExitInput;
  } catch (const std::exception& e) {
    std::cerr << "morphfem hw: " << e.what() << "\n";
    return kExitFault;
  }
}

}  // namespace morphfem
