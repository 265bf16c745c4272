// The actuation of a scene (a schedule played from `start` through bladder
// cavities or the voxel study's growth, foot friction, valves) and its
// environment (slope, heading, gravity, body length).
#include <cmath>
#include <filesystem>
#include <limits>

#include "actuation/schedule_loads.h"
#include "actuation/voxel_growth.h"
#include "hardware/channel_map.h"
#include "sim/scene_reader.h"

namespace morphfem {

namespace {

// The schedule: written inline (a mapping in the schedule file format) or a
// file (relative to the scene).
Schedule read_schedule_key(const SceneReader &r, const YAML::Node &a, Scene &scene) {
  if (!a["schedule"]) r.fail(a, "actuation", "missing key 'schedule' (a schedule file)");
  if (a["schedule"].IsMap()) {
    YAML::Emitter text;
    text << a["schedule"];
    scene.schedule_file = r.at(a["schedule"]);
    return parse_schedule(text.c_str(), scene.schedule_file + " (actuation.schedule)");
  }
  std::filesystem::path file = r.text(a["schedule"], "actuation.schedule");
  if (file.is_relative()) file = std::filesystem::path(r.file).parent_path() / file;
  scene.schedule_file = file.string();
  return read_schedule(scene.schedule_file);  // its own errors name its file and line
}

// The keys of `actuation` after its schedule, read in the order of their
// checks.
struct ActuationReader {
  ActuationReader(const SceneReader &r, const YAML::Node &a, Scene &scene, const Schedule &schedule)
      : r(r), a(a), scene(scene), schedule(schedule) {}

  const SceneReader &r;
  const YAML::Node &a;
  Scene &scene;
  const Schedule &schedule;
  const std::string key = "actuation";
  const std::size_t first_breakpoint = scene.solver.breakpoints.size();  // the schedule's come after
  const VoxelActuation voxel;
  double start = 0.0;
  std::string timing;  // "schedule" or "voxel"
  std::array<bool, 3> axes{true, true, true};
  bool valves = false;
  GasCavitySpec valve;
  double mu_active = 2.0, mu_inactive = 1e-4;  // the feet's (actuation.feet)

