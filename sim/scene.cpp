#include "sim/scene.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <sstream>

#include "core/errors.h"
#include "core/strings.h"
#include "core/yaml_reader.h"
#include "fem/elastic.h"
#include "sim/scene_reader.h"

namespace morphfem {

namespace {

// With a gait, its start and end are output times (if the run reaches them).
void add_gait_output_times(Scene& scene) {
  if (scene.gait.enabled)
    for (double t : {scene.gait.start, scene.gait.end})
      if (t <= scene.solver.t_end) scene.solver.output_times.push_back(t);
}

void check_friction_scheme(const SceneReader& r, const YAML::Node& root, const Scene& scene) {
  if (scene.friction && scene.dynamic && scene.inertia.scheme != TimeScheme::implicit_euler)
    throw InputError(r.at(root["dynamics"]),
                     "'dynamics.scheme': friction needs implicit_euler (the friction potential is written with the "
                     "implicit-Euler slip u - u_n; with bdf2/newmark it would be inconsistent)");
}

}  // namespace

void read_solver(const SceneReader& r, const YAML::Node& s, Scene& scene) {
  if (!s) {
    scene.solver.t_end = 1.0;
  } else {
    r.allow(s, "solver",
            {"end_time", "initial_step", "min_step", "max_step", "linear_solver", "quadrature_degree", "max_newton_its",
             "rtol", "formulation", "hessian_projection", "easy_newton_its"});
    auto positive = [&](const char* key, double& out) { r.optional_positive(s, "solver", key, out); };
    positive("end_time", scene.solver.t_end);
    positive("initial_step", scene.solver.dt_initial);
    positive("min_step", scene.solver.dt_min);
    positive("max_step", scene.solver.dt_max);
    positive("rtol", scene.solver.rtol);
    // A choice among names, or a positive integer.
    const auto one_of = [&](const char* key, std::string& out, const std::vector<std::string>& allowed) {
      if (!s[key]) return;
      const std::string where = std::string("solver.") + key;
      out = r.text(s[key], where);
      if (std::find(allowed.begin(), allowed.end(), out) != allowed.end()) return;
      r.fail(s[key], where, "must be one of '" + join(allowed, "', '") + "'");
    };
    const auto positive_integer = [&](const char* key, int& out) {
      if (!s[key]) return;
      const std::string where = std::string("solver.") + key;
      const double q = r.number(s[key], where);
      if (q < 1 || q != int(q)) r.fail(s[key], where, "must be a positive integer");
      out = int(q);
    };
    one_of("linear_solver", scene.solver.linear_solver, {"mumps", "mumps_lu", "gamg"});
    std::string projection = "adaptive";
    one_of("hessian_projection", projection, {"adaptive", "always"});
    scene.solver.hessian_projection = projection == "always" ? HessianProjection::always : HessianProjection::adaptive;
    positive_integer("max_newton_its", scene.solver.max_newton_its);
    positive_integer("easy_newton_its", scene.solver.easy_newton_its);
    if (s["formulation"]) {
      scene.formulation = r.text(s["formulation"], "solver.formulation");
      if (!elastic_formulations().count(scene.formulation)) {
        r.fail(
            s["formulation"], "solver.formulation",
            "unknown formulation '" + scene.formulation + "' (known: " + join_keys(elastic_formulations(), ", ") + ")");
      }
    }
    if (s["quadrature_degree"]) {
      double q = r.number(s["quadrature_degree"], "solver.quadrature_degree");
      if (q < 0 || q > 6 || q != int(q)) r.fail(s["quadrature_degree"], "solver.quadrature_degree", "must be 0..6");
      scene.quadrature_degree = int(q);
    }
  }
  scene.solver.dt_initial = std::min(scene.solver.dt_initial, scene.solver.t_end);
  scene.solver.dt_max = std::min(scene.solver.dt_max, scene.solver.t_end);
}

void read_output(const SceneReader& r, const YAML::Node& o, Scene& scene) {
  if (!o) return;
  r.allow(o, "output", {"directory", "every", "checkpoint_s"});
  if (o["directory"]) {
    std::filesystem::path dir = r.text(o["directory"], "output.directory");
    scene.output_dir = dir.string();
  }
  if (o["every"]) {
    double every = r.number(o["every"], "output.every");
    if (every < 1 || every != int(every)) r.fail(o["every"], "output.every", "must be a positive integer");
    scene.output_every = int(every);
  }
  if (o["checkpoint_s"]) {
    scene.checkpoint_s = r.number(o["checkpoint_s"], "output.checkpoint_s");
    if (!(scene.checkpoint_s >= 0)) r.fail(o["checkpoint_s"], "output.checkpoint_s", "must be >= 0 [s]");
  }
}

YAML::Node load_scene_yaml(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path, "scene file not found");
  return load_yaml_file(path, "scene file");
}

