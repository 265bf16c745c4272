// Reading a scene document (sim/scene.h): the reader of values with their file,
// line and key in every error, and one reader per scene section, called by
// scene_from_yaml in the order of its checks.
#pragma once
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "actuation/schedule.h"
#include "core/calibration_file.h"
#include "core/errors.h"
#include "core/strings.h"
#include "sim/scene.h"
#include "sim/scene_keys.h"

namespace morphfem {

// Values of a scene file: each error names the file, the line and column, and the key.
struct SceneReader {
  std::string file;
  Scene* scene = nullptr;  // where calibrated values are recorded

  std::string at(const YAML::Node& node) const {
    const YAML::Mark m = node.Mark();
    if (m.line < 0) return file;
    return file + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
  }
  [[noreturn]] void fail(const YAML::Node& node, const std::string& key, const std::string& what) const {
    throw InputError(at(node), (key.empty() ? "" : "'" + key + "': ") + what);
  }
  // The mapping `map` at `key` holds only the keys the table declares under `section`
  // (sim/scene_keys.h; `section` is `key` unless the mapping is a shared form, e.g. a
  // calibrated value).
  void allow(const YAML::Node& map, const std::string& key, const std::string& section) const {
    if (!map.IsMap()) fail(map, key, "expected a mapping of keys to values");
    const std::vector<std::string> allowed = scene_key_children(section);
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
        fail(kv.first, key.empty() ? k : key + "." + k, "unknown key (allowed: " + join(allowed, ", ") + ")");
      }
    }
  }
  void allow(const YAML::Node& map, const std::string& key) const { allow(map, key, key); }
  // The value `v` of `key` within the key's declared range (and whole if the key is an
  // integer); keys of other types, or without a range, take any number.
  void check_range(const YAML::Node& node, const std::string& key, double v) const {
    const SceneKey* declared = find_scene_key(key);
    if (!declared) return;
    const KeyType type = declared->type;
    if (type != KeyType::number && type != KeyType::integer && type != KeyType::calibrated) return;
    const bool whole = type != KeyType::integer || v == std::floor(v);
    if (!whole || (declared->range && !declared->range->contains(v))) fail(node, key, declared->requirement());
  }
  // A number, checked against the range the table declares for `key`.
  double number(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected a number");
    double v = 0;
    try {
      v = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, key, "expected a number, got '" + node.Scalar() + "'");
    }
    check_range(node, key, v);
    return v;
  }
  // An integer key (the table declares it whole, and its range).
  int integer(const YAML::Node& node, const std::string& key) const { return int(number(node, key)); }
  // A number, or a value from a calibration file: {calibration: FILE, parameter: NAME}
  // (FILE relative to the scene). The use is recorded in the scene (summary.json).
  double calibrated_number(const YAML::Node& node, const std::string& key) const {
    if (!node.IsMap()) return number(node, key);
    allow(node, key, "(calibrated value)");
    if (!node["calibration"] || !node["parameter"])
      fail(node, key, "a calibrated value needs {calibration: FILE, parameter: NAME}");
    std::filesystem::path path = text(node["calibration"], key + ".calibration");
    if (path.is_relative()) path = std::filesystem::path(file).parent_path() / path;
    const Calibration calibration = read_calibration_file(path.string());  // its errors name its file and line
    const std::string name = text(node["parameter"], key + ".parameter");
    const CalibratedValue* value = nullptr;
    for (const auto& [n, v] : calibration.parameters)
      if (n == name) value = &v;
    if (!value)
      fail(node["parameter"], key + ".parameter",
           "'" + path.string() + "' has no parameter '" + name +
               "' (it has: " + join_keys(calibration.parameters, ", ") + ")");
    check_range(node, key, value->value);
    if (scene)
      scene->calibrations.push_back(
          {key, path.string(), sha256_file(path.string()), calibration.kind, name, value->value, value->std_error});
    return value->value;
  }
  Eigen::Vector3d vector3(const YAML::Node& node, const std::string& key) const {
    if (!node.IsSequence() || node.size() != 3) fail(node, key, "expected a list of 3 numbers [x, y, z]");
    return {number(node[0], key), number(node[1], key), number(node[2], key)};
  }
  std::string text(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected text");
    return node.Scalar();
  }
  std::vector<std::string> texts(const YAML::Node& node, const std::string& key) const {
    if (node.IsScalar()) return {node.Scalar()};
    if (!node.IsSequence()) fail(node, key, "expected a name or a list of names");
    std::vector<std::string> out;
    for (const auto& n : node) out.push_back(text(n, key));
    return out;
  }
  std::array<bool, 3> axes(const YAML::Node& node, const std::string& key) const {
    std::array<bool, 3> out{false, false, false};
    for (const auto& name : texts(node, key)) {
      if (name == "x")
        out[0] = true;
      else if (name == "y")
        out[1] = true;
      else if (name == "z")
        out[2] = true;
      else
        fail(node, key, "unknown axis '" + name + "' (allowed: x, y, z)");
    }
    return out;
  }
  // true / false.
  bool flag(const YAML::Node& node, const std::string& key) const {
    const std::string v = text(node, key);
    if (v == "true") return true;
    if (v == "false") return false;
    fail(node, key, "expected true or false, got '" + v + "'");
  }
  // The optional key map[k] (path section.k) into out, out untouched if absent.
  void optional(const YAML::Node& map, const std::string& section, const char* k, double& out) const {
    if (map[k]) out = number(map[k], section + "." + k);
  }
  void optional(const YAML::Node& map, const std::string& section, const char* k, int& out) const {
    if (map[k]) out = integer(map[k], section + "." + k);
  }
  void optional(const YAML::Node& map, const std::string& section, const char* k, bool& out) const {
    if (map[k]) out = flag(map[k], section + "." + k);
  }
  // One of the values the table lists for `key`.
  std::string choice(const YAML::Node& node, const std::string& key) const {
    const std::string value = text(node, key);
    const SceneKey* declared = find_scene_key(key);
    if (!declared) throw std::logic_error("scene key '" + key + "' is not declared (sim/scene_keys.cpp)");
    const std::vector<std::string>& allowed = declared->choices;
    if (std::find(allowed.begin(), allowed.end(), value) == allowed.end())
      fail(node, key, "must be one of '" + join(allowed, "', '") + "'");
    return value;
  }
  // An open sleeve's axis (x, y or z) and the volume axes it implies (the other two).
  void open_axis(const YAML::Node& c, const std::string& key, std::array<bool, 3>& axes, int& axis) const {
    if (!c["open_axis"]) return;
    const std::string name = text(c["open_axis"], key + ".open_axis");
    if (name != "x" && name != "y" && name != "z")
      fail(c["open_axis"], key + ".open_axis", "unknown axis '" + name + "' (allowed: x, y, z)");
    axis = name[0] - 'x';
    std::array<bool, 3> others{};
    for (int i = 0; i < 3; ++i) others[i] = i != axis;
    if (c["volume_axes"] && axes != others)
      fail(c["volume_axes"], key + ".volume_axes",
           "an open sleeve's volume axes are the two other than open_axis (leave volume_axes out)");
    axes = others;
  }
  // A map of scalars and numeric lists -> ParamSet (each value remembers its line).
  ParamSet params(const YAML::Node& map, const std::string& context) const {
    if (!map.IsMap()) fail(map, context, "expected a mapping of parameters");
    ParamSet p(context);
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      const YAML::Node& v = kv.second;
      if (v.IsSequence()) {
        std::vector<double> values;
        for (const auto& item : v) values.push_back(number(item, context + "." + k));
        p.set(k, values, at(v));
      } else if (v.IsScalar()) {
        double d;
        if (YAML::convert<double>::decode(v, d))
          p.set(k, d, at(v));
        else
          p.set_string(k, v.Scalar(), at(v));
      } else if (v.IsMap()) {  // {calibration: FILE, parameter: NAME}
        p.set(k, calibrated_number(v, context + "." + k), at(v));
      } else {
        fail(v, context + "." + k,
             "expected a number, a list of numbers, text or {calibration: FILE, parameter: NAME}");
      }
    }
    return p;
  }
  // A load magnitude over time: a number (ramped from 0 over [0, end]) or a table.
  TimeFunction ramp_or_table(const YAML::Node& node, const std::string& key, double end_time) const {
    if (node.IsScalar()) return TimeFunction::ramp(number(node, key), end_time);
    if (!node.IsSequence() || node.size() == 0) fail(node, key, "expected a number or a table [[t, value], ...]");
    std::vector<std::pair<double, double>> points;
    for (const auto& row : node) {
      if (!row.IsSequence() || row.size() != 2) fail(row, key, "each table row must be [time, value]");
      points.emplace_back(number(row[0], key), number(row[1], key));
      if (points.size() > 1 && !(points.back().first > points[points.size() - 2].first))
        fail(row, key, "table times must increase strictly");
    }
    TimeFunction f(points);
    land_on(f);
    return f;
  }
  // Records the times of a load's breakpoints, where steps land (SolverOptions::breakpoints).
  void land_on(const TimeFunction& f) const {
    if (scene)
      for (const auto& point : f.points()) scene->solver.breakpoints.push_back(point.first);
  }
  void land_on(const std::vector<double>& times) const {
    if (scene) scene->solver.breakpoints.insert(scene->solver.breakpoints.end(), times.begin(), times.end());
  }
};

