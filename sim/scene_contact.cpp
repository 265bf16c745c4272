// Dynamics and contact of a scene: the time scheme, damping and initial
// velocity; ground contact, friction, the voxel lattice's floor and self-contact.
#include "sim/scene_reader.h"

namespace morphfem {

namespace {

void read_ground(const SceneReader& r, const YAML::Node& g, Scene& scene) {
  r.allow(g, "contact.ground");
  GroundContactSpec& ground = scene.ground.emplace();
  if (!g["surfaces"]) r.fail(g, "contact.ground", "missing key 'surfaces'");
  ground.surfaces = r.texts(g["surfaces"], "contact.ground.surfaces");
  if (g["point"]) ground.point = r.vector3(g["point"], "contact.ground.point");
  if (g["normal"]) {
    ground.normal = r.vector3(g["normal"], "contact.ground.normal");
    if (ground.normal.norm() == 0) r.fail(g["normal"], "contact.ground.normal", "must not be zero");
  }
  r.optional(g, "contact.ground", "dhat", ground.dhat);
  r.optional(g, "contact.ground", "kappa", ground.kappa);
}

FrictionRegion read_friction_region(const SceneReader& r, const YAML::Node& reg, double end) {
  r.allow(reg, "contact.friction.regions");
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
  return region;
}

void read_friction(const SceneReader& r, const YAML::Node& f, Scene& scene) {
  r.allow(f, "contact.friction");
  if (!scene.ground) r.fail(f, "contact.friction", "friction needs contact.ground");
  FrictionSpec& friction = scene.friction.emplace();
  r.optional(f, "contact.friction", "eps_v", friction.eps_v);
  r.optional(f, "contact.friction", "lag_updates", friction.lag_updates);
  if (!f["regions"] || !f["regions"].IsSequence())
    r.fail(f, "contact.friction", "missing 'regions: [{surface, mu_static, mu_kinetic}, ...]'");
  for (const auto& reg : f["regions"]) friction.regions.push_back(read_friction_region(r, reg, scene.solver.t_end));
}

void read_lattice_floor(const SceneReader& r, const YAML::Node& lf, Scene& scene) {
  const std::string key = "contact.lattice_floor";
  r.allow(lf, key);
  LatticeFloorScene& spec = scene.lattice_floor.emplace();
  r.optional(lf, key, "gap_foot_columns", spec.gap_foot_columns);
  if (lf["point"]) spec.floor.point = r.vector3(lf["point"], key + ".point");
  if (lf["normal"]) {
    spec.floor.normal = r.vector3(lf["normal"], key + ".normal");
    if (spec.floor.normal.norm() == 0) r.fail(lf["normal"], key + ".normal", "must not be zero");
  }
  for (auto [k, value] : {std::pair{"dhat", &spec.floor.dhat}, std::pair{"eps_v", &spec.floor.eps_v},
                          std::pair{"voxel_size", &spec.voxel_size}})
    r.optional(lf, key, k, *value);
  if (!lf["kappa"]) r.fail(lf, key, "missing key 'kappa' (the barrier stiffness [Pa])");
  r.optional(lf, key, "kappa", spec.floor.kappa);
  const YAML::Node mu = lf["mu"];
  if (!mu || !mu.IsMap() || mu.size() == 0)
    r.fail(mu ? mu : lf, key + ".mu", "expected a map volume region -> friction coefficient, e.g. {skin: 2.0}");
  for (const auto& item : mu) {
    const std::string region = r.text(item.first, key + ".mu");
    spec.mu[region] = r.number(item.second, key + ".mu." + region);
  }
}

void read_self_contact(const SceneReader& r, const YAML::Node& sc, Scene& scene) {
  r.allow(sc, "contact.self");
  SelfContactSpec& spec = scene.self_contact.emplace();
  r.optional(sc, "contact.self", "start", spec.start);
  r.optional(sc, "contact.self", "project_hessian", spec.project_hessian);
  const YAML::Node pairs = sc["pairs"];
  if (!pairs || !pairs.IsSequence() || pairs.size() == 0)
    r.fail(pairs ? pairs : sc, "contact.self.pairs", "expected a list of surface pairs [[surf_a, surf_b], ...]");
  for (const auto& pair : pairs) {
    if (!pair.IsSequence() || pair.size() != 2)
      r.fail(pair, "contact.self.pairs", "each pair must be [surf_a, surf_b] (the same name twice: within one)");
    spec.pairs.emplace_back(r.text(pair[0], "contact.self.pairs"), r.text(pair[1], "contact.self.pairs"));
  }
  // dhat [m], kappa [Pa], inflation [m], max_trust_radius [m]: 0 or absent selects
  // the default.
  for (auto [key, value] :
       {std::pair{"dhat", &spec.dhat}, std::pair{"kappa", &spec.kappa}, std::pair{"inflation", &spec.inflation},
        std::pair{"max_trust_radius", &spec.max_trust_radius}})
    r.optional(sc, "contact.self", key, *value);
}

}  // namespace

void read_dynamics(const SceneReader& r, const YAML::Node& d, Scene& scene) {
  if (!d) return;
  r.allow(d, "dynamics");
  DynamicsSpec& dynamics = scene.dynamics.emplace();
  if (d["scheme"]) {
    const std::string name = r.text(d["scheme"], "dynamics.scheme");
    const auto it = time_schemes().find(name);
    if (it == time_schemes().end()) {
      r.fail(d["scheme"], "dynamics.scheme",
             "unknown scheme '" + name + "' (known: " + join_keys(time_schemes(), ", ") + ")");
    }
    dynamics.inertia.scheme = it->second;
  }
  auto flag = [&](const char* key, bool& out) {
    if (d[key]) out = r.number(d[key], std::string("dynamics.") + key) != 0;
  };
  flag("lumped", dynamics.inertia.lumped);
  flag("adaptive", dynamics.inertia.adaptive);
  r.optional(d, "dynamics", "error_tolerance", dynamics.inertia.error_tolerance);
  r.optional(d, "dynamics", "shear_viscosity", dynamics.shear_viscosity);
  r.optional(d, "dynamics", "bulk_viscosity", dynamics.bulk_viscosity);
  if (d["initial_velocity"]) dynamics.initial_velocity = r.vector3(d["initial_velocity"], "dynamics.initial_velocity");
}

void read_contact(const SceneReader& r, const YAML::Node& c, Scene& scene) {
  if (!c) return;
  r.allow(c, "contact");
  if (const auto g = c["ground"]) read_ground(r, g, scene);
  if (const auto f = c["friction"]) read_friction(r, f, scene);
  if (const auto lf = c["lattice_floor"]) read_lattice_floor(r, lf, scene);
  if (const auto sc = c["self"]) read_self_contact(r, sc, scene);
}

}  // namespace morphfem
