#include "hardware/channel_map.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/yaml_reader.h"

namespace morphfem::hw {

namespace {

using MapReader = YamlReader;

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
  for (auto it = devs.begin(); it != devs.end(); ++it) {
    DeviceSpec d;
    d.name = it->first.Scalar();
    std::string key = "devices." + d.name;
    YAML::Node n = it->second;
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
    m.devices.push_back(d);
  }
  YAML::Node chans = root["channels"];
  if (!chans || !chans.IsMap() || chans.size() == 0)
    throw InputError(source + ": channels", "expected at least one channel (b1..b8, core, foot_a, foot_b)");
  std::set<std::pair<std::string, int>> used;
  for (auto it = chans.begin(); it != chans.end(); ++it) {
    ChannelSpec c;
    std::string name = it->first.Scalar();
    std::string key = "channels." + name;
    c.channel = channel_index(name);
    if (c.channel < 0) r.fail(it->first, key, "unknown channel '" + name + "' (b1..b8, core, foot_a, foot_b)");
    if (m.find(c.channel)) r.fail(it->first, key, "channel listed twice");
    YAML::Node n = it->second;
    r.allow_only(
        n, key,
        {"device", "address", "inflated_pa", "deflated_pa", "min_pa", "max_pa", "ramp_limit_pa_per_s", "tolerance_pa"});
    c.where = r.where(n, key);
    if (!n["device"]) r.fail(n, key, "missing 'device'");
    c.device = r.text(n["device"], key + ".device");
    const DeviceSpec* d = m.device(c.device);
    if (!d) r.fail(n["device"], key + ".device", "no device named '" + c.device + "' under devices");
    if (!n["address"]) r.fail(n, key, "missing 'address'");
    std::string a = r.text(n["address"], key + ".address");
    if (d->protocol == Protocol::alicat) {
      if (a.size() != 1 || a[0] < 'A' || a[0] > 'Z')
        r.fail(n["address"], key + ".address", "an alicat unit ID is one letter A-Z, got '" + a + "'");
      c.address = a[0];
    } else {
      char* end = nullptr;
      long v = std::strtol(a.c_str(), &end, 0);
      if (a.empty() || end != a.c_str() + a.size() || v < 1 || v > 127)
        r.fail(n["address"], key + ".address", "an I2C address is an integer 1..127, got '" + a + "'");
      c.address = static_cast<int>(v);
    }
    if (!used.insert({c.device, c.address}).second)
      r.fail(n["address"], key + ".address", "address '" + a + "' is already used on device " + c.device);
    if (!n["min_pa"] || !n["max_pa"]) r.fail(n, key, "hard limits 'min_pa' and 'max_pa' are required");
    c.min_pa = r.number(n["min_pa"], key + ".min_pa");
    c.max_pa = r.number(n["max_pa"], key + ".max_pa");
    if (c.max_pa <= c.min_pa) r.fail(n["max_pa"], key + ".max_pa", "max_pa must exceed min_pa");
    if (c.min_pa > 0 || c.max_pa < 0)
      r.fail(n["min_pa"], key + ".min_pa", "limits must include 0 Pa (venting to atmosphere)");
    if (n["inflated_pa"]) c.inflated_pa = r.number(n["inflated_pa"], key + ".inflated_pa");
    if (n["deflated_pa"]) c.deflated_pa = r.number(n["deflated_pa"], key + ".deflated_pa");
    auto within = [&](const std::optional<double>& v, const char* k) {
      if (!v || (*v >= c.min_pa && *v <= c.max_pa)) return;
      std::string what = format_number(*v);
      what += " Pa is outside this channel's limits [";
      what += format_number(c.min_pa);
      what += ", ";
      what += format_number(c.max_pa);
      what += "] Pa";
      std::string full_key = key;
      full_key += '.';
      full_key += k;
      r.fail(n[k], full_key, what);
    };
    within(c.inflated_pa, "inflated_pa");
    within(c.deflated_pa, "deflated_pa");
    if (n["ramp_limit_pa_per_s"]) {
      c.ramp_limit_pa_per_s = r.number(n["ramp_limit_pa_per_s"], key + ".ramp_limit_pa_per_s");
      if (c.ramp_limit_pa_per_s <= 0)
        r.fail(n["ramp_limit_pa_per_s"], key + ".ramp_limit_pa_per_s", "must be positive");
    }
    if (n["tolerance_pa"]) {
      c.tolerance_pa = r.number(n["tolerance_pa"], key + ".tolerance_pa");
      if (c.tolerance_pa <= 0) r.fail(n["tolerance_pa"], key + ".tolerance_pa", "must be positive");
    }
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
