// Regulator emulator: serves both wire protocols (hardware/protocols.h) on a
// pseudo-terminal (posix_openpt) per device of a channel map, and models every
// channel's pressure: a valve whose flow fills a volume from the supply or
// empties it to vacuum, venting to atmosphere, sensor quantisation and noise,
// bladder rupture above a limit, and injected faults.
//
// Pressure model per channel (gauge Pa, emulated time t):
//   regulate: u = clamp((setpoint - p) / valve_band_pa, -1, 1)
//             dp/dt = u (supply_pa - p) / tau_s     if u > 0
//             dp/dt = u (p - vacuum_pa) / tau_s     if u < 0
//   vent:     dp/dt = -p / vent_tau_s
//   hold:     dp/dt = 0
//   ruptured: the bladder leaks: dp/dt += -p / leak_tau_s, for ever.
// With valve_fill_time_s > 0, regulate is instead the simulator's valve model
// (actuation/gas_cavity.h) on a rigid chamber: the regulator's output holds the
// setpoint and fills the chamber through a linear conductance C, so
//             dp/dt = (setpoint - p) / valve_fill_time_s,
// valve_fill_time_s = tau = V / (C R T) (a scene's actuation.valves.fill_time_s).
// A channel ruptures when p exceeds rupture_pa. Measured pressure = p + N(0,
// noise_pa), quantised (10 Pa for alicat, 10-bit sensor counts for booth).
// Emulated time runs time_scale times faster than the wall clock.
//
// Faults (`--fault` spec "kind@t[:arg]", t in emulated seconds since the first
// request the emulator received):
//   garble@t[:n]      the next n replies (default 1) are corrupted
//   drop@t[:n]        the last byte of the next n replies is dropped (truncated frame)
//   silence@t[:s]     no replies for s emulated seconds (default for ever);
//                     commands are still carried out
//   delay@t:ms        every reply after t is delayed by ms wall milliseconds
//   disconnect@t[:s]  the pty is closed; after s wall seconds a new one appears
//                     behind the same link path (default: never returns)
//   stuck@t:channel   the channel's valve sticks closed (holds its pressure, ignores commands)
//   rupture@t:channel the channel's bladder ruptures
#pragma once
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "hardware/channel_map.h"
#include "hardware/protocols.h"

namespace morphfem::hw {

struct EmulatorFault {
  enum Kind { garble, drop, silence, delay, disconnect, stuck, rupture } kind = garble;
  double at_s = 0;
  double arg = 0;    // count, seconds or milliseconds depending on kind
  int channel = -1;  // stuck, rupture
  bool fired = false;
};

// Parses "kind@t[:arg]"; throws InputError naming `where` on a bad spec.
EmulatorFault parse_fault(const std::string& spec, const std::string& where = "--fault");

struct EmulatorConfig {
  double time_scale = 1;
  std::uint64_t seed = 1;
  double supply_pa = 150000;
  double vacuum_pa = -95000;
  double tau_s = 0.12;
  double valve_fill_time_s = 0;  // > 0: the valve model instead of the regulator's (above)
  double valve_band_pa = 4000;
  double vent_tau_s = 0.06;
  double leak_tau_s = 0.004;
  double noise_pa = 60;
  double rupture_pa = 60000;        // bladders (b1..b8)
  double rupture_core_pa = 120000;  // core and feet
  std::vector<EmulatorFault> faults;
  // Device name -> path of a symlink to its pty (kept across reconnections).
  std::map<std::string, std::string> links;
};

struct EmulatedChannelState {
  int channel = -1;
  double pressure_pa = 0;
  double setpoint_pa = 0;
  int mode = 0;  // 0 vent, 1 regulate, 2 hold
  bool ruptured = false;
  bool stuck = false;
  long commands = 0;
  double max_pressure_pa = 0;
  // Emulated seconds since the first request (the clock of --fault times); -1: never.
  double ruptured_at_s = -1;  // the bladder ruptured (pressure limit or fault)
  double vented_at_s = -1;    // first write of the Booth "vent" state (the player's vent)
};

class Emulator {
 public:
  Emulator(ChannelMap map, EmulatorConfig config);
  ~Emulator();
  // Opens one pty per device and starts the service thread. Returns
  // device name -> path the player should open (the link if configured).
  std::map<std::string, std::string> start();
  void stop();

  std::vector<EmulatedChannelState> snapshot() const;
  EmulatedChannelState channel(int ch) const;
  // True when every channel is venting, or regulating to 0 Pa.
  bool all_vented() const;
  long requests() const { return requests_.load(); }
  double emulated_time() const;

 private:
  struct Device;
  struct Chan;
  void loop();
  void step_physics(double dt);
  void open_pty(Device& d);
  void close_pty(Device& d);
  void serve(Device& d, double now_wall);
  void handle_alicat(Device& d, const std::string& line);
  void handle_booth(Device& d, const booth::Frame& f);
  void send(Device& d, std::vector<std::uint8_t> bytes);
  double measure(const Chan& c, Protocol p);
  void fire_faults(double now_wall);
  void flush_replies(Device& d, double now_wall);
  double fault_clock() const { return t_first_request_ < 0 ? 0 : t_emu_ - t_first_request_; }

  ChannelMap map_;
  EmulatorConfig cfg_;
  std::vector<std::unique_ptr<Device>> devices_;
  std::vector<std::unique_ptr<Chan>> chans_;
  mutable std::mutex mu_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<long> requests_{0};
  std::mt19937_64 rng_;
  double t_emu_ = 0;
  double t_first_request_ = -1;
  double last_wall_ = 0;
  // fault state
  int garble_left_ = 0, drop_left_ = 0;
  double silence_until_ = -1;
  double delay_ms_ = 0;
};

}  // namespace morphfem::hw
