// Channel map: which regulator drives each of the robot's eleven channels, and
// the pressures and limits the player must respect.
//
//   morphfem_channel_map: 1
//   devices:
//     bus:                         # a name used by channels below
//       protocol: alicat           # alicat | booth
//       port: /dev/ttyUSB0         # overridable with `play --port bus=/dev/...`
//       baud: 19200                # default 19200 (alicat), 115200 (booth)
//     bridge:
//       protocol: booth
//       port: /dev/ttyACM0
//       sensor_min_pa: -100000     # sensor transfer-function range (booth)
//       sensor_max_pa: 100000
//       half_band_pa: 500          # regulator dead band, register 21 (booth)
//   channels:                      # b1..b8, core, foot_a, foot_b; unmapped channels are not driven
//     b1: {device: bridge, address: 0x11, inflated_pa: 25000, deflated_pa: 0,
//          min_pa: -5000, max_pa: 35000, ramp_limit_pa_per_s: 200000, tolerance_pa: 2000}
//     core: {device: bus, address: A, inflated_pa: 50000, min_pa: -85000, max_pa: 55000}
//
// address: a unit ID letter A-Z (alicat) or an I2C address 1..127 (booth; 0x.. allowed).
// inflated_pa / deflated_pa (optional) replace the schedule's levels for "1" and
// "0" (for the core, inflated_pa replaces the held pressure). min_pa/max_pa are
// hard limits (required): a schedule that needs a pressure outside them is
// refused before anything is sent, and every command is clamped to them.
// ramp_limit_pa_per_s (default: none) limits how fast a setpoint may change;
// tolerance_pa (default 2000) is the settle tolerance of `--mode settle`;
// min_fill_rate_pa_per_s (default: the player's --min-fill-rate-pa-per-s) is the
// slowest rate at which the measured pressure may approach a setpoint it is
// more than 5 kPa away from before the player calls it a leak or rupture.
// The limits must lie inside the device's sensor range [sensor_min_pa,
// sensor_max_pa] (default -100..100 kPa, both protocols): beyond it the
// reading saturates and a Booth setpoint is clipped at 1023 counts.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "actuation/schedule.h"

namespace morphfem::hw {

enum class Protocol { alicat, booth };

struct DeviceSpec {
  std::string name;
  Protocol protocol = Protocol::alicat;
  std::string port;
  int baud = 19200;
  double sensor_min_pa = -100000;
  double sensor_max_pa = 100000;
  double half_band_pa = 500;
  std::string where;
};

struct ChannelSpec {
  int channel = -1;  // morphfem channel index (b1 = 0 ... foot_b = 10)
  std::string device;
  int address = 0;  // unit letter as its ASCII code (alicat) or I2C address (booth)
  std::optional<double> inflated_pa, deflated_pa;
  double min_pa = 0, max_pa = 0;
  double ramp_limit_pa_per_s = 0;                   // 0 = no limit
  double tolerance_pa = kDefaultSettleTolerancePa;  // settle mode (actuation/schedule.h, Cadence)
  std::optional<double> min_fill_rate_pa_per_s;
  std::string where;  // "file:line:col: channels.b1" for messages
};

// A pressure of the schedule that the map changes before it is commanded.
struct PressureChange {
  int channel = -1;
  int column = -1;          // matrix column 0..T-1; -1 = rest (settle phase and the end)
  double schedule_pa = 0;   // what the schedule asks for
  double commanded_pa = 0;  // what the player commands (NaN: the channel is not driven)
  std::string reason;       // "inflated_pa of channels.b1 (map.yaml:17:7)", ...
};

// The pressures commanded per channel and matrix column after the map.
struct PressurePlan {
  int columns = 0;  // T
  // [channel][0] = rest, [channel][1 + k] = matrix column k; commanded NaN = not driven.
  std::array<std::vector<double>, kNumChannels> schedule_pa, commanded_pa;
  std::vector<PressureChange> changes;  // every entry where the two differ

  // "b1 column 3: schedule 90.0 kPa, commanded 25.0 kPa (inflated_pa of ...)", one per line.
  std::string describe_changes() const;
  // Table: a row per channel, a column per matrix column (kPa), rest first.
  std::string table() const;
};

struct ChannelMap {
  std::string source;
  std::vector<DeviceSpec> devices;
  std::vector<ChannelSpec> channels;

  const DeviceSpec* device(const std::string& name) const;
  const ChannelSpec* find(int channel) const;
  // The schedule's levels with this map's inflated/deflated overrides applied.
  std::array<ChannelLevels, kNumChannels> effective_levels(const Schedule& s) const;
  // Throws InputError if the schedule asks for a pressure beyond a limit, or
  // inflates a channel the map does not drive. Nothing has been sent yet.
  void check_schedule(const Schedule& s) const;
  // What is commanded per channel and column, and every change the map makes
  // (level overrides, the core's held pressure, clamps, channels not driven).
  PressurePlan plan(const Schedule& s) const;
};

ChannelMap read_channel_map(const std::string& path);
ChannelMap parse_channel_map(const std::string& text, const std::string& source);

const char* protocol_name(Protocol p);

}  // namespace morphfem::hw
