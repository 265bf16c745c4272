#include "sim/scene_keys.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <sstream>

#include "core/strings.h"
#include "fem/elastic.h"
#include "fem/time_integrator.h"

namespace morphfem {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const KeyRange kPositive{0.0, kInf, true, false};
const KeyRange kNonNegative{0.0, kInf, false, false};
KeyRange at_least(double lo) { return {lo, kInf, false, false}; }
KeyRange between(double lo, double hi) { return {lo, hi, false, false}; }

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

SceneKey key(std::string path, KeyType type, std::string unit, std::string fallback, std::string doc,
             std::optional<KeyRange> range = std::nullopt, std::string limits = "") {
  SceneKey k;
  k.path = std::move(path);
  k.type = type;
  k.unit = std::move(unit);
  k.fallback = std::move(fallback);
  k.range = range;
  k.limits = std::move(limits);
  k.doc = std::move(doc);
  return k;
}

SceneKey choice(std::string path, std::string fallback, std::vector<std::string> choices, std::string doc) {
  SceneKey k = key(std::move(path), KeyType::choice, "", std::move(fallback), std::move(doc));
  k.choices = std::move(choices);
  return k;
}

template <class Map>
std::vector<std::string> names_of(const Map& registry) {
  std::vector<std::string> out;
  for (const auto& kv : registry) out.push_back(kv.first);
  return out;
}

using K = KeyType;
using Keys = std::vector<SceneKey>;

void append(Keys& t, const Keys& keys) { t.insert(t.end(), keys.begin(), keys.end()); }

// A cavity's wall: the keys loads.cavities, gas_cavities and volume_cavities share.
void add_wall(Keys& t, const std::string& list, const std::string& name_default) {
  t.push_back(key(list + ".name", K::text, "", name_default, "the cavity's name in results"));
  t.push_back(key(list + ".surfaces", K::names, "", "required", "surface regions that enclose the cavity"));
  t.push_back(key(list + ".volume_axes", K::axes, "", "[x, y, z]",
                  "axes of the enclosed volume: the symmetry planes' axes closing a meshed part"));
  t.push_back(key(list + ".open_axis", K::axis, "", "",
                  "a sleeve open at both ends along this axis: pressure on the walls only, no end-cap force; "
                  "the volume axes are the other two"));
}

// The scene's name and its body: geometry or mesh, materials, membranes, boundary conditions.
void add_body_keys(Keys& t) {
  const Keys keys = {
      key("name", K::text, "", "scene", "the scene's name: results are NAME.xdmf, NAME.h5"),
      key("geometry", K::parameters, "", "", "a built-in geometry (give geometry or mesh)"),
      key("geometry.type", K::text, "", "required", "the geometry builder (mesh/geometry.h)"),
      key("geometry.<parameter>", K::parameters, "", "",
          "the builder's parameters: sizes [m], mesh_size [m], order (1 or 2); checked by the builder"),
      key("mesh", K::mapping, "", "", "a mesh file instead of geometry"),
      key("mesh.file", K::file, "", "required", "a Gmsh .msh file with named volume and surface regions"),
      key("materials", K::mapping, "", "required", "volume region -> material law (fem/material.h)"),
      key("materials.<region>", K::parameters, "", "required", "the law of every volume region of the mesh"),
      key("materials.<region>.model", K::text, "", "required", "the law's registered name (neo_hookean, yeoh, ...)"),
      key("materials.<region>.<parameter>", K::calibrated, "", "",
          "the law's parameters, e.g. mu, kappa [Pa], nu [-], density [kg/m^3]; checked by the law"),
      key("membranes", K::mapping, "", "", "surface region -> thin sheet (fem/membrane.h), massless"),
      key("membranes.<surface>", K::parameters, "", "", "the sheet on one surface region"),
      key("membranes.<surface>.model", K::text, "", "required", "the sheet's law (neo_hookean, fabric, ...)"),
      key("membranes.<surface>.thickness", K::number, "[m]", "required", "the sheet's thickness", between(1e-9, 1.0)),
      key("membranes.<surface>.<parameter>", K::calibrated, "", "", "the sheet law's parameters; checked by the law"),
      key("boundary", K::list, "", "", "prescribed displacements on surface regions"),
      key("boundary.surface", K::text, "", "required", "the surface region"),
      key("boundary.fix", K::axes, "", "", "components held at zero (give fix or displacement)"),
      key("boundary.displacement", K::vector3, "[m]", "", "the final displacement, ramped linearly over the run"),
  };
  append(t, keys);
}

// The cavity lists: prescribed pressure, gas fed through a valve, prescribed volume.
void add_cavity_keys(Keys& t) {
  t.push_back(key("loads.cavities", K::list, "", "", "cavities under a prescribed pressure"));
  add_wall(t, "loads.cavities", "cavity0, cavity1, ...");
  t.push_back(key("loads.cavities.pressure", K::time_function, "[Pa]", "required", "the gauge pressure"));
  t.push_back(key("loads.gas_cavities", K::list, "", "",
                  "cavities of isothermal ideal gas fed through a valve (actuation/gas_cavity.h)"));
  add_wall(t, "loads.gas_cavities", "gas0, gas1, ...");
  const Keys gas = {
      key("loads.gas_cavities.symmetry_factor", K::number, "[-]", "1", "copies of the meshed part in the whole cavity",
          kPositive),
      key("loads.gas_cavities.temperature", K::number, "[K]", "293.15", "the gas temperature", kPositive),
      key("loads.gas_cavities.initial_gauge_pressure", K::number, "[Pa]", "0", "the gas's gauge pressure at t = 0"),
      key("loads.gas_cavities.supply_pressure", K::coefficient, "[Pa]", "0",
          "the valve's supply (gauge) pressure, held constant or a table"),
      key("loads.gas_cavities.conductance", K::coefficient, "[mol/(s Pa)]", "0", "the valve's conductance", {}, ">= 0"),
      key("loads.gas_cavities.vacuum_conductance", K::coefficient, "[mol/(s Pa)]", "conductance",
          "the conductance while the supply pressure is below 0", {}, ">= 0"),
  };
  append(t, gas);
  t.push_back(key("loads.volume_cavities", K::list, "", "",
                  "cavities of prescribed volume; the pressure is the constraint's multiplier"));
  add_wall(t, "loads.volume_cavities", "volume0, volume1, ...");
  const Keys volume = {
      key("loads.volume_cavities.volume_ratio", K::table, "[-]", "required",
          "the prescribed volume over the reference volume, V*/V_ref", {}, "> 0"),
      key("loads.volume_cavities.penalty_modulus", K::number, "[Pa]", "required",
          "the volume constraint's penalty modulus", kPositive),
      key("loads.volume_cavities.tolerance", K::number, "[-]", "1e-06", "|V - V*| / V* allowed", kPositive),
  };
  append(t, volume);
}

// External loads: gravity, the cavities, tractions, pulls.
void add_load_keys(Keys& t) {
  const Keys loads = {
      key("loads", K::mapping, "", "", "external loads"),
      key("loads.gravity", K::vector3, "[m/s^2]", "[0, 0, 0]",
          "gravitational acceleration; needs each material's density [kg/m^3]"),
  };
  append(t, loads);
  add_cavity_keys(t);
  const Keys surface_loads = {
      key("loads.tractions", K::list, "", "", "dead surface loads"),
      key("loads.tractions.surface", K::text, "", "required", "the surface region"),
      key("loads.tractions.traction", K::vector3, "[Pa]", "required", "the traction (force per reference area)"),
      key("loads.tractions.scale", K::time_function, "[-]", "ramp 0 -> 1", "the traction's factor over time"),
      key("loads.pulls", K::list, "", "", "a test machine pulling a surface region through a spring"),
      key("loads.pulls.surface", K::text, "", "required", "the pulled surface region"),
      key("loads.pulls.stiffness", K::number, "[N/m]", "required", "the spring's stiffness", kPositive),
      key("loads.pulls.velocity", K::vector3, "[m/s]", "required", "the machine's velocity", {}, "not zero"),
      key("loads.pulls.start", K::number, "[s]", "0", "when the machine starts"),
  };
  append(t, surface_loads);
}

// Time stepping and Newton's method.
void add_solver_keys(Keys& t) {
  const Keys keys = {
      key("solver", K::mapping, "", "", "time stepping and Newton's method (fem/solver.h)"),
      key("solver.end_time", K::number, "[s]", "1", "the run's end (pseudo-time for a quasi-static scene)", kPositive),
      key("solver.initial_step", K::number, "[s]", "0.1", "the first step (at most end_time)", kPositive),
      key("solver.min_step", K::number, "[s]", "1e-06", "the smallest step before the run gives up", kPositive),
      key("solver.max_step", K::number, "[s]", "1", "the largest step (at most end_time)", kPositive),
      key("solver.rtol", K::number, "[-]", "1e-09", "Newton converges at |r| <= rtol |r_0|", kPositive),
      key("solver.newton_velocity_tol", K::number, "[m/s]", "0",
          "Newton also converges once its step moves no node faster than this (0: off)", kNonNegative),
      key("solver.extrapolate", K::boolean, "", "true",
          "start Newton from the last step's velocity (false: from the last state)"),
      key("solver.land_on_breakpoints", K::boolean, "", "false",
          "steps end on the loads' breakpoints (schedule columns, ramp ends, foot switches) and are equal up to each "
          "(false: only output times are stops)"),
      choice("solver.linear_solver", "mumps", {"mumps", "mumps_lu", "gamg"},
             "the linear solver: MUMPS LDL^T, MUMPS LU or algebraic multigrid"),
      key("solver.quadrature_degree", K::integer, "[-]", "0", "the volume quadrature's degree (0: the element's)",
          between(0, 6)),
      key("solver.max_newton_its", K::integer, "[-]", "30", "Newton iterations before a step is cut", at_least(1)),
      key("solver.easy_newton_its", K::integer, "[-]", "6",
          "a step converged in at most this many iterations lets the next grow 1.5x", at_least(1)),
      choice("solver.formulation", "displacement", names_of(elastic_formulations()),
             "the elastic element formulation (fem/elastic.h)"),
      choice("solver.hessian_projection", "adaptive", {"adaptive", "always"},
             "adaptive: the exact Hessian after a full Newton step, else the projected one; always: projected"),
  };
  append(t, keys);
}

// Results on disk.
void add_output_keys(Keys& t) {
  const Keys keys = {
      key("output", K::mapping, "", "", "results on disk (none without output.directory)"),
      key("output.directory", K::text, "", "", "the results' folder (XDMF + HDF5, summary.json)"),
      key("output.every", K::integer, "[-]", "1", "write every n-th step", at_least(1)),
      key("output.checkpoint_s", K::number, "[s]", "600",
          "wall time between checkpoints (0: only the final one); `run --resume` continues from the last",
          kNonNegative),
  };
  append(t, keys);
}

// Inertia and damping.
void add_dynamics_keys(Keys& t) {
  const Keys keys = {
      key("dynamics", K::mapping, "", "", "inertia and damping (absent: quasi-static)"),
      choice("dynamics.scheme", "newmark", names_of(time_schemes()), "the time integrator (fem/time_integrator.h)"),
      key("dynamics.lumped", K::number, "[-]", "0", "nonzero: lumped (diagonal) mass instead of consistent"),
      key("dynamics.adaptive", K::number, "[-]", "0",
          "nonzero: the truncation error estimate rejects steps and chooses dt"),
      key("dynamics.error_tolerance", K::number, "[m]", "0.0001", "the largest nodal error estimate per step",
          kNonNegative),
      key("dynamics.shear_viscosity", K::number, "[Pa s]", "0", "Kelvin-Voigt shear viscosity", kNonNegative),
      key("dynamics.bulk_viscosity", K::number, "[Pa s]", "0", "Kelvin-Voigt bulk viscosity", kNonNegative),
      key("dynamics.initial_velocity", K::vector3, "[m/s]", "[0, 0, 0]", "every node's velocity at t = 0"),
  };
  append(t, keys);
}

// Ground contact, friction, the lattice floor, self-contact.
void add_contact_keys(Keys& t) {
  const Keys keys = {
      key("contact", K::mapping, "", "", "contact and friction"),
      key("contact.ground", K::mapping, "", "", "a rigid plane under barrier contact (contact/ground.h)"),
      key("contact.ground.point", K::vector3, "[m]", "[0, 0, 0]", "a point of the plane"),
      key("contact.ground.normal", K::vector3, "[-]", "[0, 0, 1]", "the plane's normal, towards the body", {},
          "not zero"),
      key("contact.ground.surfaces", K::names, "", "required", "surface regions that may touch the plane"),
      key("contact.ground.dhat", K::number, "[m]", "0", "barrier width; <= 0: 1e-3 x the bounding-box diagonal"),
      key("contact.ground.kappa", K::number, "[Pa]", "0",
          "barrier stiffness; <= 0: 3 mu of the material under most of the surfaces"),
      key("contact.friction", K::mapping, "", "", "friction on the ground contact (contact/friction.h)"),
      key("contact.friction.eps_v", K::number, "[m/s]", "0.0001", "smoothing (creep) velocity", kPositive),
      key("contact.friction.lag_updates", K::integer, "[-]", "0",
          "re-solves per step with the normal forces of the converged state", kNonNegative),
      key("contact.friction.regions", K::list, "", "required", "friction coefficients per surface region"),
      key("contact.friction.regions.surface", K::text, "", "required", "the surface region"),
      key("contact.friction.regions.mu_static", K::coefficient, "[-]", "mu", "static friction coefficient"),
      key("contact.friction.regions.mu_kinetic", K::coefficient, "[-]", "mu", "kinetic friction coefficient"),
      key("contact.friction.regions.mu", K::coefficient, "[-]", "",
          "both coefficients (give mu or mu_static and mu_kinetic)"),
      key("contact.lattice_floor", K::mapping, "", "",
          "a robot_voxel diagnostic: the voxel lattice's floor contact, a sphere per lattice voxel "
          "(contact/lattice_floor.h)"),
      key("contact.lattice_floor.point", K::vector3, "[m]", "[0, 0, 0]", "a point of the floor"),
      key("contact.lattice_floor.normal", K::vector3, "[-]", "[0, 0, 1]", "the floor's normal", {}, "not zero"),
      key("contact.lattice_floor.dhat", K::number, "[m]", "0.001", "barrier width", kPositive),
      key("contact.lattice_floor.kappa", K::number, "[Pa]", "required", "barrier stiffness", kPositive),
      key("contact.lattice_floor.eps_v", K::number, "[m/s]", "0.001", "friction smoothing velocity", kPositive),
      key("contact.lattice_floor.voxel_size", K::number, "[m]", "0.01", "the lattice's voxel size L", kPositive),
      key("contact.lattice_floor.mu", K::mapping, "", "required", "volume region -> friction coefficient"),
      key("contact.lattice_floor.mu.<region>", K::number, "[-]", "required",
          "the friction coefficient of the region's voxels", kNonNegative),
      key("contact.lattice_floor.gap_foot_columns", K::boolean, "", "false",
          "the study's third foot material on the feet's voxels in columns without a bladder"),
      key("contact.self", K::mapping, "", "", "self-contact between surface pairs (contact/self_contact.h)"),
      key("contact.self.pairs", K::pairs, "", "required",
          "surfaces that may touch, [[a, b], ...]; a name twice: within one surface"),
      key("contact.self.dhat", K::number, "[m]", "0", "barrier width; 0: 1e-3 x the bounding-box diagonal",
          kNonNegative),
      key("contact.self.kappa", K::number, "[Pa]", "0",
          "barrier stiffness; 0: 3 mu of the material under the pairs' surfaces", kNonNegative),
      key("contact.self.inflation", K::number, "[m]", "0", "candidate radius beyond dhat; 0: 20 dhat", kNonNegative),
      key("contact.self.max_trust_radius", K::number, "[m]", "0",
          "largest trust radius of a far node; below half the candidate radius: half of it", kNonNegative),
      key("contact.self.start", K::number, "[s]", "", "the barrier acts from this time on (absent: from the start)"),
      key("contact.self.project_hessian", K::boolean, "", "true", "project each pair's barrier Hessian to PSD"),
  };
  append(t, keys);
}

// A schedule played through bladders or voxel growth, with foot friction.
void add_actuation_keys(Keys& t) {
  const Keys keys = {
      key("actuation", K::mapping, "", "",
          "a schedule played through bladder cavities or voxel growth, with foot friction"),
      key("actuation.schedule", K::schedule, "", "required",
          "the schedule (actuation/schedule.h), shared with `morphfem hw play`; with cadence.mode settle a column "
          "starts once the valve-fed chambers' pressures have settled (actuation/schedule_clock.h)"),
      key("actuation.start", K::number, "[s]", "0",
          "simulation time of the gait's time 0 (settle mode: the earliest start of column 1)", kNonNegative),
      key("actuation.channel_map", K::file, "", "",
          "settle mode: the channel map (hardware/channel_map.h) whose tolerance_pa each chamber settles to "
          "(absent: 2000 Pa); it must drive every valve-fed chamber at the schedule's pressures"),
      choice("actuation.timing", "schedule (voxel with growth)", {"schedule", "voxel"},
             "the schedule's columns, or the voxel lattice's timing (actuation phase + settle)"),
      key("actuation.bladders", K::mapping, "", "", "channel -> cavity wall surface"),
      key("actuation.bladders.<channel>", K::text, "", "", "the surface region of channel b1..b8's chamber"),
      key("actuation.bladders_open_axis", K::axis, "", "", "every bladder an open sleeve along this axis"),
      key("actuation.growth", K::mapping, "", "",
          "instead of bladders: channel -> volume region grown as the voxel study's (actuation/voxel_growth.h)"),
      key("actuation.growth.<channel>", K::text, "", "", "the volume region of channel b1..b8"),
      key("actuation.core", K::text, "", "", "the core chamber's wall surface"),
      key("actuation.core_ramp_s", K::number, "[s]", "", "the core's pressure rises linearly over this time", {},
          "(0, start]"),
      key("actuation.core_open_axis", K::axis, "", "", "the core an open sleeve along this axis"),
      key("actuation.volume_axes", K::axes, "", "[x, y, z]", "the chambers' volume axes"),
      key("actuation.feet", K::mapping, "", "", "foot friction following the schedule (needs a contact floor)"),
      key("actuation.feet.foot_a", K::text, "", "", "foot A's surface region"),
      key("actuation.feet.foot_b", K::text, "", "", "foot B's surface region"),
      key("actuation.feet.mu_active", K::calibrated, "[-]", "2", "an active foot's friction coefficient"),
      key("actuation.feet.mu_inactive", K::calibrated, "[-]", "0.0001", "an inactive foot's friction coefficient"),
      key("actuation.weightless_inflated", K::boolean, "", "false",
          "with growth: an inflated bladder region carries no gravity (the voxel study's quirk)"),
      key("actuation.valves", K::mapping, "", "",
          "every scheduled cavity a gas cavity fed through a valve from its regulator"),
      key("actuation.valves.fill_time_s", K::calibrated, "[s]", "",
          "the rigid chamber's time constant V_ref / (C R T) (give fill_time_s or conductance)", kPositive),
      key("actuation.valves.conductance", K::calibrated, "[mol/(s Pa)]", "", "the valve's conductance C", kPositive),
      key("actuation.valves.temperature", K::calibrated, "[K]", "293.15", "the gas temperature", kPositive),
  };
  append(t, keys);
}

// The study's ground.
void add_environment_keys(Keys& t) {
  const Keys keys = {
      key("environment", K::mapping, "", "",
          "the study's ground: gravity rotated by the slope (instead of loads.gravity)"),
      key("environment.slope_deg", K::number, "[deg]", "0", "the slope", between(-90, 90)),
      key("environment.heading_deg", K::number, "[deg]", "the schedule's orientation",
          "the uphill heading from x; the gait is measured along it"),
      key("environment.gravity", K::number, "[m/s^2]", "9.80665", "gravity's magnitude", kNonNegative),
      key("environment.body_length", K::number, "[m]", "the mesh's y extent", "speeds are in body lengths per second",
          kPositive),
  };
  append(t, keys);
}

// A calibrated value, wherever one is allowed.
void add_calibrated_value_keys(Keys& t) {
  const Keys keys = {
      key("(calibrated value).calibration", K::file, "", "required",
          "a calibration file (core/calibration_file.h), e.g. written by `morphfem calibrate`"),
      key("(calibrated value).parameter", K::text, "", "required", "the parameter's name in that file"),
  };
  append(t, keys);
}

// Every key, section by section (the order of docs/scene-keys.md).
std::vector<SceneKey> build_table() {
  Keys t;
  for (auto add : {add_body_keys, add_load_keys, add_solver_keys, add_output_keys, add_dynamics_keys, add_contact_keys,
                   add_actuation_keys, add_environment_keys, add_calibrated_value_keys})
    add(t);
  return t;
}

std::vector<std::string> split(const std::string& path) {
  std::vector<std::string> out;
  if (path.empty()) return out;
  std::stringstream s(path);
  for (std::string part; std::getline(s, part, '.');) out.push_back(part);
  return out;
}

bool is_placeholder(const std::string& segment) { return !segment.empty() && segment.front() == '<'; }

// The table's paths split into segments, in the table's order.
const std::vector<std::vector<std::string>>& split_paths() {
  static const std::vector<std::vector<std::string>> paths = [] {
    std::vector<std::vector<std::string>> out;
    for (const SceneKey& k : scene_keys()) out.push_back(split(k.path));
    return out;
  }();
  return paths;
}

// The first `n` segments of the declared `pattern` match those of `path`.
bool prefix_matches(const std::vector<std::string>& pattern, const std::vector<std::string>& path, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!is_placeholder(pattern[i]) && pattern[i] != path[i]) return false;
  return true;
}