// The scene's sections, each from its node (undefined if the scene leaves it out).
// solver (first: load ramps need end_time), output: sim/scene.cpp.
void read_solver(const SceneReader& r, const YAML::Node& s, Scene& scene);
void read_output(const SceneReader& r, const YAML::Node& o, Scene& scene);
// geometry or mesh, materials, membranes, boundary: sim/scene_body.cpp.
void read_geometry(const SceneReader& r, const YAML::Node& root, Scene& scene);
void read_materials(const SceneReader& r, const YAML::Node& materials, Scene& scene);
void read_membranes(const SceneReader& r, const YAML::Node& membranes, Scene& scene);
void read_boundary(const SceneReader& r, const YAML::Node& b, Scene& scene);
// loads: gravity, cavities, gas and volume-controlled cavities, tractions, pulls: sim/scene_loads.cpp.
void read_loads(const SceneReader& r, const YAML::Node& l, Scene& scene);
// dynamics, contact (ground, friction, lattice floor, self-contact): sim/scene_contact.cpp.
void read_dynamics(const SceneReader& r, const YAML::Node& d, Scene& scene);
void read_contact(const SceneReader& r, const YAML::Node& c, Scene& scene);
// actuation (its schedule, if any), environment: sim/scene_actuation.cpp.
std::optional<Schedule> read_actuation(const SceneReader& r, const YAML::Node& a, Scene& scene);
void read_environment(const SceneReader& r, const YAML::Node& root, const std::optional<Schedule>& schedule,
                      Scene& scene);

}  // namespace morphfem
