// Schedule player: plays a schedule file on the regulators of a channel map.
//
// Safety rules (enforced in play()):
//  * the schedule is checked against the map's limits before any port is opened
//    (ChannelMap::check_schedule), and refused if the map would change any of its
//    pressures (ChannelMap::plan) unless allow_map_override; every command is
//    clamped to [min_pa, max_pa] and slew-limited by ramp_limit_pa_per_s;
//  * a port that cannot be opened or a regulator that does not answer at start-up
//    ends the run before any setpoint is sent (kExitInput);
//  * on an error reply, a garbled reply, a reply timeout, a disconnect that does
//    not come back within reconnect_s, a pressure fault (hardware/pressure_watch.h:
//    rupture, leak, stuck valve; or the slower tracking fault below), lost
//    columns (no completed exchange for longer than max_gap_s, unless
//    continue_after_gap), SIGINT/SIGTERM, a user stop or the end of the
//    schedule, every channel is vented to atmosphere before returning;
//  * the CSV log (format: actuation/schedule.h, read_pressure_log) is flushed at
//    least every 0.5 s wall time and at every event, so a crash loses < 1 s.
#pragma once
#include <iosfwd>
#include <map>
#include <string>

#include "actuation/schedule.h"
#include "hardware/channel_map.h"
#include "hardware/pressure_watch.h"

namespace morphfem::hw {

// Exit codes of play() and `morphfem hw play`.
constexpr int kExitOk = 0;
constexpr int kExitInput = 2;       // refused, or the devices could not be reached: nothing was sent
constexpr int kExitFault = 3;       // device or pressure fault; all channels vented
constexpr int kExitVentFailed = 4;  // a pressurised channel's vent could not be confirmed
constexpr int kExitLost = 5;        // columns lost (commands or readings missing); all channels vented
constexpr int kExitSigint = 130;
constexpr int kExitSigterm = 143;

struct PlayerOptions {
  // fixed and settle: the schedule's cadence (take_cadence; `hw play` overrides it
  // with --mode, --min-hold-s, --settle-timeout-s); step: a key advances.
  enum class Mode { fixed, settle, step } mode = Mode::fixed;
  double time_scale = 1;                     // schedule seconds per wall second (tests: 10)
  double tick_s = 0;                         // wall seconds between control ticks (0: 0.02 / time_scale,
                                             // at least 0.005: a sample every 0.02 s of schedule time at 1x)
  double reply_timeout_s = 0.3;              // wall seconds to wait for a reply
  double reconnect_s = 2.0;                  // wall seconds to wait for a vanished port while playing
  double vent_reconnect_s = 5.0;             // ... and before venting after a fault
  double settle_timeout_s = 30;              // settle mode: schedule seconds a column may wait
  double min_hold_s = 0;                     // settle mode: minimum column time
  double tracking_fault_pa = 15000;          // |measured - commanded| that counts as a fault ...
  double tracking_fault_s = 1.0;             // ... when it lasts this long (schedule seconds)
  int tracking_fault_samples = 5;            // ... over at least this many consecutive exchanges: one
                                             // late sample after a host stall is no evidence of a fault
  WatchSettings watch;                       // rupture and leak detection (pressure_watch.h); the map's
                                             // min_fill_rate_pa_per_s overrides watch.min_rate_pa_per_s
  double max_gap_s = 0.5;                    // schedule seconds without a completed exchange that lose columns
  bool continue_after_gap = false;           // play on after lost columns (logged, summary, exit 0)
  bool allow_map_override = false;           // play a schedule whose pressures the map changes (printed)
  bool dry_run = false;                      // print the command stream, open no port
  bool display = false;                      // live commanded/measured line on `err`
  std::string log_path;                      // CSV log ("" = none)
  std::map<std::string, std::string> ports;  // device name -> port path override
  int step_fd = 0;                           // step mode: a byte (Enter) advances, 'q' stops
  bool handle_signals = true;                // install SIGINT/SIGTERM handlers during play
  std::ostream* out = nullptr;               // dry-run command stream, summary (default std::cout)
  std::ostream* err = nullptr;               // messages, live display (default std::cerr)
};

// The schedule's cadence (schedule key `cadence`) as options: mode, min_hold_s,
// settle_timeout_s.
void take_cadence(const Cadence& cadence, PlayerOptions& options);

// Plays the schedule; returns one of the exit codes above. Throws InputError
// (nothing sent) if the schedule, the map or an option is refused.
int play(const Schedule& schedule, const ChannelMap& map, const PlayerOptions& options);

}  // namespace morphfem::hw