std::string escape_cell(std::string text) {
  for (size_t i = 0; (i = text.find('|', i)) != std::string::npos; i += 2) text.replace(i, 1, "\\|");
  return text;
}

}  // namespace

const char* key_type_name(KeyType type) {
  switch (type) {
    case KeyType::number:
      return "number";
    case KeyType::integer:
      return "integer";
    case KeyType::boolean:
      return "bool";
    case KeyType::text:
      return "text";
    case KeyType::choice:
      return "choice";
    case KeyType::file:
      return "file";
    case KeyType::names:
      return "name or list of names";
    case KeyType::axis:
      return "axis";
    case KeyType::axes:
      return "list of axes";
    case KeyType::vector3:
      return "vector3";
    case KeyType::mapping:
      return "mapping";
    case KeyType::list:
      return "list of mappings";
    case KeyType::time_function:
      return "time function";
    case KeyType::calibrated:
      return "number or calibrated value";
    case KeyType::coefficient:
      return "number, table or calibrated value";
    case KeyType::table:
      return "table";
    case KeyType::pairs:
      return "list of pairs";
    case KeyType::schedule:
      return "file or mapping";
    case KeyType::parameters:
      return "parameters";
  }
  return "?";
}

bool KeyRange::contains(double v) const {
  const bool above = lo_open ? v > lo : v >= lo;
  const bool below = hi_open ? v < hi : v <= hi;
  return above && below;  // false for NaN
}

