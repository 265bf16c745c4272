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
  if (scene.friction && scene.dynamics && scene.dynamics->inertia.scheme != TimeScheme::implicit_euler)
    throw InputError(r.at(root["dynamics"]),
                     "'dynamics.scheme': friction needs implicit_euler (the friction potential is written with the "
                     "implicit-Euler slip u - u_n; with bdf2/newmark it would be inconsistent)");
}

}  // namespace

void read_solver(const SceneReader& r, const YAML::Node& s, Scene& scene) {
  if (!s) {
    scene.solver.t_end = 1.0;
  } else {
    const std::string key = "solver";
    r.allow(s, key);
    SolverOptions& solver = scene.solver;
    r.optional(s, key, "end_time", solver.t_end);
    r.optional(s, key, "initial_step", solver.dt_initial);
    r.optional(s, key, "min_step", solver.dt_min);
    r.optional(s, key, "max_step", solver.dt_max);
    r.optional(s, key, "rtol", solver.rtol);
    r.optional(s, key, "newton_velocity_tol", solver.newton_velocity_tol);
    r.optional(s, key, "extrapolate", solver.extrapolate);
    r.optional(s, key, "land_on_breakpoints", solver.land_on_breakpoints);
    if (s["linear_solver"]) solver.linear_solver = r.choice(s["linear_solver"], "solver.linear_solver");
    if (s["hessian_projection"])
      solver.hessian_projection = r.choice(s["hessian_projection"], "solver.hessian_projection") == "always"
                                      ? HessianProjection::always
                                      : HessianProjection::adaptive;
    r.optional(s, key, "max_newton_its", solver.max_newton_its);
    r.optional(s, key, "easy_newton_its", solver.easy_newton_its);
    if (s["formulation"]) {
      scene.formulation = r.text(s["formulation"], "solver.formulation");
      if (!elastic_formulations().count(scene.formulation)) {
        r.fail(
            s["formulation"], "solver.formulation",
            "unknown formulation '" + scene.formulation + "' (known: " + join_keys(elastic_formulations(), ", ") + ")");
      }
    }
    r.optional(s, key, "quadrature_degree", scene.quadrature_degree);
  }
  scene.solver.dt_initial = std::min(scene.solver.dt_initial, scene.solver.t_end);
  scene.solver.dt_max = std::min(scene.solver.dt_max, scene.solver.t_end);
}

void read_output(const SceneReader& r, const YAML::Node& o, Scene& scene) {
  if (!o) return;
  r.allow(o, "output");
  if (o["directory"]) scene.output_dir = r.text(o["directory"], "output.directory");
  r.optional(o, "output", "every", scene.output_every);
  r.optional(o, "output", "checkpoint_s", scene.checkpoint_s);
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
  r.allow(root, "");
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
