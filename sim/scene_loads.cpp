// The loads of a scene: gravity, pressure cavities, gas-filled and
// volume-controlled cavities, surface tractions and test-machine pulls.
#include "sim/scene_reader.h"

namespace morphfem {

namespace {

void read_cavities(const SceneReader& r, const YAML::Node& cs, Scene& scene) {
  const double end = scene.solver.t_end;
  if (!cs.IsSequence()) r.fail(cs, "loads.cavities", "expected a list");
  for (const auto& c : cs) {
    r.allow(c, "loads.cavities");
    CavitySpec spec;
    if (!c["surfaces"]) r.fail(c, "loads.cavities", "missing key 'surfaces'");
    if (!c["pressure"]) r.fail(c, "loads.cavities", "missing key 'pressure'");
    spec.name = c["name"] ? r.text(c["name"], "loads.cavities.name") : "cavity" + std::to_string(scene.cavities.size());
    spec.surfaces = r.texts(c["surfaces"], "loads.cavities.surfaces");
    if (c["volume_axes"]) spec.axes = r.axes(c["volume_axes"], "loads.cavities.volume_axes");
    r.open_axis(c, "loads.cavities", spec.axes, spec.open_axis);
    spec.pressure = r.ramp_or_table(c["pressure"], "loads.cavities.pressure", end);
    scene.cavities.push_back(spec);
  }
}

GasCavitySpec read_gas_cavity(const SceneReader& r, const YAML::Node& c, const Scene& scene) {
  const double end = scene.solver.t_end;
  const std::string key = "loads.gas_cavities";
  r.allow(c, key);
  GasCavitySpec spec;
  if (!c["surfaces"]) r.fail(c, key, "missing key 'surfaces'");
  spec.wall.name = c["name"] ? r.text(c["name"], key + ".name") : "gas" + std::to_string(scene.gas_cavities.size());
  spec.wall.surfaces = r.texts(c["surfaces"], key + ".surfaces");
  if (c["volume_axes"]) spec.wall.axes = r.axes(c["volume_axes"], key + ".volume_axes");
  r.open_axis(c, key, spec.wall.axes, spec.wall.open_axis);
  r.optional(c, key, "symmetry_factor", spec.wall.symmetry_factor);
  r.optional(c, key, "temperature", spec.temperature);
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
  return spec;
}

void read_volume_cavities(const SceneReader& r, const YAML::Node& vs, Scene& scene) {
  const double end = scene.solver.t_end;
  const std::string key = "loads.volume_cavities";
  if (!vs.IsSequence()) r.fail(vs, key, "expected a list");
  for (const auto& c : vs) {
    r.allow(c, key);
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
    spec.penalty_modulus = r.number(c["penalty_modulus"], key + ".penalty_modulus");
    r.optional(c, key, "tolerance", spec.tolerance);
    scene.volume_cavities.push_back(spec);
  }
}

void read_tractions(const SceneReader& r, const YAML::Node& ts, Scene& scene) {
  const double end = scene.solver.t_end;
  if (!ts.IsSequence()) r.fail(ts, "loads.tractions", "expected a list");
  for (const auto& t : ts) {
    r.allow(t, "loads.tractions");
    TractionSpec spec;
    if (!t["surface"] || !t["traction"]) r.fail(t, "loads.tractions", "needs 'surface' and 'traction'");
    spec.surface = r.text(t["surface"], "loads.tractions.surface");
    spec.traction = r.vector3(t["traction"], "loads.tractions.traction");
    spec.scale = t["scale"] ? r.ramp_or_table(t["scale"], "loads.tractions.scale", end) : TimeFunction::ramp(1.0, end);
    spec.where = r.at(t);
    scene.tractions.push_back(spec);
  }
}

// Test-machine pull springs (fem/pull_spring.h).
void read_pulls(const SceneReader& r, const YAML::Node& ps, Scene& scene) {
  if (!ps.IsSequence()) r.fail(ps, "loads.pulls", "expected a list");
  for (const auto& p : ps) {
    r.allow(p, "loads.pulls");
    if (!p["surface"] || !p["stiffness"] || !p["velocity"])
      r.fail(p, "loads.pulls", "needs 'surface', 'stiffness' [N/m] and 'velocity' [m/s]");
    PullSpringSpec spec;
    spec.surface = r.text(p["surface"], "loads.pulls.surface");
    spec.stiffness = r.number(p["stiffness"], "loads.pulls.stiffness");
    spec.velocity = r.vector3(p["velocity"], "loads.pulls.velocity");
    if (!(spec.velocity.norm() > 0)) r.fail(p["velocity"], "loads.pulls.velocity", "must not be zero [m/s]");
    if (p["start"]) spec.start = r.number(p["start"], "loads.pulls.start");
    spec.where = r.at(p);
    scene.pulls.push_back(spec);
  }
}

}  // namespace

void read_loads(const SceneReader& r, const YAML::Node& l, Scene& scene) {
  if (!l) return;
  r.allow(l, "loads");
  if (l["gravity"]) scene.gravity = r.vector3(l["gravity"], "loads.gravity");
  if (const auto cs = l["cavities"]) read_cavities(r, cs, scene);
  if (const auto gs = l["gas_cavities"]) {
    if (!gs.IsSequence()) r.fail(gs, "loads.gas_cavities", "expected a list");
    for (const auto& c : gs) scene.gas_cavities.push_back(read_gas_cavity(r, c, scene));
  }
  if (const auto vs = l["volume_cavities"]) read_volume_cavities(r, vs, scene);
  if (const auto ts = l["tractions"]) read_tractions(r, ts, scene);
  if (const auto ps = l["pulls"]) read_pulls(r, ps, scene);
}

}  // namespace morphfem
