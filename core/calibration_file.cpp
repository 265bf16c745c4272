// Calibration files (format in calibration_file.h).
#include "core/calibration_file.h"

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/json.h"
#include "core/yaml_reader.h"

namespace morphfem {

namespace {

// SHA-256 round constants: first 32 bits of the fractional parts of the cube roots
// of the first 64 primes (FIPS 180-4, 4.2.2).
constexpr std::array<uint32_t, 64> kRound = {
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5,
    0xd807aa98, 0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174,
    0xe49b69c1, 0xefbe4786, 0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da,
    0x983e5152, 0xa831c66d, 0xb00327c8, 0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967,
    0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13, 0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85,
    0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819, 0xd6990624, 0xf40e3585, 0x106aa070,
    0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a, 0x5b9cca4f, 0x682e6ff3,
    0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7, 0xc67178f2};

uint32_t rotr(uint32_t x, int n) { return (x >> n) | (x << (32 - n)); }

std::string quoted(const std::string& s) { return json_string(s); }  // JSON strings are valid YAML

}  // namespace

std::string sha256_hex(const std::string& bytes) {
  std::array<uint32_t, 8> h = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                               0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
  std::string msg = bytes;
  const uint64_t bit_length = static_cast<uint64_t>(bytes.size()) * 8;
  msg += static_cast<char>(0x80);
  while (msg.size() % 64 != 56) msg += '\0';
  for (int i = 7; i >= 0; --i) msg += static_cast<char>((bit_length >> (8 * i)) & 0xff);
  for (size_t chunk = 0; chunk < msg.size(); chunk += 64) {
    std::array<uint32_t, 64> w{};
    for (int i = 0; i < 16; ++i)
      for (int b = 0; b < 4; ++b) w[i] = (w[i] << 8) | static_cast<unsigned char>(msg[chunk + 4 * i + b]);
    for (int i = 16; i < 64; ++i) {
      const uint32_t s0 = rotr(w[i - 15], 7) ^ rotr(w[i - 15], 18) ^ (w[i - 15] >> 3);
      const uint32_t s1 = rotr(w[i - 2], 17) ^ rotr(w[i - 2], 19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16] + s0 + w[i - 7] + s1;
    }
    auto [a, b, c, d, e, f, g, hh] = h;
    for (int i = 0; i < 64; ++i) {
      const uint32_t S1 = rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25);
      const uint32_t ch = (e & f) ^ (~e & g);
      const uint32_t t1 = hh + S1 + ch + kRound[i] + w[i];
      const uint32_t S0 = rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22);
      const uint32_t maj = (a & b) ^ (a & c) ^ (b & c);
      const uint32_t t2 = S0 + maj;
      hh = g;
      g = f;
      f = e;
      e = d + t1;
      d = c;
      c = b;
      b = a;
      a = t1 + t2;
    }
    const std::array<uint32_t, 8> add = {a, b, c, d, e, f, g, hh};
    for (int i = 0; i < 8; ++i) h[i] += add[i];
  }
  std::ostringstream out;
  for (uint32_t v : h) out << std::hex << std::setw(8) << std::setfill('0') << v;
  return out.str();
}

std::string sha256_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open the data file to checksum it");
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return sha256_hex(bytes.str());
}

const CalibratedValue& Calibration::parameter(const std::string& name) const {
  for (const auto& [n, v] : parameters)
    if (n == name) return v;
  throw InputError("calibration", "no parameter '" + name + "'");
}

std::string calibration_yaml(const Calibration& c) {
  std::ostringstream o;
  o << std::setprecision(10);
  o << "# morphfem calibration file (written by morphfem calibrate; see core/calibration_file.h)\n"
    << "kind: " << quoted(c.kind) << "\n"
    << "command: " << quoted(c.command) << "\n"
    << "created: " << quoted(c.created) << "\n";
  o << "group: {";
  bool first = true;
  for (const auto& [k, v] : c.group) {
    o << (first ? "" : ", ") << k << ": " << quoted(v);
    first = false;
  }
  o << "}\nparameters:\n";
  for (const auto& [name, v] : c.parameters)
    o << "  " << name << ": {value: " << json_number(v.value) << ", std_error: " << json_number(v.std_error)
      << ", ci95: [" << json_number(v.ci_low) << ", " << json_number(v.ci_high) << "], unit: " << quoted(v.unit)
      << "}\n";
  o << "fit: {";
  first = true;
  for (const auto& [k, v] : c.fit) {
    o << (first ? "" : ", ") << k << ": " << quoted(v);
    first = false;
  }
  o << "}\ndata:" << (c.data.empty() ? " []\n" : "\n");
  for (const auto& d : c.data)
    o << "  - {file: " << quoted(d.file) << ", sha256: " << quoted(d.sha256) << ", specimen: " << quoted(d.specimen)
      << "}\n";
  return o.str();
}