Scene read_scene(const std::string& path) { return scene_from_yaml(load_scene_yaml(path), path); }

// The sections in the order of their checks (the first error found is the one reported).
Scene scene_from_yaml(const YAML::Node& root, const std::string& path) {
  Scene scene;
  SceneReader r{path, &scene};
  if (!root.IsMap()) throw InputError(path, "a scene must be a mapping with keys geometry/mesh, materials, ...");
  r.allow(root, "",
          {"name", "geometry", "mesh", "materials", "membranes", "boundary", "loads", "solver", "output", "dynamics",
           "contact", "actuation", "environment"});
  scene.source = path;
  if (root["name"]) scene.name = r.text(root["name"], "name");
  read_solver(r, root["solver"], scene);  // first: load ramps need end_time
  read_geometry(r, root, scene);
  read_materials(r, root["materials"], scene);
  read_membranes(r, root["membranes"], scene);
  read_boundary(r, root["boundary"], scene);
  read_loads(r, root["loads"], scene);
  read_dynamics(r, root["dynamics"], scene);
  read_contact(r, root["contact"], scene);
  const std::optional<Schedule> schedule = read_actuation(r, root["actuation"], scene);
  read_environment(r, root, schedule, scene);
  add_gait_output_times(scene);
  check_friction_scheme(r, root, scene);
  read_output(r, root["output"], scene);
  return scene;
}

namespace {

void set_path(YAML::Node node, const std::vector<std::string>& path, size_t i, const YAML::Node& value,
              const std::string& where, const std::string& key) {
  if (!node.IsMap())
    throw InputError(where,
                     "--set " + key + ": " + (i == 0 ? "the scene" : "'" + path[i - 1] + "'") + " is not a mapping");
  if (!path[i].empty() && path[i].back() == '*') {  // every key starting with the prefix
    if (i + 1 == path.size()) throw InputError(where, "--set " + key + ": '*' cannot be in the last key");
    const std::string prefix = path[i].substr(0, path[i].size() - 1);
    int matched = 0;
    for (auto kv : node)
      if (kv.first.as<std::string>().rfind(prefix, 0) == 0) {
        set_path(kv.second, path, i + 1, value, where, key);
        ++matched;
      }
    if (matched == 0) throw InputError(where, "--set " + key + ": no key matches '" + path[i] + "'");
    return;
  }
  if (i + 1 == path.size()) {
    node[path[i]] = value;
    return;
  }
  if (!node[path[i]]) throw InputError(where, "--set " + key + ": no key '" + path[i] + "' in the scene");
  set_path(node[path[i]], path, i + 1, value, where, key);
}

}  // namespace

void set_scene_key(YAML::Node root, const std::string& assignment, const std::string& where) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == assignment.size())
    throw InputError(where, "--set '" + assignment + "': expected KEY=VALUE (e.g. geometry.order=2)");
  const std::string key = assignment.substr(0, eq);
  std::vector<std::string> path;
  std::stringstream s(key);
  for (std::string part; std::getline(s, part, '.');) {
    if (part.empty()) throw InputError(where, "--set " + key + ": empty key in the path");
    path.push_back(part);
  }
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    throw InputError(where, "--set " + key + ": the value is not YAML: " + e.what());
  }
  set_path(root, path, 0, value, where, key);
}

}  // namespace morphfem
