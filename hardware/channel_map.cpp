#include "hardware/channel_map.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/yaml_reader.h"

namespace morphfem::hw {

namespace {

using MapReader = YamlReader;
constexpr double kNotDriven = std::numeric_limits<double>::quiet_NaN();

}  // namespace

const char* protocol_name(Protocol p) { return p == Protocol::alicat ? "alicat" : "booth"; }

const DeviceSpec* ChannelMap::device(const std::string& name) const {
  for (auto& d : devices)
    if (d.name == name) return &d;
  return nullptr;
}

const ChannelSpec* ChannelMap::find(int channel) const {
  for (auto& c : channels)
    if (c.channel == channel) return &c;
  return nullptr;
}

std::array<ChannelLevels, kNumChannels> ChannelMap::effective_levels(const Schedule& s) const {
  auto lv = s.levels;
  for (auto& c : channels) {
    if (c.inflated_pa) lv[c.channel].inflate_pa = *c.inflated_pa;
    if (c.deflated_pa && c.channel != kChannelCore) lv[c.channel].deflate_pa = *c.deflated_pa;
  }
  return lv;
}

void ChannelMap::check_schedule(const Schedule& s) const {
  auto lv = effective_levels(s);
  const std::string sw = s.source.empty() ? "schedule" : s.source;
  for (int ch = 0; ch < kNumChannels; ++ch) {
    int row = channel_row(ch);
    bool uses_on = false, uses_off = false;
    if (ch == kChannelCore) {
      uses_on = true;
    } else {
      for (int k = 0; k < s.columns(); ++k) (s.matrix[row][k] ? uses_on : uses_off) = true;
      if (row >= 8)
        uses_on = true;  // feet are active while settling and at rest
      else
        uses_off = true;  // bladders are deflated at rest
    }
    const ChannelSpec* c = find(ch);
    if (!c) {
      bool needed = ch == kChannelCore ? lv[ch].inflate_pa != 0 : (row < 8 ? uses_on : false);
      if (needed)
        throw InputError(source + ": channels",
                         "schedule " + sw + " drives channel " + channel_name(ch) + " but the map has no such channel");
      continue;
    }
    auto check = [&](double p, const char* what) {
      if (p < c->min_pa || p > c->max_pa)
        throw InputError(c->where, std::string("refused before sending anything: schedule ") + sw + " needs " + what +
                                       " pressure " + format_number(p) + " Pa on " + channel_name(ch) +
                                       ", outside this channel's limits [" + format_number(c->min_pa) + ", " +
                                       format_number(c->max_pa) + "] Pa");
    };
    if (uses_on) check(lv[ch].inflate_pa, ch == kChannelCore ? "core" : "inflate");
    if (uses_off && ch != kChannelCore) check(lv[ch].deflate_pa, "deflate");
    if (0 < c->min_pa || 0 > c->max_pa) throw InputError(c->where, "limits must include 0 Pa (venting to atmosphere)");
  }
}

namespace {

std::string kpa_text(double pa) {
  if (!std::isfinite(pa)) return "not driven";
  char b[32];
  std::snprintf(b, sizeof b, "%.1f kPa", pa / 1000.0);
  return b;
}

// "rest", "column 3", "columns 3-5", "rest and columns 1-8" for columns first..last (-1 = rest).
std::string columns_name(int first, int last) {
  std::string rest = first < 0 ? "rest" : "";
  if (first < 0) first = 0;
  if (last < first) return rest;
  std::string cols = first == last ? "column " + std::to_string(first + 1)
                                   : "columns " + std::to_string(first + 1) + "-" + std::to_string(last + 1);
  return rest.empty() ? cols : rest + " and " + cols;
}

bool same_change(const PressureChange& a, const PressureChange& b) {
  auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  return a.channel == b.channel && b.column == a.column + 1 && same(a.schedule_pa, b.schedule_pa) &&
         same(a.commanded_pa, b.commanded_pa) && a.reason == b.reason;
}

// Why the map commands `commanded` where the schedule asks for `wanted`.
std::string change_reason(const ChannelSpec* c, bool inflated, double wanted, double effective, double commanded) {
  if (!c) return "the map has no such channel: it is not driven";
  std::string r;
  if (effective != wanted) {
    const char* key = c->channel == kChannelCore || inflated ? "inflated_pa" : "deflated_pa";
    r = std::string(key) + " of " + c->where;
    if (c->channel == kChannelCore) r += " (the core's held pressure)";
  }
  if (commanded != effective) r += std::string(r.empty() ? "" : "; ") + "clamped to this channel's limits";
  return r;
}

}  // namespace

PressurePlan ChannelMap::plan(const Schedule& s) const {
  PressurePlan p;
  p.columns = s.columns();
  const auto lv = effective_levels(s);
  for (int ch = 0; ch < kNumChannels; ++ch) {
    const ChannelSpec* c = find(ch);
    const int row = channel_row(ch);
    for (int k = -1; k < p.columns; ++k) {
      const double wanted = s.target_pa(ch, k, s.levels);
      const double effective = s.target_pa(ch, k, lv);
      const double commanded = c ? std::clamp(effective, c->min_pa, c->max_pa) : kNotDriven;
      p.schedule_pa[ch].push_back(wanted);
      p.commanded_pa[ch].push_back(commanded);
      const bool differs = c ? std::abs(commanded - wanted) > 0.5 : wanted != 0;
      if (!differs) continue;
      const bool on = row >= 0 && (k < 0 ? row >= 8 : s.active(row, k));
      p.changes.push_back({ch, k, wanted, commanded, change_reason(c, on, wanted, effective, commanded)});
    }
  }
  return p;
}

std::string PressurePlan::describe_changes() const {
  std::ostringstream o;
  for (std::size_t i = 0; i < changes.size();) {
    std::size_t j = i;  // consecutive columns with the same change are one line
    while (j + 1 < changes.size() && same_change(changes[j], changes[j + 1])) ++j;
    const PressureChange& c = changes[i];
    o << "  " << channel_name(c.channel) << " " << columns_name(c.column, changes[j].column) << ": schedule "
      << kpa_text(c.schedule_pa) << ", commanded " << kpa_text(c.commanded_pa) << " (" << c.reason << ")\n";
    i = j + 1;
  }
  return o.str();
}

std::string PressurePlan::table() const {
  std::ostringstream o;
  char b[32];
  std::snprintf(b, sizeof b, "  %-15s %6s", "kPa", "rest");
  o << b;
  for (int k = 0; k < columns; ++k) {
    std::snprintf(b, sizeof b, " %6d", k + 1);
    o << b;
  }
  o << "\n";
  for (int ch = 0; ch < kNumChannels; ++ch) {
    std::snprintf(b, sizeof b, "  %-15s", channel_name(ch).c_str());
    o << b;
    for (double v : commanded_pa[ch]) {
      if (std::isfinite(v))
        std::snprintf(b, sizeof b, " %6.1f", v / 1000.0);
      else
        std::snprintf(b, sizeof b, " %6s", "-");
      o << b;
    }
    o << "\n";
  }
  return o.str();
}

namespace {

DeviceSpec parse_device(MapReader& r, const std::string& name, const YAML::Node& n) {
  DeviceSpec d;
  d.name = name;
  const std::string key = "devices." + d.name;
  r.allow_only(n, key, {"protocol", "port", "baud", "sensor_min_pa", "sensor_max_pa", "half_band_pa"});
  d.where = r.where(n, key);
  if (!n["protocol"]) r.fail(n, key, "missing 'protocol' (alicat or booth)");
  std::string proto = r.text(n["protocol"], key + ".protocol");
  if (proto == "alicat")
    d.protocol = Protocol::alicat;
  else if (proto == "booth")
    d.protocol = Protocol::booth;
  else
    r.fail(n["protocol"], key + ".protocol", "unknown protocol '" + proto + "' (expected alicat or booth)");
  d.baud = d.protocol == Protocol::alicat ? 19200 : 115200;
  if (n["port"]) d.port = r.text(n["port"], key + ".port");
  if (n["baud"]) {
    double b = r.number(n["baud"], key + ".baud");
    static const std::set<double> ok = {9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600};
    if (!ok.count(b)) r.fail(n["baud"], key + ".baud", "unsupported baud rate " + format_number(b));
    d.baud = static_cast<int>(b);
  }
  if (n["sensor_min_pa"]) d.sensor_min_pa = r.number(n["sensor_min_pa"], key + ".sensor_min_pa");
  if (n["sensor_max_pa"]) d.sensor_max_pa = r.number(n["sensor_max_pa"], key + ".sensor_max_pa");
  if (d.sensor_max_pa <= d.sensor_min_pa) r.fail(n, key, "sensor_max_pa must exceed sensor_min_pa");
  if (n["half_band_pa"]) d.half_band_pa = r.number(n["half_band_pa"], key + ".half_band_pa");
  if (d.half_band_pa < 0) r.fail(n["half_band_pa"], key + ".half_band_pa", "must be non-negative");
  return d;
}

int parse_address(MapReader& r, const YAML::Node& n, const std::string& key, const DeviceSpec& d) {
  std::string a = r.text(n, key);
  if (d.protocol == Protocol::alicat) {
    if (a.size() != 1 || a[0] < 'A' || a[0] > 'Z')
      r.fail(n, key, "an alicat unit ID is one letter A-Z, got '" + a + "'");
    return a[0];
  }
  char* end = nullptr;
  long v = std::strtol(a.c_str(), &end, 0);
  if (a.empty() || end != a.c_str() + a.size() || v < 1 || v > 127)
    r.fail(n, key, "an I2C address is an integer 1..127, got '" + a + "'");
  return static_cast<int>(v);
}

std::string range_text(double lo, double hi) { return "[" + format_number(lo) + ", " + format_number(hi) + "] Pa"; }

// Hard limits: present, ordered, including 0 Pa, inside the device's sensor range.
void parse_limits(MapReader& r, const YAML::Node& n, const std::string& key, const DeviceSpec& d, ChannelSpec& c) {
  if (!n["min_pa"] || !n["max_pa"]) r.fail(n, key, "hard limits 'min_pa' and 'max_pa' are required");
  c.min_pa = r.number(n["min_pa"], key + ".min_pa");
  c.max_pa = r.number(n["max_pa"], key + ".max_pa");
  if (c.max_pa <= c.min_pa) r.fail(n["max_pa"], key + ".max_pa", "max_pa must exceed min_pa");
  if (c.min_pa > 0 || c.max_pa < 0)
    r.fail(n["min_pa"], key + ".min_pa", "limits must include 0 Pa (venting to atmosphere)");
  const std::string sensor = " the sensor range " + range_text(d.sensor_min_pa, d.sensor_max_pa) + " of device " +
                             d.name + " (devices." + d.name + ".sensor_min_pa/sensor_max_pa)";
  if (c.max_pa > d.sensor_max_pa)
    r.fail(n["max_pa"], key + ".max_pa",
           format_number(c.max_pa) + " Pa is above" + sensor + ": the reading would saturate and the setpoint clip");
  if (c.min_pa < d.sensor_min_pa)
    r.fail(n["min_pa"], key + ".min_pa",
           format_number(c.min_pa) + " Pa is below" + sensor + ": the reading would saturate and the setpoint clip");
}

double positive(MapReader& r, const YAML::Node& n, const std::string& key) {
  double v = r.number(n, key);
  if (!(v > 0)) r.fail(n, key, "must be positive");
  return v;
}

ChannelSpec parse_channel(MapReader& r, const ChannelMap& m, const YAML::Node& name_node, const YAML::Node& n) {
  ChannelSpec c;
  const std::string name = name_node.Scalar();
  const std::string key = "channels." + name;
  c.channel = channel_index(name);
  if (c.channel < 0) r.fail(name_node, key, "unknown channel '" + name + "' (b1..b8, core, foot_a, foot_b)");
  if (m.find(c.channel)) r.fail(name_node, key, "channel listed twice");
  r.allow_only(n, key,
               {"device", "address", "inflated_pa", "deflated_pa", "min_pa", "max_pa", "ramp_limit_pa_per_s",
                "tolerance_pa", "min_fill_rate_pa_per_s"});
  c.where = r.where(n, key);
  if (!n["device"]) r.fail(n, key, "missing 'device'");
  c.device = r.text(n["device"], key + ".device");
  const DeviceSpec* d = m.device(c.device);
  if (!d) r.fail(n["device"], key + ".device", "no device named '" + c.device + "' under devices");
  if (!n["address"]) r.fail(n, key, "missing 'address'");
  c.address = parse_address(r, n["address"], key + ".address", *d);
  parse_limits(r, n, key, *d, c);
  for (const char* k : {"inflated_pa", "deflated_pa"}) {
    if (!n[k]) continue;
    double v = r.number(n[k], key + "." + k);
    if (v < c.min_pa || v > c.max_pa)
      r.fail(n[k], key + "." + k,
             format_number(v) + " Pa is outside this channel's limits " + range_text(c.min_pa, c.max_pa));
    (std::string(k) == "inflated_pa" ? c.inflated_pa : c.deflated_pa) = v;
  }
  if (n["ramp_limit_pa_per_s"])
    c.ramp_limit_pa_per_s = positive(r, n["ramp_limit_pa_per_s"], key + ".ramp_limit_pa_per_s");
  if (n["tolerance_pa"]) c.tolerance_pa = positive(r, n["tolerance_pa"], key + ".tolerance_pa");
  if (n["min_fill_rate_pa_per_s"])
    c.min_fill_rate_pa_per_s = positive(r, n["min_fill_rate_pa_per_s"], key + ".min_fill_rate_pa_per_s");
  return c;
}

}  // namespace

ChannelMap parse_channel_map(const std::string& text, const std::string& source) {
  MapReader r{source};
  const YAML::Node root = load_yaml_text(text, source);
  if (!root.IsMap()) throw InputError(source, "a channel map is a YAML mapping");
  r.allow_only(root, "", {"morphfem_channel_map", "devices", "channels"});
  if (!root["morphfem_channel_map"])
    throw InputError(source, "missing required key 'morphfem_channel_map' (version, 1)");
  if (r.number(root["morphfem_channel_map"], "morphfem_channel_map") != 1)
    r.fail(root["morphfem_channel_map"], "morphfem_channel_map", "unsupported version (expected 1)");
  ChannelMap m;
  m.source = source;
  YAML::Node devs = root["devices"];
  if (!devs || !devs.IsMap() || devs.size() == 0)
    throw InputError(source + ": devices", "expected at least one device");
  for (auto it = devs.begin(); it != devs.end(); ++it)
    m.devices.push_back(parse_device(r, it->first.Scalar(), it->second));
  YAML::Node chans = root["channels"];
  if (!chans || !chans.IsMap() || chans.size() == 0)
    throw InputError(source + ": channels", "expected at least one channel (b1..b8, core, foot_a, foot_b)");
  std::set<std::pair<std::string, int>> used;
  for (auto it = chans.begin(); it != chans.end(); ++it) {
    ChannelSpec c = parse_channel(r, m, it->first, it->second);
    if (!used.insert({c.device, c.address}).second)
      r.fail(it->second["address"], "channels." + it->first.Scalar() + ".address",
             "address '" + r.text(it->second["address"], "address") + "' is already used on device " + c.device);
    m.channels.push_back(c);
  }
  return m;
}

ChannelMap read_channel_map(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open channel map file");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_channel_map(ss.str(), path);
}

}  // namespace morphfem::hw