std::string KeyRange::text() const {
  if (hi == kInf) return (lo_open ? "> " : ">= ") + number_text(lo);
  if (lo == -kInf) return (hi_open ? "< " : "<= ") + number_text(hi);
  return (lo_open ? "(" : "[") + number_text(lo) + ", " + number_text(hi) + (hi_open ? ")" : "]");
}

std::string SceneKey::requirement() const {
  const bool bounded = range && range->lo > -kInf && range->hi < kInf;  // "in [lo, hi]", else "> lo" or "<= hi"
  const std::string bound = range ? (bounded ? "in " : "") + range->text() : "";
  if (type == KeyType::integer) {
    if (range && range->lo == 1 && !range->lo_open && range->hi == kInf) return "must be a positive integer";
    return range ? "must be an integer " + bound : "must be an integer";
  }
  if (!range) return "";
  std::string what = "must be " + bound;
  if (range->lo == 0 && range->hi == kInf) what = range->lo_open ? "must be positive" : "must not be negative";
  if (!unit.empty() && unit != "[-]") what += " " + unit;
  return what;
}

const std::vector<SceneKey>& scene_keys() {
  static const std::vector<SceneKey> table = build_table();
  return table;
}

const SceneKey* find_scene_key(const std::string& path) {
  const std::vector<std::string> segments = split(path);
  const auto& paths = split_paths();
  for (size_t i = 0; i < paths.size(); ++i)
    if (paths[i].size() == segments.size() && prefix_matches(paths[i], segments, segments.size()))
      return &scene_keys()[i];
  return nullptr;
}

