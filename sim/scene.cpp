#include "sim/scene.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <set>

#include "actuation/schedule_loads.h"
#include "actuation/voxel_growth.h"
#include "core/calibration_file.h"
#include "core/errors.h"
#include "core/strings.h"
#include "core/yaml_reader.h"
#include "fem/elastic.h"

namespace morphfem {

namespace {

struct Reader {
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
  void allow(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) const {
    if (!map.IsMap()) fail(map, key, "expected a mapping of keys to values");
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      if (!allowed.count(k)) {
        fail(kv.first, key.empty() ? k : key + "." + k, "unknown key (allowed: " + join(allowed, ", ") + ")");
      }
    }
  }
  double number(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected a number");
    try {
      return node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, key, "expected a number, got '" + node.Scalar() + "'");
    }
  }
  // A number, or a value from a calibration file: {calibration: FILE, parameter: NAME}
  // (FILE relative to the scene). The use is recorded in the scene (summary.json).
  double calibrated_number(const YAML::Node& node, const std::string& key) const {
    if (!node.IsMap()) return number(node, key);
    allow(node, key, {"calibration", "parameter"});
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
    if (scene)
      scene->calibrations.push_back(
          {key, path.string(), sha256_file(path.string()), calibration.kind, name, value->value, value->std_error});
    return value->value;
  }
  // A number (or, if `calibrated`, a calibrated value) that must be > 0.
  double positive(const YAML::Node& node, const std::string& key, bool calibrated = false) const {
    const double v = calibrated ? calibrated_number(node, key) : number(node, key);
    if (!(v > 0)) fail(node, key, "must be positive");
    return v;
  }
  // The optional key map[k] (path where.k): a positive number into out, out untouched if absent.
  void optional_positive(const YAML::Node& map, const std::string& where, const char* k, double& out) const {
    if (map[k]) out = positive(map[k], where + "." + k);
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
    return TimeFunction(points);
  }
};

}  // namespace

YAML::Node load_scene_yaml(const std::string& path) {
  if (!std::filesystem::exists(path)) throw InputError(path, "scene file not found");
  return load_yaml_file(path, "scene file");
}

Scene read_scene(const std::string& path) { return scene_from_yaml(load_scene_yaml(path), path); }

