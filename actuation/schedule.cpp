#include "actuation/schedule.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/errors.h"
#include "core/yaml_reader.h"

namespace morphfem {

namespace {

const std::array<std::string, kNumChannels> kChannelNames = {"b1", "b2", "b3",   "b4",     "b5",    "b6",
                                                             "b7", "b8", "core", "foot_a", "foot_b"};

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// YAML helpers (core/yaml_reader.h): every error names file:line:col and the key path.
using Reader = YamlReader;

std::vector<int> parse_row(const Reader& r, const YAML::Node& n, const std::string& key) {
  std::vector<int> row;
  if (n.IsScalar()) {
    for (char c : n.Scalar()) {
      if (c == ' ' || c == '_') continue;
      if (c != '0' && c != '1') r.fail(n, key, std::string("row must contain only 0 and 1, found '") + c + "'");
      row.push_back(c - '0');
    }
  } else if (n.IsSequence()) {
    for (std::size_t j = 0; j < n.size(); ++j)
      row.push_back(r.integer_in(n[j], key + "[" + std::to_string(j) + "]", 0, 1));
  } else {
    r.fail(n, key, "a row is a string of 0/1 or a list of 0/1");
  }
  if (row.empty()) r.fail(n, key, "row is empty");
  return row;
}

void parse_levels(const Reader& r, const YAML::Node& n, const std::string& key, ChannelLevels& lv, bool core) {
  if (core) {
    r.allow_only(n, key, {"pressure_pa", "ramp_s"});
    if (n["pressure_pa"]) lv.inflate_pa = r.number(n["pressure_pa"], key + ".pressure_pa");
    if (n["ramp_s"]) lv.inflate_ramp_s = lv.deflate_ramp_s = r.number_in(n["ramp_s"], key + ".ramp_s", 0, 1e6);
    return;
  }
  r.allow_only(n, key, {"inflate_pa", "deflate_pa", "ramp_s", "inflate_ramp_s", "deflate_ramp_s"});
  if (n["inflate_pa"]) lv.inflate_pa = r.number(n["inflate_pa"], key + ".inflate_pa");
  if (n["deflate_pa"]) lv.deflate_pa = r.number(n["deflate_pa"], key + ".deflate_pa");
  if (n["ramp_s"]) {
    if (n["inflate_ramp_s"] || n["deflate_ramp_s"])
      r.fail(n["ramp_s"], key + ".ramp_s", "give either ramp_s or inflate_ramp_s/deflate_ramp_s, not both");
    lv.inflate_ramp_s = lv.deflate_ramp_s = r.number_in(n["ramp_s"], key + ".ramp_s", 0, 1e6);
  }
  if (n["inflate_ramp_s"]) lv.inflate_ramp_s = r.number_in(n["inflate_ramp_s"], key + ".inflate_ramp_s", 0, 1e6);
  if (n["deflate_ramp_s"]) lv.deflate_ramp_s = r.number_in(n["deflate_ramp_s"], key + ".deflate_ramp_s", 0, 1e6);
}

Cadence parse_cadence(const Reader& r, const YAML::Node& n) {
  if (!n.IsMap()) r.fail(n, "cadence", "expected a mapping {mode: fixed|settle, min_hold_s: S, timeout_s: S}");
  r.allow_only(n, "cadence", {"mode", "min_hold_s", "timeout_s"});
  Cadence c;
  if (n["mode"]) {
    const std::string mode = r.text(n["mode"], "cadence.mode");
    if (mode == "settle")
      c.mode = Cadence::Mode::settle;
    else if (mode != "fixed")
      r.fail(n["mode"], "cadence.mode", "expected fixed or settle, got '" + mode + "'");
  }
  if (n["min_hold_s"]) c.min_hold_s = r.number_in(n["min_hold_s"], "cadence.min_hold_s", 0, 1e6);
  if (n["timeout_s"]) c.timeout_s = r.number_in(n["timeout_s"], "cadence.timeout_s", 1e-6, 1e6);
  return c;
}

}  // namespace

const std::string& channel_name(int channel) {
  static const std::string bad = "?";
  return (channel >= 0 && channel < kNumChannels) ? kChannelNames[channel] : bad;
}

int channel_index(const std::string& name) {
  for (int i = 0; i < kNumChannels; ++i)
    if (kChannelNames[i] == name) return i;
  return -1;
}

int channel_row(int channel) {
  if (channel >= 0 && channel < kNumBladders) return channel;
  if (channel == kChannelFootA) return 8;
  if (channel == kChannelFootB) return 9;
  return -1;
}

std::vector<int> genome_row(int f, int phi, int columns) {
  if (f < 0 || f > 8) throw std::invalid_argument("genome f must be in 0..8, got " + std::to_string(f));
  if (phi < 0 || phi > 8) throw std::invalid_argument("genome phi must be in 0..8, got " + std::to_string(phi));
  if (columns < 1) throw std::invalid_argument("a schedule needs at least one column");
  std::vector<int> row(columns, f == 0 ? 1 : 0);
  if (f == 0) return row;
  const int period = f + 1;
  const int first = phi + 1;  // 1-based anchor column
  // All c = first + k*period with 1 <= c <= columns, k any integer (positive or negative).
  int c = first - ((first - 1) / period) * period;  // smallest c >= 1 in the anchor's class
  if (c > columns) return row;
  for (; c <= columns; c += period) row[c - 1] = 1;
  return row;
}

ScheduleMatrix genome_matrix(const Genome& genome, int columns) {
  ScheduleMatrix m;
  for (auto& g : genome.rows) m.push_back(genome_row(g.f, g.phi, columns));
  return m;
}

double ChannelLevels::rise_rate() const {
  double swing = std::abs(inflate_pa - deflate_pa);
  return (inflate_ramp_s <= 0 || swing == 0) ? kInf : swing / inflate_ramp_s;
}

double ChannelLevels::fall_rate() const {
  double swing = std::abs(inflate_pa - deflate_pa);
  return (deflate_ramp_s <= 0 || swing == 0) ? kInf : swing / deflate_ramp_s;
}

double ramp_towards(double value, double target, double rise_rate, double fall_rate, double dt) {
  if (target > value) {
    if (std::isinf(rise_rate)) return target;
    return std::min(target, value + rise_rate * std::max(0.0, dt));
  }
  if (target < value) {
    if (std::isinf(fall_rate)) return target;
    return std::max(target, value - fall_rate * std::max(0.0, dt));
  }
  return value;
}

const char* cadence_mode_name(Cadence::Mode mode) { return mode == Cadence::Mode::settle ? "settle" : "fixed"; }

bool channel_settled(double pressure_pa, double setpoint_pa, double target_pa, double tolerance_pa) {
  return std::abs(setpoint_pa - target_pa) <= 0.5 && std::abs(pressure_pa - setpoint_pa) <= tolerance_pa;
}

std::array<ChannelLevels, kNumChannels> Schedule::default_levels(double core_pressure_pa) {
  std::array<ChannelLevels, kNumChannels> lv;
  for (int i = 0; i < kNumBladders; ++i) lv[i] = {25000.0, 0.0, 0.0, 0.0};
  lv[kChannelCore] = {core_pressure_pa, 0.0, 0.0, 0.0};
  lv[kChannelFootA] = lv[kChannelFootB] = {50000.0, -80000.0, 0.0, 0.0};
  return lv;
}

Schedule Schedule::from_matrix(ScheduleMatrix m, double column_s, int repeats, double orientation_deg,
                               double core_pressure_pa) {
  Schedule s;
  s.matrix = std::move(m);
  s.column_s = column_s;
  s.repeats = repeats;
  s.orientation_deg = orientation_deg;
  s.core_pressure_pa = core_pressure_pa;
  s.levels = default_levels(core_pressure_pa);
  s.validate();
  return s;
}

Schedule Schedule::from_genome(const Genome& g, double column_s, int repeats, int columns) {
  Schedule s = from_matrix(genome_matrix(g, columns), column_s, repeats, g.orientation_deg, g.core_pressure_pa);
  s.genome = g;
  return s;
}

void Schedule::validate() const {
  std::string w = source.empty() ? "schedule" : source;
  if (matrix.size() != kNumRows)
    throw InputError(w + ": matrix",
                     "expected " + std::to_string(kNumRows) + " rows, got " + std::to_string(matrix.size()));
  for (std::size_t i = 0; i < matrix.size(); ++i) {
    if (matrix[i].empty() || matrix[i].size() != matrix[0].size())
      throw InputError(
          w + ": matrix[" + std::to_string(i) + "]",
          "all rows must have the same non-zero length (row 1 has " + std::to_string(matrix[0].size()) + " columns)");
    for (int v : matrix[i])
      if (v != 0 && v != 1) throw InputError(w + ": matrix[" + std::to_string(i) + "]", "entries must be 0 or 1");
  }
  if (!(column_s > 0) || !std::isfinite(column_s)) throw InputError(w + ": column_s", "must be positive");
  if (repeats < 1) throw InputError(w + ": repeats", "must be at least 1");
  if (!(settle_s >= 0)) throw InputError(w + ": settle_s", "must be non-negative");
  if (orientation_deg < 0 || orientation_deg > 90) throw InputError(w + ": orientation_deg", "must be in 0..90");
  if (!(cadence.min_hold_s >= 0)) throw InputError(w + ": cadence.min_hold_s", "must not be negative");
  if (!(cadence.timeout_s > 0)) throw InputError(w + ": cadence.timeout_s", "must be positive");
  for (int c = 0; c < kNumChannels; ++c) {
    const auto& l = levels[c];
    if (!std::isfinite(l.inflate_pa) || !std::isfinite(l.deflate_pa))
      throw InputError(w + ": pressures." + channel_name(c), "pressures must be finite");
  }
}

bool Schedule::active(int row, int column) const {
  int T = columns();
  if (T == 0 || column < 0) return false;
  return matrix[row][column % T] != 0;
}

double Schedule::target_pa(int channel, int column, const std::array<ChannelLevels, kNumChannels>& lv) const {
  const ChannelLevels& l = lv[channel];
  if (channel == kChannelCore) return l.inflate_pa;
  int row = channel_row(channel);
  bool on;
  if (column < 0 || column >= total_columns())
    on = (row >= 8);  // rest: bladders off, feet active
  else
    on = active(row, column);
  return on ? l.inflate_pa : l.deflate_pa;
}

ScheduleState Schedule::at(double t, const std::array<ChannelLevels, kNumChannels>& lv) const {
  ScheduleState st;
  st.t = t;
  const int K = total_columns();
  int col = -1;
  if (t >= 0 && t < duration()) col = std::min(K - 1, static_cast<int>(std::floor(t / column_s)));
  st.column = col;
  for (int b = 0; b < kNumBladders; ++b) st.bladder_inflated[b] = col >= 0 && active(b, col);
  st.foot_a_active = col < 0 || active(8, col);
  st.foot_b_active = col < 0 || active(9, col);
  // Setpoints: start at the rest level at t = 0 and ramp column by column. The core
  // ramps from 0 at the start of settling (t = -settle_s).
  for (int c = 0; c < kNumChannels; ++c) {
    const ChannelLevels& l = lv[c];
    double rise = l.rise_rate(), fall = l.fall_rate();
    if (c == kChannelCore) {
      rise = (l.inflate_ramp_s > 0 && l.inflate_pa != 0) ? std::abs(l.inflate_pa) / l.inflate_ramp_s : kInf;
      fall = rise;
      st.pressure_pa[c] = ramp_towards(0.0, l.inflate_pa, rise, fall, t + settle_s);
      continue;
    }
    double v = target_pa(c, -1, lv);
    if (t >= 0) {
      int last = std::min(K, static_cast<int>(std::floor(t / column_s)));
      for (int k = 0; k < last; ++k) v = ramp_towards(v, target_pa(c, k, lv), rise, fall, column_s);
      double tau = t - last * column_s;
      v = ramp_towards(v, target_pa(c, last < K ? last : -1, lv), rise, fall, tau);
    }
    st.pressure_pa[c] = v;
  }
  return st;
}

std::string Schedule::to_yaml() const {
  std::ostringstream o;
  o.precision(10);
  o << "morphfem_schedule: 1\n";
  if (!name.empty()) o << "name: \"" << name << "\"\n";
  o << "orientation_deg: " << orientation_deg << "\ncore_pressure_pa: " << core_pressure_pa
    << "\ncolumn_s: " << column_s << "\nrepeats: " << repeats << "\nsettle_s: " << settle_s << "\n";
  if (cadence.mode == Cadence::Mode::settle)
    o << "cadence: {mode: settle, min_hold_s: " << cadence.min_hold_s << ", timeout_s: " << cadence.timeout_s << "}\n";
  o << "matrix:\n";
  for (auto& row : matrix) {
    o << "  - \"";
    for (int v : row) o << v;
    o << "\"\n";
  }
  o << "pressures:\n";
  for (int c = 0; c < kNumChannels; ++c) {
    const auto& l = levels[c];
    if (c == kChannelCore)
      o << "  core: {pressure_pa: " << l.inflate_pa << ", ramp_s: " << l.inflate_ramp_s << "}\n";
    else
      o << "  " << channel_name(c) << ": {inflate_pa: " << l.inflate_pa << ", deflate_pa: " << l.deflate_pa
        << ", inflate_ramp_s: " << l.inflate_ramp_s << ", deflate_ramp_s: " << l.deflate_ramp_s << "}\n";
  }
  return o.str();
}

Schedule parse_schedule(const std::string& text, const std::string& source) {
  Reader r{source};
  const YAML::Node root = load_yaml_text(text, source);
  if (!root.IsMap()) throw InputError(source, "a schedule file is a YAML mapping (key: value)");
  r.allow_only(root, "",
               {"morphfem_schedule", "name", "orientation_deg", "core_pressure_pa", "column_s", "repeats", "settle_s",
                "cadence", "matrix", "genome", "pressures"});
  if (!root["morphfem_schedule"])
    throw InputError(source, "missing required key 'morphfem_schedule' (format version, 1)");
  r.integer_in(root["morphfem_schedule"], "morphfem_schedule", 1, 1);

  Schedule s;
  s.source = source;
  if (root["name"]) s.name = r.text(root["name"], "name");
  if (root["orientation_deg"]) s.orientation_deg = r.number_in(root["orientation_deg"], "orientation_deg", 0, 90);
  if (root["core_pressure_pa"])
    // Gauge pressure: no lower than vacuum; the study's genome range is 0..12000 Pa, a
    // physical robot's core runs from its vacuum to its line pressure (-80 / 50 kPa).
    s.core_pressure_pa = r.number_in(root["core_pressure_pa"], "core_pressure_pa", -101325, 1e6);
  if (root["column_s"]) s.column_s = r.number_in(root["column_s"], "column_s", 1e-6, 1e6);
  if (root["repeats"]) s.repeats = r.integer_in(root["repeats"], "repeats", 1, 1000000);
  if (root["settle_s"]) s.settle_s = r.number_in(root["settle_s"], "settle_s", 0, 1e6);
  if (root["cadence"]) s.cadence = parse_cadence(r, root["cadence"]);

  const bool has_matrix = bool(root["matrix"]), has_genome = bool(root["genome"]);
  if (has_matrix == has_genome)
    throw InputError(source, has_matrix ? "give either 'matrix' or 'genome', not both"
                                        : "missing 'matrix' (10 rows of 0/1) or 'genome'");
  if (has_matrix) {
    YAML::Node m = root["matrix"];
    if (!m.IsSequence()) r.fail(m, "matrix", "expected a list of 10 rows");
    if (m.size() != kNumRows)
      r.fail(m, "matrix", "expected 10 rows (bladders 1-8, foot A, foot B), got " + std::to_string(m.size()));
    for (std::size_t i = 0; i < m.size(); ++i) {
      std::string key = "matrix[" + std::to_string(i) + "] (row " + std::to_string(i + 1) + ")";
      s.matrix.push_back(parse_row(r, m[i], key));
      if (s.matrix.back().size() != s.matrix[0].size())
        r.fail(m[i], key,
               "has " + std::to_string(s.matrix.back().size()) + " columns but row 1 has " +
                   std::to_string(s.matrix[0].size()));
    }
  } else {
    YAML::Node g = root["genome"];
    r.allow_only(g, "genome", {"orientation_deg", "core_pressure_pa", "columns", "rows"});
    Genome gen;
    gen.orientation_deg = s.orientation_deg;
    gen.core_pressure_pa = s.core_pressure_pa;
    if (g["orientation_deg"]) gen.orientation_deg = r.number_in(g["orientation_deg"], "genome.orientation_deg", 0, 90);
    if (g["core_pressure_pa"])
      gen.core_pressure_pa = r.number_in(g["core_pressure_pa"], "genome.core_pressure_pa", 0, 12000);
    int columns = g["columns"] ? r.integer_in(g["columns"], "genome.columns", 1, 10000) : 8;
    YAML::Node rows = g["rows"];
    if (!rows) r.fail(g, "genome", "missing 'rows' (10 pairs [f, phi])");
    if (!rows.IsSequence() || rows.size() != kNumRows)
      r.fail(rows, "genome.rows", "expected 10 pairs [f, phi], one per matrix row");
    for (std::size_t i = 0; i < kNumRows; ++i) {
      std::string key = "genome.rows[" + std::to_string(i) + "]";
      if (!rows[i].IsSequence() || rows[i].size() != 2) r.fail(rows[i], key, "expected a pair [f, phi]");
      gen.rows[i].f = r.integer_in(rows[i][0], key + ".f", 0, 8);
      gen.rows[i].phi = r.integer_in(rows[i][1], key + ".phi", 0, 8);
    }
    s.orientation_deg = gen.orientation_deg;
    s.core_pressure_pa = gen.core_pressure_pa;
    s.matrix = genome_matrix(gen, columns);
    s.genome = gen;
  }

  s.levels = Schedule::default_levels(s.core_pressure_pa);
  if (root["pressures"]) {
    YAML::Node p = root["pressures"];
    std::set<std::string> allowed = {"bladders", "feet", "core"};
    for (int c = 0; c < kNumChannels; ++c) allowed.insert(channel_name(c));
    r.allow_only(p, "pressures", allowed);
    // Group blocks first, then per-channel overrides.
    if (p["bladders"])
      for (int b = 0; b < kNumBladders; ++b) parse_levels(r, p["bladders"], "pressures.bladders", s.levels[b], false);
    if (p["feet"])
      for (int c : {kChannelFootA, kChannelFootB}) parse_levels(r, p["feet"], "pressures.feet", s.levels[c], false);
    for (int c = 0; c < kNumChannels; ++c)
      if (p[channel_name(c)])
        parse_levels(r, p[channel_name(c)], "pressures." + channel_name(c), s.levels[c], c == kChannelCore);
  }
  s.validate();
  return s;
}

Schedule read_schedule(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open schedule file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_schedule(ss.str(), path);
}

// ----------------------------------------------------------------------------
// Player log reader
// ----------------------------------------------------------------------------

namespace {
std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      out.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  out.push_back(cur);
  return out;
}

double interp(const std::vector<double>& t, const std::vector<double>& v, double time) {
  // Skip missing values: interpolate between the nearest finite neighbours.
  if (t.empty()) return kNaN;
  std::size_t hi = std::lower_bound(t.begin(), t.end(), time) - t.begin();
  std::ptrdiff_t a = static_cast<std::ptrdiff_t>(hi) - 1;
  while (a >= 0 && !std::isfinite(v[a])) --a;
  std::size_t b = hi;
  while (b < t.size() && !std::isfinite(v[b])) ++b;
  if (a < 0 && b >= t.size()) return kNaN;
  if (a < 0) return v[b];
  if (b >= t.size()) return v[a];
  if (t[b] == t[a]) return v[b];
  double w = (time - t[a]) / (t[b] - t[a]);
  return v[a] + w * (v[b] - v[a]);
}
}  // namespace

