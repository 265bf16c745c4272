// Reading YAML input with located errors: every message names
// "file:line:col: key.path" and what is wrong (InputError). Shared by the
// schedule and channel-map readers.
#pragma once
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "core/strings.h"

namespace morphfem {

// Shortest round-trip text of a number, for messages.
inline std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// Parses YAML text; a syntax error becomes InputError "source:line:col: YAML syntax
// error: ..." (source names the file in the message).
inline YAML::Node load_yaml_text(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(source + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1),
                     "YAML syntax error: " + e.msg);
  }
}

// Reads and parses a YAML file; InputError "path: cannot open the WHAT" or a syntax error.
inline YAML::Node load_yaml_file(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the " + what);
  std::stringstream text;
  text << in.rdbuf();
  return load_yaml_text(text.str(), path);
}

struct YamlReader {
  std::string source;

  std::string where(const YAML::Node& n, const std::string& key) const {
    std::string w = source;
    if (n.IsDefined() && n.Mark().line >= 0)
      w += ":" + std::to_string(n.Mark().line + 1) + ":" + std::to_string(n.Mark().column + 1);
    return key.empty() ? w : w + ": " + key;
  }
  [[noreturn]] void fail(const YAML::Node& n, const std::string& key, const std::string& what) const {
    throw InputError(where(n, key), what);
  }
  double number(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected a number");
    const std::string& s = n.Scalar();
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end != s.c_str() + s.size()) fail(n, key, "expected a number, got '" + s + "'");
    if (!std::isfinite(v)) fail(n, key, "value is not a finite number");
    return v;
  }
  double number_in(const YAML::Node& n, const std::string& key, double lo, double hi) const {
    double v = number(n, key);
    if (v < lo || v > hi)
      fail(n, key,
           "value " + format_number(v) + " is outside the allowed range [" + format_number(lo) + ", " +
               format_number(hi) + "]");
    return v;
  }
  int integer_in(const YAML::Node& n, const std::string& key, int lo, int hi) const {
    double v = number(n, key);
    if (v != std::floor(v)) fail(n, key, "expected an integer, got " + format_number(v));
    if (v < lo || v > hi)
      fail(n, key,
           "value " + format_number(v) + " is outside the allowed range [" + std::to_string(lo) + ", " +
               std::to_string(hi) + "]");
    return static_cast<int>(v);
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected text");
    return n.Scalar();
  }
  void allow_only(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const {
    if (!map.IsMap()) fail(map, key, "expected a mapping (key: value)");
    for (auto it = map.begin(); it != map.end(); ++it) {
      std::string k = it->first.Scalar();
      if (!allowed.count(k)) {
        fail(it->first, key.empty() ? k : key + "." + k,
             "unknown key '" + k + "' (allowed: " + join(allowed, ", ") + ")");
      }
    }
  }
};

}  // namespace morphfem
