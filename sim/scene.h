// Scenes: what to simulate, read from YAML or built in code (verification cases
// build the same struct). A scene declares only the physics it needs; the
// simulation builds only those energy terms.
//
// YAML layout (every key is declared in sim/scene_keys.h's table, printed as
// docs/scene-keys.md; unknown keys and numbers outside their range are errors):
//   name: demo
//   geometry: {type: thick_cylinder, inner_radius: 0.01, ..., mesh_size: 0.002, order: 2}
//   mesh: {file: body.msh}                      # instead of geometry
//   materials:                                  # volume region -> law (fem/material.h)
//     body: {model: neo_hookean, mu: 80e3, kappa: 80e6, density: 1070}
//   membranes:                                  # surface region -> thin sheet (fem/membrane.h)
//     fabric_sheet: {model: fabric, thickness: 5e-4, mu: 1e6, fibre_modulus: 2.6e8,
//                    fibres: [1, 0, 0, 0, 1, 0]}   # no mass: fold it into the volume's density
//   boundary:                                   # surface region -> prescribed displacement
//     - {surface: sym_x, fix: [x]}              # u_x = 0
//     - {surface: top, displacement: [0, 0, -1e-3]}   # ramped linearly over the run
//   loads:
//     gravity: [0, 0, -9.81]                    # m/s^2, needs `density` [kg/m^3]
//     cavities:
//       - {name: core, surfaces: [inner], volume_axes: [x, y], pressure: 40e3}
//         # pressure [Pa]: a number (ramped 0 -> value over the run) or a table
//         # [[t0, p0], [t1, p1], ...] (piecewise linear, times in s)
//       - {name: core, surfaces: [core_wall], open_axis: y, pressure: 12e3}
//         # open_axis: a sleeve open at both ends along that axis (volume axes the
//         # other two): pressure in the cross-sections only, no end-cap force
//     gas_cavities:                             # isothermal ideal gas fed through a valve
//       - {name: core, surfaces: [inner], volume_axes: [x, y, z], symmetry_factor: 1,
//          temperature: 293.15, initial_gauge_pressure: 0,          # K, Pa
//          supply_pressure: 50e3, conductance: 1e-8,                # Pa (gauge), mol/(s Pa)
//          vacuum_conductance: 3e-8}                                # while supply_pressure < 0
//         # supply_pressure / (vacuum_)conductance: a number (constant), a table
//         # [[t, v], ...] or a calibrated value {calibration: FILE, parameter: NAME}
//         # (`morphfem calibrate morphing` writes conductance_supply / _vacuum)
//     volume_cavities:                          # a prescribed volume; the pressure is its multiplier
//       - {name: b1, surfaces: [bladder_1_wall], volume_ratio: [[0, 1], [1, 6]],   # V*/V_ref table
//          penalty_modulus: 1e5, tolerance: 1e-6}   # Pa (see VolumeControlSpec), |V - V*| / V*
//         # traces a chamber's pressure-volume curve through a pressure maximum
//     tractions:
//       - {surface: tip, traction: [0, 0, -100]}  # dead load [Pa], ramped like pressure
//     pulls:                                    # test machine pulling a region through a spring
//       - {surface: foot, stiffness: 2000, velocity: [1.667e-3, 0, 0], start: 0}   # N/m, m/s, s
//   solver: {end_time: 1, initial_step: 0.1, min_step: 1e-6, max_step: 1,
//            linear_solver: mumps|gamg, quadrature_degree: 0, max_newton_its: 30,
//            easy_newton_its: 6,   # a step that converged in at most this many iterations grows 1.5x
//            formulation: displacement, hessian_projection: adaptive,
//            newton_velocity_tol: 0,   # m/s; > 0: Newton also stops once no node moves faster
//            extrapolate: true}        # Newton starts from the last step's velocity
//            # hessian_projection: adaptive (default) = the exact Hessian after a full Newton
//            # step, falling back to the projected one if it does not descend or the line
//            # search fails along it; always = terms project their Hessians to PSD in every
//            # iteration (self-contact pairs, friction's static-to-kinetic drop) (fem/solver.h)
//   dynamics:                                   # absent: quasi-static (no inertia)
//     {scheme: newmark|bdf2|implicit_euler, lumped: false, adaptive: false,
//      error_tolerance: 1e-4, shear_viscosity: 0, bulk_viscosity: 0,   # Pa s (Kelvin-Voigt)
//      initial_velocity: [0, 0, 0]}                                     # m/s
//   contact:
//     ground: {point: [0, 0, 0], normal: [0, 0, 1], surfaces: [zmin], dhat: 0, kappa: 0}
//             # 0: defaults, dhat 1e-3 x box diagonal, kappa [Pa] 3 mu of the material under
//             # most of the surfaces' area (contact_shear_modulus, sim/terms.h)
//     friction: {eps_v: 1e-4, lag_updates: 0,
//                regions: [{surface: zmin, mu_static: 0.5, mu_kinetic: 0.4}]}
//                # mu: a number or a table [[t, mu], ...] (coefficients that change over time)
//                # or a calibrated value {calibration: FILE, parameter: mu_static}
//                # (`morphfem calibrate friction` writes FILE; also for feet.mu_active/inactive,
//                # material and geometry parameters; `calibrate materials` writes e.g.
//                # dragonskin10.yeoh.c1)
//     self: {pairs: [[cavity_top, cavity_bottom]], dhat: 0, kappa: 0, inflation: 0, start: 2.0}
//           # surfaces that may touch (a name twice: within one surface); 0: defaults
//           # (contact/self_contact.h: dhat 1e-3 x box diagonal, kappa 3 mu of the material
//           # under the pairs' surfaces, inflation 20 dhat);
//           # start [s]: the barrier acts only from then on (default: from the start)
//           # project_hessian: true (default) projects each pair's barrier Hessian to PSD
//     lattice_floor: {point: [0, 0, -0.004], normal: [0, 0, 1], dhat: 5e-4, kappa: 6e5, eps_v: 1e-3,
//                     voxel_size: 0.01, mu: {skin: 2.0, bladder_1: 0.6667, ...}}
//           # a diagnostic, robot_voxel only: the voxel lattice's floor contact (Voxelyze), a
//           # sphere of radius L (s_x + s_y + s_z)/6 at each lattice voxel's mass centre,
//           # growing with its bladder (contact/lattice_floor.h); mu per volume region
//   actuation:                                  # a schedule file shared with `morphfem hw play`
//     {schedule: schedules/rolling.yaml, start: 1.0,      # gait time 0 at t = start [s]
//      bladders: {b1: bladder_1_wall, ...},               # channel -> cavity wall surface
//      bladders_open_axis: y,                             # chambers without end walls: open sleeves
//      core: core_wall, volume_axes: [x, y, z], core_open_axis: y,   # (open sleeve core)
//      feet: {foot_a: foot_a, foot_b: foot_b, mu_active: 2.0, mu_inactive: 1.0e-4}}
//     # schedule: a file, or the schedule itself inline (a mapping in the schedule file format)
//     # or, instead of bladder cavities, the voxel study's growth actuation
//     # (actuation/voxel_growth.h): channel -> bladder volume region, voxel timing
//     {schedule: ..., start: 1.5, growth: {b1: bladder_1, ...}, core: core_wall,
//      core_ramp_s: 1.0, feet: {...}, weightless_inflated: false}
//     # valves: {fill_time_s: 0.05} (or {conductance: C} [mol/(s Pa)], temperature: 293.15):
//     #   each scheduled cavity is a gas cavity fed through a valve whose supply is the
//     #   regulator's output (the schedule's setpoint); fill_time_s: the rigid
//     #   chamber's time constant V_ref / (C R T). Without valves a cavity IS at its
//     #   setpoint (pressure control), which has no nearby equilibrium past a
//     #   chamber's pressure maximum (thin walls balloon).
//     # weightless_inflated: the voxel study's inflated bladder voxels get no gravity
//     # timing: schedule (columns of column_s) or voxel (the lattice's column
//     # lengths: actuation phase + settle with every foot active); growth implies voxel.
//     # A schedule whose cadence.mode is settle (actuation/schedule.h) starts each column
//     # once the valve-fed chambers' pressures have settled, as `hw play --mode settle`
//     # (actuation/schedule_clock.h); channel_map: MAP gives the tolerances (tolerance_pa).
//     # It needs valves and the schedule timing.
//   environment:                                # the study's ground: gravity rotated
//     {slope_deg: 15, heading_deg: 90,          # heading default: the schedule's orientation
//      gravity: 9.80665, body_length: 0.22}     # m/s^2; m (default: the mesh's y extent)
//     # g = |g| (-sin s cos h, -sin s sin h, -cos s): uphill is the heading (cos h, sin h, 0).
//     # With an actuation schedule the run reports the gait: displacement of the mean
//     # node position along the heading from `start` to the end of the gait, in BL/s.
//   output: {directory: results/demo, every: 1,  # every: write each n-th step
//            checkpoint_s: 600}                 # wall seconds between checkpoints (0: only
//     # the final one); `morphfem run SCENE --resume` continues an interrupted run from
//     # its last checkpoint, or extends a finished one to a later solver.end_time.
#pragma once
#include <yaml-cpp/yaml.h>

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "actuation/cavity.h"
#include "actuation/gas_cavity.h"
#include "actuation/schedule.h"
#include "contact/friction.h"
#include "contact/ground.h"
#include "contact/lattice_floor.h"
#include "contact/self_contact.h"
#include "core/params.h"
#include "fem/inertia.h"
#include "fem/membrane.h"
#include "fem/pull_spring.h"
#include "fem/solver.h"