bool PressureTrace::has(int channel) const {
  for (int c : channels)
    if (c == channel) return true;
  return false;
}

double PressureTrace::measured_at(int channel, double time) const {
  for (std::size_t k = 0; k < channels.size(); ++k)
    if (channels[k] == channel) return interp(t, measured[k], time);
  return kNaN;
}

double PressureTrace::commanded_at(int channel, double time) const {
  for (std::size_t k = 0; k < channels.size(); ++k)
    if (channels[k] == channel) return interp(t, commanded[k], time);
  return kNaN;
}

ScheduleMatrix PressureTrace::to_matrix(double column_s, int columns,
                                        const std::array<ChannelLevels, kNumChannels>& lv) const {
  ScheduleMatrix m(kNumRows, std::vector<int>(columns, 0));
  for (int c = 0; c < kNumChannels; ++c) {
    int row = channel_row(c);
    if (row < 0 || !has(c)) continue;
    for (int k = 0; k < columns; ++k) {
      double p = commanded_at(c, (k + 0.5) * column_s);
      m[row][k] = std::abs(p - lv[c].inflate_pa) < std::abs(p - lv[c].deflate_pa) ? 1 : 0;
    }
  }
  return m;
}

PressureTrace read_pressure_log(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open log file");
  PressureTrace tr;
  tr.source = path;
  std::string line;
  int lineno = 0;
  bool header_seen = false;
  int i_t = -1, i_kind = -1, i_col = -1, i_msg = -1;
  std::vector<int> cmd_idx, meas_idx;
  std::size_t ncols = 0;
  while (std::getline(in, line)) {
    ++lineno;
    std::string where = path + ":" + std::to_string(lineno);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line[0] == '#') {
      auto colon = line.find(':');
      if (colon != std::string::npos) {
        auto trim = [](std::string s) {
          std::size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
          return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
        };
        tr.metadata.emplace_back(trim(line.substr(1, colon - 1)), trim(line.substr(colon + 1)));
      }
      continue;
    }
    auto f = split_csv(line);
    if (!header_seen) {
      header_seen = true;
      ncols = f.size();
      for (std::size_t j = 0; j < f.size(); ++j) {
        const std::string& h = f[j];
        if (h == "t_s")
          i_t = int(j);
        else if (h == "kind")
          i_kind = int(j);
        else if (h == "column")
          i_col = int(j);
        else if (h == "message")
          i_msg = int(j);
        else if (h.rfind("cmd_", 0) == 0 || h.rfind("meas_", 0) == 0) {
          bool cmd = h[0] == 'c';
          std::string name = h.substr(cmd ? 4 : 5);
          int ch = channel_index(name);
          if (ch < 0) throw InputError(where, "unknown channel '" + name + "' in column '" + h + "'");
          std::size_t k = 0;
          while (k < tr.channels.size() && tr.channels[k] != ch) ++k;
          if (k == tr.channels.size()) {
            tr.channels.push_back(ch);
            cmd_idx.push_back(-1);
            meas_idx.push_back(-1);
          }
          (cmd ? cmd_idx : meas_idx)[k] = int(j);
        } else {
          throw InputError(where, "unknown column '" + h + "' in the log header");
        }
      }
      if (i_t < 0 || i_kind < 0) throw InputError(where, "log header needs columns 't_s' and 'kind'");
      tr.commanded.assign(tr.channels.size(), {});
      tr.measured.assign(tr.channels.size(), {});
      continue;
    }
    if (f.size() != ncols) {
      // A crash can cut the last line short: accept the log up to there.
      if (in.peek() == EOF) break;
      throw InputError(where, "expected " + std::to_string(ncols) + " fields, got " + std::to_string(f.size()));
    }
    auto num = [&](int j, const char* what) {
      if (j < 0 || f[j].empty()) return kNaN;
      char* end = nullptr;
      double v = std::strtod(f[j].c_str(), &end);
      if (end != f[j].c_str() + f[j].size())
        throw InputError(where, std::string("bad number in ") + what + ": '" + f[j] + "'");
      return v;
    };
    double t = num(i_t, "t_s");
    if (!std::isfinite(t)) throw InputError(where, "missing time t_s");
    const std::string& kind = f[i_kind];
    if (kind == "sample") {
      if (!tr.t.empty() && t < tr.t.back()) throw InputError(where, "sample times must not decrease");
      tr.t.push_back(t);
      tr.column.push_back(i_col >= 0 && !f[i_col].empty() ? static_cast<int>(num(i_col, "column")) : -1);
      for (std::size_t k = 0; k < tr.channels.size(); ++k) {
        tr.commanded[k].push_back(num(cmd_idx[k], "cmd"));
        tr.measured[k].push_back(num(meas_idx[k], "meas"));
      }
    } else if (kind == "event" || kind == "fault") {
      tr.events.push_back({t, kind, i_msg >= 0 ? f[i_msg] : ""});
    } else {
      throw InputError(where, "unknown row kind '" + kind + "' (expected sample, event or fault)");
    }
  }
  if (!header_seen) throw InputError(path, "log has no header line");
  return tr;
}

}  // namespace morphfem
