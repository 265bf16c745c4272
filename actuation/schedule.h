// Actuation schedules: the file format shared by the simulator and the hardware
// player (hardware/), the (f, phi) genome row construction of the voxel study, and
// the time query "what is commanded at time t". Depends only on core/ and yaml-cpp.
//
// ---------------------------------------------------------------------------
// Schedule file (YAML). All pressures are gauge pressures in Pa, times in s.
//
//   morphfem_schedule: 1        # format version (required)
//   name: rolling               # optional label
//   orientation_deg: 0          # heading vs. uphill, 0..90 (default 0)
//   core_pressure_pa: 12000     # core gauge pressure, -101325..1e6 (default 0; genome: 0..12000)
//   column_s: 1.237             # duration of one column (default 1.237)
//   repeats: 2                  # the matrix is played this many times (default 1)
//   settle_s: 0                 # rest phase before column 1 (default 0)
//   matrix:                     # exactly 10 rows, all of the same length T >= 1
//     - "0000 0001"             #  row 1..8: outer bladder inflated (1) / deflated (0)
//     - [0,0,0,0,0,0,1,0]       #  a row is a string of 0/1 (spaces ignored) or a list
//     ...                       #  row 9: foot A friction active, row 10: foot B
//   # instead of `matrix`, a genome (T = 8 unless `columns` is given):
//   genome:
//     orientation_deg: 0        # overrides the top-level value
//     core_pressure_pa: 12000
//     columns: 8
//     rows: [[7, 7], [7, 6], ...]   # 10 pairs (f, phi), integers 0..8
//   cadence:                    # optional; how one column follows the next (below)
//     mode: settle              # fixed (default) or settle
//     min_hold_s: 0.5           # settle: shortest column (default 0)
//     timeout_s: 30             # settle: longest wait for the pressures (default 30)
//   pressures:                  # optional levels; defaults below
//     bladders: {inflate_pa: 25000, deflate_pa: 0, ramp_s: 0}     # all eight bladders
//     b3:       {inflate_pa: 30000}                                 # one bladder (b1..b8)
//     feet:     {inflate_pa: 50000, deflate_pa: -80000}            # both feet
//     foot_a:   {...}
//     foot_b:   {...}
//     core:     {pressure_pa: 12000, ramp_s: 2}                    # held for the whole run
//
// A level block accepts inflate_pa, deflate_pa, and either ramp_s (both
// directions) or inflate_ramp_s / deflate_ramp_s: the time the setpoint takes to
// move linearly across the full swing |inflate - deflate| (0 = a step). For the
// core, pressure_pa (default: core_pressure_pa) and ramp_s (time for the swing
// from 0 to pressure_pa).
//
// Time convention: the gait runs from t = 0 to duration() = columns*repeats*column_s;
// column k (0-based, over all repeats) covers [k*column_s, (k+1)*column_s) and
// uses matrix column k mod T. For t < 0 (settling) and t >= duration() the
// schedule is at rest: bladders deflated, all feet active (as in the voxel
// study's settle phases), the core at its pressure. A setpoint moves towards the
// level of the current column at its ramp rate starting from where it was, so it
// is continuous and piecewise linear; at t = 0 it starts from the rest level.
//
// Cadence: with mode fixed every column lasts column_s (the time convention
// above). With mode settle a column lasts until every driven channel has settled
// (channel_settled: its setpoint has reached the column's level and its pressure
// is within the channel's tolerance of it, tolerance_pa of the channel map,
// default 2000 Pa), and at least min_hold_s; the rest phase before column 1
// until every channel has settled and at least settle_s. A column that waits
// longer than timeout_s is a fault. The player (`morphfem hw play`) reads the
// regulators' pressures; the simulator the valve-fed cavities' (actuation/
// schedule_clock.h), so one file gives one cadence on the bench and in the model;
// column_s is then unused.
// ---------------------------------------------------------------------------
#pragma once
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace morphfem {

// The eleven pneumatic channels, in this order everywhere (logs, maps, arrays).
constexpr int kNumBladders = 8;
constexpr int kNumRows = 10;      // schedule matrix rows: 8 bladders + foot A + foot B
constexpr int kNumChannels = 11;  // 8 bladders, core, foot A, foot B
constexpr int kChannelCore = 8;
constexpr int kChannelFootA = 9;
constexpr int kChannelFootB = 10;

// "b1".."b8", "core", "foot_a", "foot_b".
const std::string& channel_name(int channel);
// Index of a channel name, or -1.
int channel_index(const std::string& name);
// Matrix row (0-based) driving a channel, or -1 for the core.
int channel_row(int channel);

using ScheduleMatrix = std::vector<std::vector<int>>;  // [row 0..9][column 0..T-1], 0/1

struct GenomeGene {
  int f = 0;    // 0..8
  int phi = 0;  // 0..8
};

struct Genome {
  double orientation_deg = 0;   // 0..90
  double core_pressure_pa = 0;  // 0..12000
  std::array<GenomeGene, kNumRows> rows{};
};

// ROBOT.md row construction with 1-based columns 1..T: f = 0 gives all ones;
// otherwise 1 at columns phi+1 + k(f+1) for every integer k, inside 1..T.
// Throws std::invalid_argument if f or phi is outside 0..8 or T < 1.
std::vector<int> genome_row(int f, int phi, int columns = 8);
ScheduleMatrix genome_matrix(const Genome& genome, int columns = 8);

// Pressure levels of one channel.
struct ChannelLevels {
  double inflate_pa = 0;      // "1" in the matrix (core: the held pressure)
  double deflate_pa = 0;      // "0" in the matrix (core: unused, always 0 before start)
  double inflate_ramp_s = 0;  // time to rise across the full swing (0 = step)
  double deflate_ramp_s = 0;  // time to fall across the full swing (0 = step)
  // Rates in Pa/s (infinite for a step or a zero swing).
  double rise_rate() const;
  double fall_rate() const;
};

// Moves `value` towards `target` for `dt` seconds at the given rates (Pa/s).
double ramp_towards(double value, double target, double rise_rate, double fall_rate, double dt);

// The cadence (schedule key `cadence`, see above).
constexpr double kDefaultSettleTolerancePa = 2000;  // a channel map's tolerance_pa if it gives none

struct Cadence {
  enum class Mode { fixed, settle };
  Mode mode = Mode::fixed;
  double min_hold_s = 0;  // settle: shortest column [s]
  double timeout_s = 30;  // settle: longest column [s]

  // Settle mode: whether column k (-1: the rest phase, which lasts at least rest_s)
  // may end after held_s [s], given whether every driven channel has settled.
  bool may_end(int column, double held_s, double rest_s, bool settled) const {
    return settled && held_s >= (column < 0 ? rest_s : min_hold_s);
  }
  // Settle mode: column k (not the rest phase) has waited longer than timeout_s.
  bool timed_out(int column, double held_s) const { return column >= 0 && held_s > timeout_s; }
};

// "fixed" or "settle".
const char* cadence_mode_name(Cadence::Mode mode);

// A channel has settled when its setpoint is within 0.5 Pa of the column's level
// (its ramp is over) and its pressure within tolerance_pa of the setpoint [Pa].
bool channel_settled(double pressure_pa, double setpoint_pa, double target_pa, double tolerance_pa);

struct ScheduleState {
  double t = 0;
  int column = -1;  // 0-based column over all repeats; -1 at rest (t < 0 or t >= duration)
  std::array<bool, kNumBladders> bladder_inflated{};
  bool foot_a_active = true;
  bool foot_b_active = true;
  std::array<double, kNumChannels> pressure_pa{};  // setpoint of every channel (with ramps)
};

class Schedule {
 public:
  std::string name;
  std::string source;  // file the schedule was read from ("" if built in code)
  double orientation_deg = 0;
  double core_pressure_pa = 0;
  double column_s = 1.237;
  int repeats = 1;
  double settle_s = 0;
  ScheduleMatrix matrix;         // 10 x T
  std::optional<Genome> genome;  // set when the file gave a genome
  Cadence cadence;
  std::array<ChannelLevels, kNumChannels> levels = default_levels(0);

  static std::array<ChannelLevels, kNumChannels> default_levels(double core_pressure_pa);
  // A schedule with default levels for the matrix (validated: 10 rows, equal length, 0/1).
  static Schedule from_matrix(ScheduleMatrix m, double column_s = 1.237, int repeats = 1, double orientation_deg = 0,
                              double core_pressure_pa = 0);
  static Schedule from_genome(const Genome& g, double column_s = 1.237, int repeats = 1, int columns = 8);

  int columns() const { return matrix.empty() ? 0 : static_cast<int>(matrix[0].size()); }
  int total_columns() const { return columns() * repeats; }
  double duration() const { return total_columns() * column_s; }
  // Matrix entry of row (0..9) in global column k (wraps over repeats).
  bool active(int row, int column) const;
  // Level the channel heads for during global column k (k = -1: rest level).
  double target_pa(int channel, int column) const { return target_pa(channel, column, levels); }
  double target_pa(int channel, int column, const std::array<ChannelLevels, kNumChannels>& lv) const;
  // The commanded state at gait time t (see the time convention above).
  ScheduleState at(double t) const { return at(t, levels); }
  // Same with other levels (the hardware player substitutes the channel map's).
  ScheduleState at(double t, const std::array<ChannelLevels, kNumChannels>& lv) const;
  // Throws InputError (naming `source`) if the schedule is inconsistent.
  void validate() const;
  // Writes the schedule as a file this reader accepts (matrix form).
  std::string to_yaml() const;
};

// Reads a schedule file; every error names file:line:column, the key and the problem.
Schedule read_schedule(const std::string& path);
Schedule parse_schedule(const std::string& text, const std::string& source);

// ---------------------------------------------------------------------------
// Player log (written by hardware/player.cpp), read back for real-to-sim replay.
// CSV, '#' lines are comments ("# key: value" metadata, e.g. "# column_s: 1.237").
// Header: t_s,kind,column,cmd_<channel>...,meas_<channel>...,message
// kind is "sample" (pressures filled), "event" or "fault" (pressures may be empty).
// ---------------------------------------------------------------------------
struct PressureTrace {
  std::string source;
  std::vector<int> channels;                   // channel indices present in the log
  std::vector<double> t;                       // sample times (gait time, s)
  std::vector<int> column;                     // column of each sample (-1 = rest)
  std::vector<std::vector<double>> commanded;  // [k][i] for channels[k]; NaN if missing
  std::vector<std::vector<double>> measured;
  struct Event {
    double t;
    std::string kind, message;
  };
  std::vector<Event> events;
  std::vector<std::pair<std::string, std::string>> metadata;

  bool has(int channel) const;
  // Linear interpolation in time (clamped at the ends); NaN if the channel is absent.
  double measured_at(int channel, double time) const;
  double commanded_at(int channel, double time) const;
  double duration() const { return t.empty() ? 0 : t.back(); }
  // Binary matrix recovered from the commanded pressures: a row is 1 in a column
  // when the commanded pressure at the column's midpoint is nearer to inflate_pa
  // than to deflate_pa of `levels`. Columns of length column_s from t = 0.
  ScheduleMatrix to_matrix(double column_s, int columns, const std::array<ChannelLevels, kNumChannels>& levels) const;
};

PressureTrace read_pressure_log(const std::string& path);

}  // namespace morphfem