std::vector<std::string> scene_key_children(const std::string& path) {
  const std::vector<std::string> segments = split(path);
  const auto& paths = split_paths();
  std::set<std::string> children;
  for (const auto& p : paths)
    if (p.size() == segments.size() + 1 && !is_placeholder(p.back()) && prefix_matches(p, segments, segments.size()))
      children.insert(p.back());
  return {children.begin(), children.end()};
}

std::string scene_keys_markdown() {
  std::ostringstream out;
  out << "# Scene keys\n\n"
      << "Every key a scene file (`morphfem run SCENE.yaml`) may hold. The readers refuse any other key and "
         "check each range below; the table is `scene_keys()` in `sim/scene_keys.cpp`, and this page is its "
         "output:\n\n"
      << "    build/app/morphfem scene-keys > docs/scene-keys.md\n\n"
      << "Keys of the mappings in a list are under the list's path (`loads.cavities.pressure` is each "
         "cavity's pressure); a segment in angle brackets is a name the scene chooses. A time function is a "
         "number (ramped from 0 over the run) or a table `[[t0, v0], [t1, v1], ...]` (piecewise linear, times "
         "in s); a calibrated value is `{calibration: FILE, parameter: NAME}`. Default \"required\": the "
         "key must be given when its mapping is; empty: absent means not used.\n";
  std::string section = "-";
  for (const SceneKey& k : scene_keys()) {
    const std::string top = k.path.substr(0, k.path.find('.'));
    if (top != section) {
      section = top;
      out << "\n## "
          << (k.path.find('.') == std::string::npos && k.type != KeyType::mapping && k.type != KeyType::list &&
                      k.type != KeyType::parameters
                  ? "scene"
                  : top)
          << "\n\n| key | type | unit | default | range or values | description |\n|---|---|---|---|---|---|\n";
    }
    std::string values = k.range ? k.range->text() : k.limits;
    if (!k.choices.empty()) values = join(k.choices, ", ");
    out << "| `" << k.path << "` | " << key_type_name(k.type) << " | " << k.unit << " | " << escape_cell(k.fallback)
        << " | " << escape_cell(values) << " | " << escape_cell(k.doc) << " |\n";
  }
  return out.str();
}

}  // namespace morphfem