namespace morphfem {

struct BoundarySpec {
  std::string surface;
  std::array<bool, 3> components{false, false, false};
  Eigen::Vector3d displacement = Eigen::Vector3d::Zero();  // final value [m], ramped
  std::string where;
  // Code-built scenes only: u(X, t) [m] instead of the ramped constant.
  std::function<Eigen::Vector3d(const Eigen::Vector3d& X, double t)> field;
};

struct TractionSpec {
  std::string surface;
  Eigen::Vector3d traction = Eigen::Vector3d::Zero();  // [Pa]
  TimeFunction scale;                                  // dimensionless factor of time
  std::string where;
};

// contact.lattice_floor: the voxel lattice's floor contact on a robot_voxel body, a
// sphere at each lattice voxel's centre (contact/lattice_floor.h; a diagnostic).
struct LatticeFloorScene {
  LatticeFloorSpec floor;            // plane, barrier, friction smoothing
  double voxel_size = 0.01;          // the lattice's nominal voxel size L [m]
  std::map<std::string, double> mu;  // volume region -> friction coefficient
  // actuation.feet without contact.ground: foot surface -> its friction mu(t), for the
  // skin voxels (both layers) over the foot's y range, as the lattice's foot voxels.
  std::vector<std::pair<std::string, TimeFunction>> feet;
  // contact.lattice_floor.gap_foot_columns: the study's third foot material on the skin
  // voxels of the feet's bands whose column holds no bladder (x = 4, 8, 12): its friction
  // (voxel_gap_foot_friction: raised at the first settle phase, never lowered) and its
  // voxels' x scale 0.9 (pancakerobot.jl), for the sphere radius.
  bool gap_foot_columns = false;
  std::optional<TimeFunction> gap_foot_mu;  // set by actuation.feet (voxel timing)
};

// dynamics: inertia and viscous damping (a scene without them is quasi-static).
struct DynamicsSpec {
  InertiaOptions inertia;                                      // time scheme, mass lumping, error control
  double shear_viscosity = 0.0, bulk_viscosity = 0.0;          // [Pa s]
  Eigen::Vector3d initial_velocity = Eigen::Vector3d::Zero();  // [m/s]
};

// The gait measurement of a scene that plays a schedule (see `environment`).
struct GaitSpec {
  bool enabled = false;
  // Simulation times of the gait's first column and its end [s]; in settle mode the
  // earliest start of the first column, and the end is decided by the run (NaN).
  double start = 0.0, end = 0.0;
  double nominal_s = 0.0;  // the schedule's nominal duration (speeds divide by it in fixed mode, as the study) [s]
  Cadence cadence;         // the schedule's cadence (actuation/schedule.h), reported with the speed
  std::vector<double> column_starts;  // fixed mode: the columns' start times [s] (settle: the run's clock)
  Eigen::Vector3d heading = Eigen::Vector3d::UnitX();
  double body_length = 0.0;  // [m]; <= 0: the mesh's extent along y
};

// A schedule played in settle mode (its cadence.mode): what the run's schedule
// clock needs (actuation/schedule_clock.h) and the loads that follow it.
struct SettleSpec {
  Schedule schedule;
  double start = 0.0;                               // the earliest start of column 1 [s] (actuation.start)
  std::array<double, kNumChannels> tolerance_pa{};  // per channel [Pa]: actuation.channel_map's tolerance_pa
  std::string channel_map;                          // the map's file ("": none, the default tolerance)
  // Gas cavities (index into Scene::gas_cavities) fed by a channel through a valve:
  // the clock watches their pressures; their supply follows the clock (but the core's,
  // whose setpoint does not depend on the column).
  std::vector<std::pair<std::size_t, int>> valves;
  // Friction regions (index into FrictionSpec::regions) of the feet, and their channel.
  std::vector<std::pair<std::size_t, int>> feet;
  double mu_active = 2.0, mu_inactive = 1e-4;  // the feet's coefficients (actuation.feet)
};

struct Scene {
  std::string name = "scene";
  std::string source;                         // file the scene came from ("" if built in code)
  ParamSet geometry;                          // builder parameters (type, sizes, mesh_size, order)
  std::string mesh_file;                      // or a .msh file
  std::map<std::string, ParamSet> materials;  // volume region -> law parameters
  std::vector<MembraneSpec> membranes;        // sheets on surface regions
  std::vector<BoundarySpec> boundary;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  std::vector<CavitySpec> cavities;
  std::vector<GasCavitySpec> gas_cavities;
  std::vector<VolumeControlSpec> volume_cavities;
  std::vector<TractionSpec> tractions;
  std::vector<PullSpringSpec> pulls;  // fem/pull_spring.h; force in tables "pulls" and summary.json
  // Code-built scenes only: a body force b(X, t) [N/m^3] on every cell (e.g. a
  // manufactured solution's load), integrated with `body_force_degree`.
  std::function<Eigen::Vector3d(const Eigen::Vector3d& X, double t)> body_force;
  int body_force_degree = 4;
  // Each present only if the scene declares it (the simulation builds only those terms).
  std::optional<DynamicsSpec> dynamics;  // inertia and viscous damping
  std::optional<GroundContactSpec> ground;
  std::optional<FrictionSpec> friction;            // on the ground contact
  std::optional<LatticeFloorScene> lattice_floor;  // the voxel lattice's floor contact (a diagnostic)
  std::optional<SelfContactSpec> self_contact;     // between declared surface pairs
  std::string schedule_file;  // the actuation schedule, if any (its loads are in cavities/friction)
  // Values taken from calibration files (core/calibration_file.h), recorded in summary.json.
  struct CalibrationUse {
    std::string key, file, sha256, kind, parameter;
    double value = 0, std_error = 0;
  };
  std::vector<CalibrationUse> calibrations;
  // Prescribed growth (active strain) of volume regions: stretches (g_x, g_y, g_z)(t).
  std::vector<std::pair<std::string, std::function<Eigen::Vector3d(double)>>> growth;
  // The lattice's quirk (actuation.weightless_inflated): a growing region carries no
  // gravity while its thickness stretch g_z > 1 (inflating, inflated or deflating).
  bool weightless_inflated = false;
  GaitSpec gait;
  std::optional<SettleSpec> settle;  // a schedule in settle mode (actuation.schedule's cadence)
  SolverOptions solver;
  std::string formulation = "displacement";  // elastic element formulation (fem/elastic.h)
  int quadrature_degree = 0;
  std::string output_dir;  // empty: no files
  int output_every = 1;
  double checkpoint_s = 600.0;  // wall seconds between checkpoints (0: only the final one)
};

// Reads and checks a scene file. Throws InputError("file:line:col", what) on the
// first problem; nothing is created on disk.
Scene read_scene(const std::string& path);
// The scene file's document (InputError if missing or not YAML, with the line).
YAML::Node load_scene_yaml(const std::string& path);
// The same from a parsed document (e.g. a template with keys overridden in code);
// `path` names it in messages and anchors relative file names.
Scene scene_from_yaml(const YAML::Node& root, const std::string& path);

// Sets one key of a scene document from "a.b.c=VALUE" (VALUE in YAML; a path segment
// ending in '*' means every key of that mapping with that prefix, "*" every key). The mappings on the path must exist;
// the last key may be new. Throws InputError naming `where` and the path.
void set_scene_key(YAML::Node root, const std::string& assignment, const std::string& where);

}  // namespace morphfem