void write_calibration_file(const std::string& path, const Calibration& c) {
  write_file_atomic(path, calibration_yaml(c));
}

Calibration read_calibration_file(const std::string& path) {
  const YAML::Node root = load_yaml_file(path, "calibration file");
  auto at = [&](const YAML::Node& n) { return path + ":" + std::to_string(n.Mark().line + 1); };
  if (!root.IsMap()) throw InputError(path, "a calibration file is a map of keys");
  const std::set<std::string> allowed = {"kind", "command", "created", "group", "parameters", "fit", "data"};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (!allowed.count(key)) throw InputError(at(kv.first), "unknown key '" + key + "'");
  }
  Calibration c;
  auto text = [&](const YAML::Node& n, const std::string& key) {
    if (!n || !n.IsScalar()) throw InputError(n ? at(n) : path, "'" + key + "' must be text");
    return n.Scalar();
  };
  auto number = [&](const YAML::Node& n, const std::string& key) {
    try {
      if (!n || !n.IsScalar()) throw YAML::Exception(YAML::Mark(), "");
      return n.as<double>();
    } catch (const YAML::Exception&) {
      throw InputError(n ? at(n) : path, "'" + key + "' must be a number");
    }
  };
  c.kind = text(root["kind"], "kind");
  if (root["command"]) c.command = text(root["command"], "command");
  if (root["created"]) c.created = text(root["created"], "created");
  if (const auto g = root["group"]) {
    if (!g.IsMap()) throw InputError(at(g), "'group' must be a map");
    for (const auto& kv : g) c.group[kv.first.as<std::string>()] = text(kv.second, "group");
  }
  const auto params = root["parameters"];
  if (!params || !params.IsMap() || params.size() == 0)
    throw InputError(params ? at(params) : path, "'parameters' must map names to {value, std_error, ci95, unit}");
  for (const auto& kv : params) {
    const std::string name = kv.first.as<std::string>();
    const auto& p = kv.second;
    if (!p.IsMap()) throw InputError(at(p), "parameter '" + name + "' must be a map");
    for (const auto& k : p) {
      const std::string key = k.first.as<std::string>();
      if (key != "value" && key != "std_error" && key != "ci95" && key != "unit")
        throw InputError(at(k.first), "parameter '" + name + "': unknown key '" + key + "'");
    }
    CalibratedValue v;
    v.value = number(p["value"], "parameters." + name + ".value");
    if (p["std_error"]) v.std_error = number(p["std_error"], "parameters." + name + ".std_error");
    if (const auto ci = p["ci95"]) {
      if (!ci.IsSequence() || ci.size() != 2) throw InputError(at(ci), "'ci95' must be [low, high]");
      v.ci_low = number(ci[0], "ci95");
      v.ci_high = number(ci[1], "ci95");
    } else {
      v.ci_low = v.ci_high = v.value;
    }
    if (p["unit"]) v.unit = text(p["unit"], "unit");
    c.parameters.emplace_back(name, v);
  }
  if (const auto f = root["fit"]) {
    if (!f.IsMap()) throw InputError(at(f), "'fit' must be a map");
    for (const auto& kv : f) c.fit[kv.first.as<std::string>()] = text(kv.second, "fit");
  }
  if (const auto d = root["data"]) {
    if (!d.IsSequence()) throw InputError(at(d), "'data' must be a list of {file, sha256, specimen}");
    for (const auto& item : d) {
      CalibrationData cd;
      cd.file = text(item["file"], "data.file");
      if (item["sha256"]) cd.sha256 = text(item["sha256"], "data.sha256");
      if (item["specimen"]) cd.specimen = text(item["specimen"], "data.specimen");
      c.data.push_back(cd);
    }
  }
  return c;
}

std::vector<std::string> verify_calibration_data(const Calibration& c) {
  std::vector<std::string> problems;
  for (const auto& d : c.data) {
    try {
      if (sha256_file(d.file) != d.sha256) problems.push_back(d.file + ": checksum differs (the data changed)");
    } catch (const InputError&) {
      problems.push_back(d.file + ": missing");
    }
  }
  return problems;
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

}  // namespace morphfem