  void read_timing();
  void read_growth();
  void read_weightless();
  void read_valves();
  void add_cavity(int channel, const std::string &surface, const char *open_key, TimeFunction pressure);
  void read_bladders();
  void read_core();
  void read_feet();
  void read_cadence(std::size_t first_valve, std::size_t first_foot);
  void read_channel_map(SettleSpec &settle) const;
};

// The start, the timing and the gait they give.
void ActuationReader::read_timing() {
  r.optional(a, key, "start", start);
  if (a["growth"] && a["bladders"]) r.fail(a["growth"], key + ".growth", "give either bladders or growth, not both");
  timing = a["growth"] ? "voxel" : "schedule";
  if (a["timing"]) {
    timing = r.choice(a["timing"], key + ".timing");
    if (a["growth"] && timing != "voxel")
      r.fail(a["timing"], key + ".timing", "growth actuation runs on the voxel timing");
  }
  const double gait_s = timing == "voxel" ? voxel_timeline(schedule, voxel).duration() : schedule.duration();
  scene.gait.enabled = true;
  scene.gait.start = start;
  scene.gait.end = start + gait_s;
  scene.gait.nominal_s = schedule.duration();
  scene.gait.cadence = schedule.cadence;
  if (timing == "voxel")
    for (double t : voxel_timeline(schedule, voxel).column_start) scene.gait.column_starts.push_back(start + t);
  else
    for (int k = 0; k < schedule.total_columns(); ++k)
      scene.gait.column_starts.push_back(start + k * schedule.column_s);
  // A run shorter than the gait plays only part of the schedule; its summary
  // then says gait_complete: false and reports no speed.
}

void ActuationReader::read_growth() {
  const auto g = a["growth"];
  if (!g) return;
  if (!g.IsMap()) r.fail(g, key + ".growth", "expected a map {b1: volume region, ...}");
  for (const auto &kv : g) {
    const std::string name = kv.first.as<std::string>();
    const int channel = channel_index(name);
    if (channel < 0 || channel >= kNumBladders)
      r.fail(kv.first, key + ".growth." + name, "not a bladder channel (b1..b8)");
    scene.growth.emplace_back(r.text(kv.second, key + ".growth." + name),
                              voxel_bladder_growth(schedule, channel, start, schedule.core_pressure_pa, voxel));
  }
  // The growth is linear between the timeline's times: steps land on them.
  const VoxelTimeline line = voxel_timeline(schedule, voxel);
  std::vector<double> times;
  for (const auto *phase : {&line.column_start, &line.actuation_end, &line.column_end})
    for (double t : *phase) times.push_back(start + t);
  r.land_on(times);
}

void ActuationReader::read_weightless() {
  if (const auto w = a["weightless_inflated"]) {
    if (!a["growth"]) r.fail(w, key + ".weightless_inflated", "needs growth actuation");
    scene.weightless_inflated = r.flag(w, key + ".weightless_inflated");
  }
}

// actuation.valves: every scheduled cavity holds gas fed through a valve from
// its regulator, whose output follows the schedule's setpoint (gas cavities,
// actuation/gas_cavity.h), instead of being held at the setpoint itself.
void ActuationReader::read_valves() {
  const YAML::Node v = a["valves"];
  valves = static_cast<bool>(v);
  if (!valves) return;
  const std::string vkey = key + ".valves";
  if (!v.IsMap()) r.fail(v, vkey, "expected a map {fill_time_s: T} or {conductance: C}");
  r.allow(v, vkey);
  if (static_cast<bool>(v["fill_time_s"]) == static_cast<bool>(v["conductance"]))
    r.fail(v, vkey, "give exactly one of fill_time_s [s] and conductance [mol/(s Pa)]");
  auto calibrated = [&](const char *k) { return r.calibrated_number(v[k], vkey + "." + k); };
  if (v["fill_time_s"]) valve.fill_time = calibrated("fill_time_s");
  if (v["conductance"]) valve.conductance = TimeFunction::constant(calibrated("conductance"));
  if (v["temperature"]) valve.temperature = calibrated("temperature");
}

// A channel's cavity; with actuation.<open_key> an open sleeve along that axis
// (its volume axes the other two, whatever volume_axes says).
void ActuationReader::add_cavity(int channel, const std::string &surface, const char *open_key, TimeFunction pressure) {
  CavitySpec spec;
  spec.name = channel_name(channel);
  spec.surfaces = {surface};
  spec.axes = axes;
  spec.pressure = std::move(pressure);
  r.land_on(spec.pressure);
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
}

void ActuationReader::read_bladders() {
  if (const auto b = a["bladders"]) {
    if (!b.IsMap()) r.fail(b, key + ".bladders", "expected a map {b1: surface, ...}");
    for (const auto &kv : b) {
      const std::string name = kv.first.as<std::string>();
      const int channel = channel_index(name);
      if (channel < 0 || channel >= kNumBladders)
        r.fail(kv.first, key + ".bladders." + name, "not a bladder channel (b1..b8)");
      // bladders_open_axis: chambers without end walls (a plane-strain slice)
      add_cavity(channel, r.text(kv.second, key + ".bladders." + name), "bladders_open_axis",
                 channel_pressure(schedule, channel, start));
    }
  } else if (a["bladders_open_axis"]) {
    r.fail(a["bladders_open_axis"], key + ".bladders_open_axis", "needs 'bladders'");
  }
}

void ActuationReader::read_core() {
  if (a["core"]) {
    TimeFunction core = channel_pressure(schedule, kChannelCore, start);
    if (a["core_ramp_s"]) {  // the core rises linearly from 0 over [0,
                             // core_ramp_s], then holds
      const double ramp = r.number(a["core_ramp_s"], key + ".core_ramp_s");
      if (!(ramp > 0) || ramp > start) r.fail(a["core_ramp_s"], key + ".core_ramp_s", "must be in (0, start]");
      core = TimeFunction::ramp(schedule.core_pressure_pa, ramp);
    }
    add_cavity(kChannelCore, r.text(a["core"], key + ".core"), "core_open_axis", core);
  } else if (a["core_ramp_s"] || a["core_open_axis"]) {
    const char *k = a["core_ramp_s"] ? "core_ramp_s" : "core_open_axis";
    r.fail(a[k], key + "." + k, "needs 'core'");
  }
}

// Foot friction following the schedule: friction regions on the ground, or the
// lattice floor's foot voxels.
void ActuationReader::read_feet() {
  const auto f = a["feet"];
  if (!f) return;
  r.allow(f, key + ".feet");
  if (!scene.ground && !scene.lattice_floor)
    r.fail(f, key + ".feet", "foot friction needs contact.ground (or contact.lattice_floor)");
  if (f["mu_active"]) mu_active = r.calibrated_number(f["mu_active"], key + ".feet.mu_active");
  if (f["mu_inactive"]) mu_inactive = r.calibrated_number(f["mu_inactive"], key + ".feet.mu_inactive");
  // Ground contact: friction regions; the lattice floor only: its foot voxels.
  if (scene.ground && !scene.friction) scene.friction.emplace();
  for (const auto &[foot, channel] :
       {std::pair<const char *, int>{"foot_a", kChannelFootA}, {"foot_b", kChannelFootB}}) {
    if (!f[foot]) continue;
    const TimeFunction mu = timing == "voxel"
                                ? voxel_foot_friction(schedule, channel, start, mu_active, mu_inactive, voxel)
                                : foot_friction(schedule, channel, start, mu_active, mu_inactive);
    r.land_on(mu);
    const std::string surface = r.text(f[foot], key + ".feet." + foot);
    if (scene.ground)
      scene.friction->regions.push_back({surface, mu, mu});
    else
      scene.lattice_floor->feet.push_back({surface, mu});
  }
  if (scene.lattice_floor && scene.lattice_floor->gap_foot_columns && !scene.ground) {
    LatticeFloorScene &lattice = *scene.lattice_floor;
    if (timing != "voxel")
      r.fail(f, key + ".feet", "contact.lattice_floor.gap_foot_columns needs the voxel timing (growth actuation)");
    lattice.gap_foot_mu = voxel_gap_foot_friction(schedule, start, mu_active, mu_inactive, voxel);
    r.land_on(*lattice.gap_foot_mu);
  }
}

// A schedule in settle mode (its cadence.mode): the valve-fed chambers read from
// first_valve on in scene.gas_cavities, the feet's friction regions from
// first_foot on, and the tolerances of actuation.channel_map.
void ActuationReader::read_cadence(std::size_t first_valve, std::size_t first_foot) {
  if (schedule.cadence.mode != Cadence::Mode::settle) {
    if (a["channel_map"])
      r.fail(a["channel_map"], key + ".channel_map",
             "the map's tolerances serve settle mode, but schedule " + schedule.source + " has cadence.mode fixed");
    return;
  }
  const std::string why = "schedule " + schedule.source + " plays in settle mode (cadence.mode: settle)";
  if (timing != "schedule")
    r.fail(a["timing"] ? a["timing"] : a["growth"], key + ".timing",
           why + ", which needs the schedule timing and valve-fed chambers, not the voxel timing");
  if (!valves)
    r.fail(a, key + ".valves",
           why + ": its columns follow the chambers' pressures, which need the valve model (give actuation.valves)");
  if (first_valve == scene.gas_cavities.size())
    r.fail(a, key, why + ": no chamber (actuation.bladders or actuation.core) is fed through a valve to watch");
  if (a["feet"] && !scene.ground)
    r.fail(a["feet"], key + ".feet", why + ": foot friction follows the columns on contact.ground only");
  SettleSpec settle;
  settle.schedule = schedule;
  settle.start = start;
  settle.mu_active = mu_active;
  settle.mu_inactive = mu_inactive;
  for (std::size_t i = first_valve; i < scene.gas_cavities.size(); ++i)
    settle.valves.emplace_back(i, channel_index(scene.gas_cavities[i].wall.name));
  std::size_t region = first_foot;
  for (const auto &[foot, channel] : {std::pair<const char *, int>{"foot_a", kChannelFootA}, {"foot_b", kChannelFootB}})
    if (a["feet"] && a["feet"][foot]) settle.feet.emplace_back(region++, channel);
  read_channel_map(settle);
  // The columns start where the run decides, always at a step's end: the fixed-time
  // schedule's breakpoints are not stops (ramp ends within a column are not either).
  scene.solver.breakpoints.resize(first_breakpoint);
  scene.gait.end = std::numeric_limits<double>::quiet_NaN();  // decided by the run
  scene.gait.column_starts.clear();
  scene.settle = std::move(settle);
}

// actuation.channel_map: the tolerance_pa of every watched channel. The map must
// accept the schedule and play its pressures on those channels, as `hw play` would
// without --allow-map-override. Without a map, every channel has the default.
void ActuationReader::read_channel_map(SettleSpec &settle) const {
  settle.tolerance_pa.fill(kDefaultSettleTolerancePa);
  if (!a["channel_map"]) return;
  const std::string where = key + ".channel_map";
  std::filesystem::path file = r.text(a["channel_map"], where);
  if (file.is_relative()) file = std::filesystem::path(r.file).parent_path() / file;
  settle.channel_map = file.string();
  const hw::ChannelMap map = hw::read_channel_map(settle.channel_map);  // its own errors name its file and line
  try {
    map.check_schedule(schedule);
  } catch (const InputError &e) {
    r.fail(a["channel_map"], where, e.what());
  }
  hw::PressurePlan plan = map.plan(schedule);
  std::vector<hw::PressureChange> changed;
  for (const hw::PressureChange &change : plan.changes)
    for (const auto &[index, channel] : settle.valves)
      if (change.channel == channel) changed.push_back(change);
  if (!changed.empty()) {
    plan.changes = changed;
    r.fail(a["channel_map"], where,
           "the map " + settle.channel_map +
               " does not play the schedule's pressures on the valve-fed chambers, which the simulator does:\n" +
               plan.describe_changes() + "put the map's pressures in the schedule's pressures block");
  }
  for (const auto &[index, channel] : settle.valves)
    if (const hw::ChannelSpec *driven = map.find(channel)) settle.tolerance_pa[channel] = driven->tolerance_pa;
}

}  // namespace

std::optional<Schedule> read_actuation(const SceneReader &r, const YAML::Node &a, Scene &scene) {
  if (!a) return std::nullopt;
  r.allow(a, "actuation");
  std::optional<Schedule> schedule = read_schedule_key(r, a, scene);
  ActuationReader actuation(r, a, scene, *schedule);
  actuation.read_timing();
  actuation.read_growth();
  actuation.read_weightless();
  if (a["volume_axes"]) actuation.axes = r.axes(a["volume_axes"], "actuation.volume_axes");
  actuation.read_valves();
  const std::size_t first_valve = scene.gas_cavities.size();
  actuation.read_bladders();
  actuation.read_core();
  const std::size_t first_foot = scene.friction ? scene.friction->regions.size() : 0;
  actuation.read_feet();
  actuation.read_cadence(first_valve, first_foot);
  return schedule;
}

void read_environment(const SceneReader &r, const YAML::Node &root, const std::optional<Schedule> &schedule,
                      Scene &scene) {
  const auto e = root["environment"];
  if (!e) return;
  const std::string key = "environment";
  r.allow(e, key);
  if (root["loads"] && root["loads"]["gravity"])
    r.fail(e, key, "give gravity either in loads.gravity or through environment, not both");
  double slope = 0.0;
  r.optional(e, key, "slope_deg", slope);
  double heading = schedule ? schedule->orientation_deg : 0.0;
  r.optional(e, key, "heading_deg", heading);
  double g = 9.80665;
  r.optional(e, key, "gravity", g);
  const double deg = M_PI / 180.0, s_ = slope * deg, h = heading * deg;
  // The voxel study's rotated gravity: uphill along the heading (cos h, sin h,
  // 0).
  scene.gravity = g * Eigen::Vector3d(-std::sin(s_) * std::cos(h), -std::sin(s_) * std::sin(h), -std::cos(s_));
  scene.gait.heading = Eigen::Vector3d(std::cos(h), std::sin(h), 0.0);
  r.optional(e, key, "body_length", scene.gait.body_length);
}

}  // namespace morphfem