Scene scene_from_yaml(const YAML::Node& root, const std::string& path) {
  Scene scene;
  Reader r{path, &scene};
  if (!root.IsMap()) throw InputError(path, "a scene must be a mapping with keys geometry/mesh, materials, ...");
  r.allow(root, "",
          {"name", "geometry", "mesh", "materials", "membranes", "boundary", "loads", "solver", "output", "dynamics",
           "contact", "actuation", "environment"});
  scene.source = path;
  if (root["name"]) scene.name = r.text(root["name"], "name");

  // Solver first: load ramps need end_time.
  if (const auto s = root["solver"]) {
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
  } else {
    scene.solver.t_end = 1.0;
  }
  scene.solver.dt_initial = std::min(scene.solver.dt_initial, scene.solver.t_end);
  scene.solver.dt_max = std::min(scene.solver.dt_max, scene.solver.t_end);
  const double end = scene.solver.t_end;

  if (root["geometry"] && root["mesh"]) r.fail(root["mesh"], "mesh", "give either geometry or mesh, not both");
  if (const auto g = root["geometry"]) {
    scene.geometry = r.params(g, "geometry");
    if (!scene.geometry.has("type")) r.fail(g, "geometry", "missing key 'type'");
  } else if (const auto m = root["mesh"]) {
    r.allow(m, "mesh", {"file"});
    if (!m["file"]) r.fail(m, "mesh", "missing key 'file'");
    std::filesystem::path file = r.text(m["file"], "mesh.file");
    if (file.is_relative()) file = std::filesystem::path(path).parent_path() / file;
    scene.mesh_file = file.string();
  } else {
    throw InputError(path, "missing 'geometry' or 'mesh'");
  }

  const auto materials = root["materials"];
  if (!materials || !materials.IsMap() || materials.size() == 0)
    throw InputError(materials ? r.at(materials) : path, "'materials' must map each volume region to a material");
  for (const auto& kv : materials) {
    const std::string region = kv.first.as<std::string>();
    ParamSet p = r.params(kv.second, "materials." + region);
    if (!p.has("model")) r.fail(kv.second, "materials." + region, "missing key 'model'");
    scene.materials[region] = p;
  }

  if (const auto membranes = root["membranes"]) {  // surface region -> sheet (fem/membrane.h)
    if (!membranes.IsMap())
      r.fail(membranes, "membranes", "expected a mapping: surface region -> {model, thickness, ...}");
    for (const auto& kv : membranes) {
      const std::string surface = kv.first.as<std::string>();
      const std::string key = "membranes." + surface;
      ParamSet p = r.params(kv.second, key);
      if (!p.has("model")) r.fail(kv.second, key, "missing key 'model'");
      if (!p.has("thickness")) r.fail(kv.second, key, "missing key 'thickness' [m]");
      MembraneSpec spec;
      spec.surface = surface;
      spec.thickness = p.number_in("thickness", 1e-9, 1.0);
      spec.law = make_membrane_law(p.without("thickness"));
      spec.where = p.where("model");
      scene.membranes.push_back(spec);
    }
  }

  if (const auto b = root["boundary"]) {
    if (!b.IsSequence()) r.fail(b, "boundary", "expected a list of {surface, fix | displacement}");
    for (const auto& item : b) {
      r.allow(item, "boundary", {"surface", "fix", "displacement"});
      if (!item["surface"]) r.fail(item, "boundary", "missing key 'surface'");
      BoundarySpec spec;
      spec.surface = r.text(item["surface"], "boundary.surface");
      spec.where = r.at(item);
      if (item["fix"] && item["displacement"]) r.fail(item, "boundary", "give either 'fix' or 'displacement'");
      if (item["fix"])
        spec.components = r.axes(item["fix"], "boundary.fix");
      else if (item["displacement"]) {
        spec.components = {true, true, true};
        spec.displacement = r.vector3(item["displacement"], "boundary.displacement");
      } else {
        r.fail(item, "boundary", "missing 'fix: [x, y, z]' or 'displacement: [ux, uy, uz]'");
      }
      scene.boundary.push_back(spec);
    }
  }

  if (const auto l = root["loads"]) {
    r.allow(l, "loads", {"gravity", "cavities", "gas_cavities", "volume_cavities", "tractions", "pulls"});
    if (l["gravity"]) scene.gravity = r.vector3(l["gravity"], "loads.gravity");
    if (const auto cs = l["cavities"]) {
      if (!cs.IsSequence()) r.fail(cs, "loads.cavities", "expected a list");
      for (const auto& c : cs) {
        r.allow(c, "loads.cavities", {"name", "surfaces", "volume_axes", "open_axis", "pressure"});
        CavitySpec spec;
        if (!c["surfaces"]) r.fail(c, "loads.cavities", "missing key 'surfaces'");
        if (!c["pressure"]) r.fail(c, "loads.cavities", "missing key 'pressure'");
        spec.name =
            c["name"] ? r.text(c["name"], "loads.cavities.name") : "cavity" + std::to_string(scene.cavities.size());
        spec.surfaces = r.texts(c["surfaces"], "loads.cavities.surfaces");
        if (c["volume_axes"]) spec.axes = r.axes(c["volume_axes"], "loads.cavities.volume_axes");
        r.open_axis(c, "loads.cavities", spec.axes, spec.open_axis);
        spec.pressure = r.ramp_or_table(c["pressure"], "loads.cavities.pressure", end);
        scene.cavities.push_back(spec);
      }
    }
    if (const auto gs = l["gas_cavities"]) {
      if (!gs.IsSequence()) r.fail(gs, "loads.gas_cavities", "expected a list");
      for (const auto& c : gs) {
        const std::string key = "loads.gas_cavities";
        r.allow(c, key,
                {"name", "surfaces", "volume_axes", "open_axis", "symmetry_factor", "temperature",
                 "initial_gauge_pressure", "supply_pressure", "conductance", "vacuum_conductance"});
        GasCavitySpec spec;
        if (!c["surfaces"]) r.fail(c, key, "missing key 'surfaces'");
        spec.wall.name =
            c["name"] ? r.text(c["name"], key + ".name") : "gas" + std::to_string(scene.gas_cavities.size());
        spec.wall.surfaces = r.texts(c["surfaces"], key + ".surfaces");
        if (c["volume_axes"]) spec.wall.axes = r.axes(c["volume_axes"], key + ".volume_axes");
        r.open_axis(c, key, spec.wall.axes, spec.wall.open_axis);
        r.optional_positive(c, key, "symmetry_factor", spec.wall.symmetry_factor);
        r.optional_positive(c, key, "temperature", spec.temperature);
        if (c["initial_gauge_pressure"])
          spec.initial_gauge_pressure = r.number(c["initial_gauge_pressure"], key + ".initial_gauge_pressure");
        // A number (or a calibrated value) held constant, or a table [[t, value], ...].
        auto constant_or_table = [&](const char* k, TimeFunction& out) {
          if (!c[k]) return;
          out = c[k].IsSequence() ? r.ramp_or_table(c[k], key + "." + k, end)
                                  : TimeFunction::constant(r.calibrated_number(c[k], key + "." + k));
        };
        constant_or_table("supply_pressure", spec.supply_gauge_pressure);
        constant_or_table("conductance", spec.conductance);
        constant_or_table("vacuum_conductance", spec.vacuum_conductance);
        spec.has_vacuum_conductance = static_cast<bool>(c["vacuum_conductance"]);
        for (const auto& [k, f] :
             {std::pair{"conductance", &spec.conductance}, std::pair{"vacuum_conductance", &spec.vacuum_conductance}})
          for (const auto& [t, v] : f->points())
            if (v < 0) r.fail(c[k], key + "." + k, "must not be negative");
        scene.gas_cavities.push_back(spec);
      }
    }
    if (const auto vs = l["volume_cavities"]) {
      const std::string key = "loads.volume_cavities";
      if (!vs.IsSequence()) r.fail(vs, key, "expected a list");
      for (const auto& c : vs) {
        r.allow(c, key,
                {"name", "surfaces", "volume_axes", "open_axis", "volume_ratio", "penalty_modulus", "tolerance"});
        VolumeControlSpec spec;
        for (const char* k : {"surfaces", "volume_ratio", "penalty_modulus"})
          if (!c[k]) r.fail(c, key, std::string("missing key '") + k + "'");
        spec.wall.name =
            c["name"] ? r.text(c["name"], key + ".name") : "volume" + std::to_string(scene.volume_cavities.size());
        spec.wall.surfaces = r.texts(c["surfaces"], key + ".surfaces");
        if (c["volume_axes"]) spec.wall.axes = r.axes(c["volume_axes"], key + ".volume_axes");
        r.open_axis(c, key, spec.wall.axes, spec.wall.open_axis);
        if (!c["volume_ratio"].IsSequence())
          r.fail(c["volume_ratio"], key + ".volume_ratio", "expected a table [[t, V/V_ref], ...]");
        spec.volume = r.ramp_or_table(c["volume_ratio"], key + ".volume_ratio", end);
        spec.volume_is_ratio = true;
        for (const auto& [t, v] : spec.volume.points())
          if (!(v > 0)) r.fail(c["volume_ratio"], key + ".volume_ratio", "volume ratios must be positive");
        spec.penalty_modulus = r.positive(c["penalty_modulus"], key + ".penalty_modulus");
        r.optional_positive(c, key, "tolerance", spec.tolerance);
        scene.volume_cavities.push_back(spec);
      }
    }
    if (const auto ts = l["tractions"]) {
      if (!ts.IsSequence()) r.fail(ts, "loads.tractions", "expected a list");
      for (const auto& t : ts) {
        r.allow(t, "loads.tractions", {"surface", "traction", "scale"});
        TractionSpec spec;
        if (!t["surface"] || !t["traction"]) r.fail(t, "loads.tractions", "needs 'surface' and 'traction'");
        spec.surface = r.text(t["surface"], "loads.tractions.surface");
        spec.traction = r.vector3(t["traction"], "loads.tractions.traction");
        spec.scale =
            t["scale"] ? r.ramp_or_table(t["scale"], "loads.tractions.scale", end) : TimeFunction::ramp(1.0, end);
        spec.where = r.at(t);
        scene.tractions.push_back(spec);
      }
    }
    if (const auto ps = l["pulls"]) {  // test-machine pull springs (fem/pull_spring.h)
      if (!ps.IsSequence()) r.fail(ps, "loads.pulls", "expected a list");
      for (const auto& p : ps) {
        r.allow(p, "loads.pulls", {"surface", "stiffness", "velocity", "start"});
        if (!p["surface"] || !p["stiffness"] || !p["velocity"])
          r.fail(p, "loads.pulls", "needs 'surface', 'stiffness' [N/m] and 'velocity' [m/s]");
        PullSpringSpec spec;
        spec.surface = r.text(p["surface"], "loads.pulls.surface");
        spec.stiffness = r.number(p["stiffness"], "loads.pulls.stiffness");
        if (!(spec.stiffness > 0)) r.fail(p["stiffness"], "loads.pulls.stiffness", "must be > 0 [N/m]");
        spec.velocity = r.vector3(p["velocity"], "loads.pulls.velocity");
        if (!(spec.velocity.norm() > 0)) r.fail(p["velocity"], "loads.pulls.velocity", "must not be zero [m/s]");
        if (p["start"]) spec.start = r.number(p["start"], "loads.pulls.start");
        spec.where = r.at(p);
        scene.pulls.push_back(spec);
      }
    }
  }

  if (const auto d = root["dynamics"]) {
    r.allow(
        d, "dynamics",
        {"scheme", "lumped", "adaptive", "error_tolerance", "shear_viscosity", "bulk_viscosity", "initial_velocity"});
    scene.dynamic = true;
    if (d["scheme"]) {
      const std::string name = r.text(d["scheme"], "dynamics.scheme");
      const auto it = time_schemes().find(name);
      if (it == time_schemes().end()) {
        r.fail(d["scheme"], "dynamics.scheme",
               "unknown scheme '" + name + "' (known: " + join_keys(time_schemes(), ", ") + ")");
      }
      scene.inertia.scheme = it->second;
    }
    auto flag = [&](const char* key, bool& out) {
      if (d[key]) out = r.number(d[key], std::string("dynamics.") + key) != 0;
    };
    flag("lumped", scene.inertia.lumped);
    flag("adaptive", scene.inertia.adaptive);
    auto nonnegative = [&](const char* key, double& out) {
      if (!d[key]) return;
      out = r.number(d[key], std::string("dynamics.") + key);
      if (out < 0) r.fail(d[key], std::string("dynamics.") + key, "must not be negative");
    };
    nonnegative("error_tolerance", scene.inertia.error_tolerance);
    nonnegative("shear_viscosity", scene.shear_viscosity);
    nonnegative("bulk_viscosity", scene.bulk_viscosity);
    if (d["initial_velocity"]) scene.initial_velocity = r.vector3(d["initial_velocity"], "dynamics.initial_velocity");
  }

  if (const auto c = root["contact"]) {
    r.allow(c, "contact", {"ground", "friction", "self", "lattice_floor"});
    if (const auto g = c["ground"]) {
      r.allow(g, "contact.ground", {"point", "normal", "surfaces", "dhat", "kappa"});
      scene.ground_contact = true;
      if (!g["surfaces"]) r.fail(g, "contact.ground", "missing key 'surfaces'");
      scene.ground.surfaces = r.texts(g["surfaces"], "contact.ground.surfaces");
      if (g["point"]) scene.ground.point = r.vector3(g["point"], "contact.ground.point");
      if (g["normal"]) {
        scene.ground.normal = r.vector3(g["normal"], "contact.ground.normal");
        if (scene.ground.normal.norm() == 0) r.fail(g["normal"], "contact.ground.normal", "must not be zero");
      }
      if (g["dhat"]) scene.ground.dhat = r.number(g["dhat"], "contact.ground.dhat");
      if (g["kappa"]) scene.ground.kappa = r.number(g["kappa"], "contact.ground.kappa");
    }
    if (const auto f = c["friction"]) {
      r.allow(f, "contact.friction", {"eps_v", "lag_updates", "regions"});
      if (!scene.ground_contact) r.fail(f, "contact.friction", "friction needs contact.ground");
      scene.friction = true;
      r.optional_positive(f, "contact.friction", "eps_v", scene.friction_spec.eps_v);
      if (f["lag_updates"])
        scene.friction_spec.lag_updates = int(r.number(f["lag_updates"], "contact.friction.lag_updates"));
      if (!f["regions"] || !f["regions"].IsSequence())
        r.fail(f, "contact.friction", "missing 'regions: [{surface, mu_static, mu_kinetic}, ...]'");
      for (const auto& reg : f["regions"]) {
        r.allow(reg, "contact.friction.regions", {"surface", "mu_static", "mu_kinetic", "mu"});
        FrictionRegion region;
        if (!reg["surface"]) r.fail(reg, "contact.friction.regions", "missing key 'surface'");
        region.surface = r.text(reg["surface"], "contact.friction.regions.surface");
        // mu: a constant or a table of (time, mu); mu sets both coefficients.
        auto coefficient = [&](const YAML::Node& node, const std::string& key) {
          if (node.IsScalar() || node.IsMap()) return TimeFunction::constant(r.calibrated_number(node, key));
          return r.ramp_or_table(node, key, end);
        };
        const YAML::Node both = reg["mu"];
        const YAML::Node ms = reg["mu_static"] ? reg["mu_static"] : both;
        const YAML::Node mk = reg["mu_kinetic"] ? reg["mu_kinetic"] : both;
        if (!ms || !mk) r.fail(reg, "contact.friction.regions", "give 'mu' or both 'mu_static' and 'mu_kinetic'");
        region.mu_static = coefficient(ms, "contact.friction.regions.mu_static");
        region.mu_kinetic = coefficient(mk, "contact.friction.regions.mu_kinetic");
        scene.friction_spec.regions.push_back(region);
      }
    }
    if (const auto lf = c["lattice_floor"]) {
      const std::string key = "contact.lattice_floor";
      r.allow(lf, key, {"point", "normal", "dhat", "kappa", "eps_v", "voxel_size", "mu", "gap_foot_columns"});
      scene.lattice_floor = true;
      LatticeFloorScene& spec = scene.lattice_floor_spec;
      if (lf["gap_foot_columns"]) spec.gap_foot_columns = r.flag(lf["gap_foot_columns"], key + ".gap_foot_columns");
      if (lf["point"]) spec.floor.point = r.vector3(lf["point"], key + ".point");
      if (lf["normal"]) {
        spec.floor.normal = r.vector3(lf["normal"], key + ".normal");
        if (spec.floor.normal.norm() == 0) r.fail(lf["normal"], key + ".normal", "must not be zero");
      }
      for (auto [k, value] : {std::pair{"dhat", &spec.floor.dhat}, std::pair{"eps_v", &spec.floor.eps_v},
                              std::pair{"voxel_size", &spec.voxel_size}})
        r.optional_positive(lf, key, k, *value);
      if (!lf["kappa"]) r.fail(lf, key, "missing key 'kappa' (the barrier stiffness [Pa])");
      r.optional_positive(lf, key, "kappa", spec.floor.kappa);
      const YAML::Node mu = lf["mu"];
      if (!mu || !mu.IsMap() || mu.size() == 0)
        r.fail(mu ? mu : lf, key + ".mu", "expected a map volume region -> friction coefficient, e.g. {skin: 2.0}");
      for (const auto& item : mu) {
        const std::string region = r.text(item.first, key + ".mu");
        const double value = r.number(item.second, key + ".mu." + region);
        if (!(value >= 0)) r.fail(item.second, key + ".mu." + region, "must not be negative");
        spec.mu[region] = value;
      }
    }
    if (const auto sc = c["self"]) {
      r.allow(sc, "contact.self",
              {"pairs", "dhat", "kappa", "inflation", "max_trust_radius", "start", "project_hessian"});
      if (sc["start"]) scene.self_contact_spec.start = r.number(sc["start"], "contact.self.start");
      if (sc["project_hessian"])
        scene.self_contact_spec.project_hessian = r.flag(sc["project_hessian"], "contact.self.project_hessian");
      scene.self_contact = true;
      const YAML::Node pairs = sc["pairs"];
      if (!pairs || !pairs.IsSequence() || pairs.size() == 0)
        r.fail(pairs ? pairs : sc, "contact.self.pairs", "expected a list of surface pairs [[surf_a, surf_b], ...]");
      for (const auto& pair : pairs) {
        if (!pair.IsSequence() || pair.size() != 2)
          r.fail(pair, "contact.self.pairs", "each pair must be [surf_a, surf_b] (the same name twice: within one)");
        scene.self_contact_spec.pairs.emplace_back(r.text(pair[0], "contact.self.pairs"),
                                                   r.text(pair[1], "contact.self.pairs"));
      }
      // dhat [m], kappa [Pa], inflation [m], max_trust_radius [m]: 0 or absent selects
      // the default.
      for (auto [key, value] :
           {std::pair{"dhat", &scene.self_contact_spec.dhat}, std::pair{"kappa", &scene.self_contact_spec.kappa},
            std::pair{"inflation", &scene.self_contact_spec.inflation},
            std::pair{"max_trust_radius", &scene.self_contact_spec.max_trust_radius}}) {
        if (!sc[key]) continue;
        *value = r.number(sc[key], std::string("contact.self.") + key);
        if (!(*value >= 0)) r.fail(sc[key], std::string("contact.self.") + key, "must not be negative");
      }
    }
  }

  std::optional<Schedule> schedule;
  if (const auto a = root["actuation"]) {
    const std::string key = "actuation";
    r.allow(a, key,
            {"schedule", "start", "bladders", "growth", "timing", "core", "core_ramp_s", "volume_axes",
             "core_open_axis", "bladders_open_axis", "feet", "weightless_inflated", "valves"});
    if (!a["schedule"]) r.fail(a, key, "missing key 'schedule' (a schedule file)");
    if (a["schedule"].IsMap()) {  // the schedule written inline, in the schedule file format
      YAML::Emitter text;
      text << a["schedule"];
      scene.schedule_file = r.at(a["schedule"]);
      schedule = parse_schedule(text.c_str(), scene.schedule_file + " (actuation.schedule)");
    } else {
      std::filesystem::path file = r.text(a["schedule"], key + ".schedule");
      if (file.is_relative()) file = std::filesystem::path(path).parent_path() / file;
      scene.schedule_file = file.string();
      schedule = read_schedule(scene.schedule_file);  // its own errors name its file and line
    }
    const double start = a["start"] ? r.number(a["start"], key + ".start") : 0.0;
    if (start < 0) r.fail(a["start"], key + ".start", "must be >= 0");
    if (a["growth"] && a["bladders"]) r.fail(a["growth"], key + ".growth", "give either bladders or growth, not both");
    std::string timing = a["growth"] ? "voxel" : "schedule";
    if (a["timing"]) {
      timing = r.text(a["timing"], key + ".timing");
      if (timing != "schedule" && timing != "voxel") r.fail(a["timing"], key + ".timing", "must be schedule or voxel");
      if (a["growth"] && timing != "voxel")
        r.fail(a["timing"], key + ".timing", "growth actuation runs on the voxel timing");
    }
    const VoxelActuation voxel;
    const double gait_s = timing == "voxel" ? voxel_timeline(*schedule, voxel).duration() : schedule->duration();
    scene.gait.enabled = true;
    scene.gait.start = start;
    scene.gait.end = start + gait_s;
    scene.gait.nominal_s = schedule->duration();
    // A run shorter than the gait plays only part of the schedule; its summary then
    // says gait_complete: false and reports no speed.
    if (const auto g = a["growth"]) {
      if (!g.IsMap()) r.fail(g, key + ".growth", "expected a map {b1: volume region, ...}");
      for (const auto& kv : g) {
        const std::string name = kv.first.as<std::string>();
        const int channel = channel_index(name);
        if (channel < 0 || channel >= kNumBladders)
          r.fail(kv.first, key + ".growth." + name, "not a bladder channel (b1..b8)");
        scene.growth.emplace_back(r.text(kv.second, key + ".growth." + name),
                                  voxel_bladder_growth(*schedule, channel, start, schedule->core_pressure_pa, voxel));
      }
    }
    if (const auto w = a["weightless_inflated"]) {
      if (!a["growth"]) r.fail(w, key + ".weightless_inflated", "needs growth actuation");
      scene.weightless_inflated = r.flag(w, key + ".weightless_inflated");
    }
    std::array<bool, 3> axes{true, true, true};
    if (a["volume_axes"]) axes = r.axes(a["volume_axes"], key + ".volume_axes");
    // actuation.valves: every scheduled cavity holds gas fed through a valve from its
    // regulator, whose output follows the schedule's setpoint (gas cavities,
    // actuation/gas_cavity.h), instead of being held at the setpoint itself.
    GasCavitySpec valve;
    const YAML::Node valves = a["valves"];
    if (valves) {
      const std::string vkey = key + ".valves";
      if (!valves.IsMap()) r.fail(valves, vkey, "expected a map {fill_time_s: T} or {conductance: C}");
      r.allow(valves, vkey, {"fill_time_s", "conductance", "temperature"});
      if (static_cast<bool>(valves["fill_time_s"]) == static_cast<bool>(valves["conductance"]))
        r.fail(valves, vkey, "give exactly one of fill_time_s [s] and conductance [mol/(s Pa)]");
      auto positive = [&](const char* k) { return r.positive(valves[k], vkey + "." + k, true); };
      if (valves["fill_time_s"]) valve.fill_time = positive("fill_time_s");
      if (valves["conductance"]) valve.conductance = TimeFunction::constant(positive("conductance"));
      if (valves["temperature"]) valve.temperature = positive("temperature");
    }
    // A channel's cavity; with actuation.<open_key> an open sleeve along that axis (its
    // volume axes the other two, whatever volume_axes says).
    auto add_cavity = [&](int channel, const std::string& surface, const char* open_key, TimeFunction pressure) {
      CavitySpec spec;
      spec.name = channel_name(channel);
      spec.surfaces = {surface};
      spec.axes = axes;
      spec.pressure = std::move(pressure);
      if (a[open_key]) {
        YAML::Node sleeve;
        sleeve["open_axis"] = a[open_key];
        r.open_axis(sleeve, key + "." + open_key, spec.axes, spec.open_axis);
      }
      if (!valves) {
        scene.cavities.push_back(spec);
        return;
      }
      GasCavitySpec gas = valve;  // starts at atmospheric pressure, the setpoint is the supply
      gas.wall = {spec.name, spec.surfaces, spec.axes, 1.0, spec.open_axis};
      gas.supply_gauge_pressure = spec.pressure;
      scene.gas_cavities.push_back(gas);
    };
    if (const auto b = a["bladders"]) {
      if (!b.IsMap()) r.fail(b, key + ".bladders", "expected a map {b1: surface, ...}");
      for (const auto& kv : b) {
        const std::string name = kv.first.as<std::string>();
        const int channel = channel_index(name);
        if (channel < 0 || channel >= kNumBladders)
          r.fail(kv.first, key + ".bladders." + name, "not a bladder channel (b1..b8)");
        // bladders_open_axis: chambers without end walls (a plane-strain slice)
        add_cavity(channel, r.text(kv.second, key + ".bladders." + name), "bladders_open_axis",
                   channel_pressure(*schedule, channel, start));
      }
    } else if (a["bladders_open_axis"]) {
      r.fail(a["bladders_open_axis"], key + ".bladders_open_axis", "needs 'bladders'");
    }
    if (a["core"]) {
      TimeFunction core = channel_pressure(*schedule, kChannelCore, start);
      if (a["core_ramp_s"]) {  // the core rises linearly from 0 over [0, core_ramp_s], then holds
        const double ramp = r.number(a["core_ramp_s"], key + ".core_ramp_s");
        if (!(ramp > 0) || ramp > start) r.fail(a["core_ramp_s"], key + ".core_ramp_s", "must be in (0, start]");
        core = TimeFunction::ramp(schedule->core_pressure_pa, ramp);
      }
      add_cavity(kChannelCore, r.text(a["core"], key + ".core"), "core_open_axis", core);
    } else if (a["core_ramp_s"] || a["core_open_axis"]) {
      const char* k = a["core_ramp_s"] ? "core_ramp_s" : "core_open_axis";
      r.fail(a[k], key + "." + k, "needs 'core'");
    }
    if (const auto f = a["feet"]) {
      r.allow(f, key + ".feet", {"foot_a", "foot_b", "mu_active", "mu_inactive"});
      if (!scene.ground_contact && !scene.lattice_floor)
        r.fail(f, key + ".feet", "foot friction needs contact.ground (or contact.lattice_floor)");
      const double mu_active = f["mu_active"] ? r.calibrated_number(f["mu_active"], key + ".feet.mu_active") : 2.0;
      const double mu_inactive =
          f["mu_inactive"] ? r.calibrated_number(f["mu_inactive"], key + ".feet.mu_inactive") : 1e-4;
      // Ground contact: friction regions; the lattice floor only: its foot voxels.
      scene.friction = scene.ground_contact;
      for (const auto& [foot, channel] :
           {std::pair<const char*, int>{"foot_a", kChannelFootA}, {"foot_b", kChannelFootB}}) {
        if (!f[foot]) continue;
        const TimeFunction mu = timing == "voxel"
                                    ? voxel_foot_friction(*schedule, channel, start, mu_active, mu_inactive, voxel)
                                    : foot_friction(*schedule, channel, start, mu_active, mu_inactive);
        const std::string surface = r.text(f[foot], key + ".feet." + foot);
        if (scene.ground_contact)
          scene.friction_spec.regions.push_back({surface, mu, mu});
        else
          scene.lattice_floor_spec.feet.push_back({surface, mu});
      }
      LatticeFloorScene& lattice = scene.lattice_floor_spec;
      if (lattice.gap_foot_columns && !scene.ground_contact) {
        if (timing != "voxel")
          r.fail(f, key + ".feet", "contact.lattice_floor.gap_foot_columns needs the voxel timing (growth actuation)");
        lattice.gap_foot_mu = voxel_gap_foot_friction(*schedule, start, mu_active, mu_inactive, voxel);
      }
    }
  }

  if (const auto e = root["environment"]) {
    const std::string key = "environment";
    r.allow(e, key, {"slope_deg", "heading_deg", "gravity", "body_length"});
    if (root["loads"] && root["loads"]["gravity"])
      r.fail(e, key, "give gravity either in loads.gravity or through environment, not both");
    const double slope = e["slope_deg"] ? r.number(e["slope_deg"], key + ".slope_deg") : 0.0;
    if (slope < -90 || slope > 90) r.fail(e["slope_deg"], key + ".slope_deg", "must be in [-90, 90]");
    double heading = schedule ? schedule->orientation_deg : 0.0;
    if (e["heading_deg"]) heading = r.number(e["heading_deg"], key + ".heading_deg");
    const double g = e["gravity"] ? r.number(e["gravity"], key + ".gravity") : 9.80665;
    if (!(g >= 0)) r.fail(e["gravity"], key + ".gravity", "must be >= 0 [m/s^2]");
    const double deg = M_PI / 180.0, s_ = slope * deg, h = heading * deg;
    // The voxel study's rotated gravity: uphill along the heading (cos h, sin h, 0).
    scene.gravity = g * Eigen::Vector3d(-std::sin(s_) * std::cos(h), -std::sin(s_) * std::sin(h), -std::cos(s_));
    scene.gait.heading = Eigen::Vector3d(std::cos(h), std::sin(h), 0.0);
    if (e["body_length"]) {
      scene.gait.body_length = r.number(e["body_length"], key + ".body_length");
      if (!(scene.gait.body_length > 0)) r.fail(e["body_length"], key + ".body_length", "must be positive [m]");
    }
  }
  if (scene.gait.enabled)
    for (double t : {scene.gait.start, scene.gait.end})
      if (t <= scene.solver.t_end) scene.solver.output_times.push_back(t);

  if (scene.friction && scene.dynamic && scene.inertia.scheme != TimeScheme::implicit_euler)
    throw InputError(r.at(root["dynamics"]),
                     "'dynamics.scheme': friction needs implicit_euler (the friction potential is written with the "
                     "implicit-Euler slip u - u_n; with bdf2/newmark it would be inconsistent)");

  if (const auto o = root["output"]) {
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
