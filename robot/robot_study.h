// The robot as a study: gait scenes built from a template scene with the
// schedule, the slope and the fidelity level set in code, the validation of the
// voxel study's baselines (../shared/data/voxel-study/baselines.txt), fidelity
// ladders, and the "robot" fitness of the search (optim/fitness.h).
//
// A robot case = template scene (examples/voxel/*.yaml: geometry, materials,
// contact, friction regions, dynamics) + schedule (written inline into the scene)
// + slope + fidelity level. What the case sets in the template:
//   actuation.schedule   the case's schedule (inline), column_s = the lattice's
//                        column (11670 steps of 1.0602e-4 s = 1.23731 s), 2 repeats;
//   actuation.start      1.5 s: the core ramps to its pressure over 0.5 s, then the
//                        robot settles for 1 s (gravity, contact) before column 1;
//   environment          slope_deg; the heading is the schedule's orientation;
//   solver.end_time      start + the gait's duration on the voxel timing;
//   geometry.mesh_size, geometry.order, solver.max_step   from the fidelity level;
//   output.directory     the case's result folder (or none);
//   then the case's overrides (`--set KEY=VALUE` on the command line).
// The speed is the scene's gait measurement: displacement of the mean node
// position along the heading from start to the end of the gait, divided by the
// body length (0.22 m) and the schedule's nominal duration (16 columns), as the
// voxel study's BL/s.
#pragma once
#include <mpi.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "actuation/schedule.h"
#include "core/json.h"
#include "sim/simulation.h"

namespace morphfem {

// A fidelity level of the robot scenes (mesh, element order, largest time step).
struct RobotFidelity {
  std::string name;
  double mesh_size = 0.015;  // [m]
  int order = 1;
  double max_step = 0.05;  // [s]
};
// Levels "0" (coarsest, the search level) .. "3" (finest).
const std::vector<RobotFidelity>& robot_fidelity_levels();
// Throws InputError naming the known levels.
const RobotFidelity& find_robot_fidelity(const std::string& name);

struct RobotCase {
  std::string name;            // e.g. "inch_flat"
  std::string template_scene;  // path of the template scene
  Schedule schedule;
  double slope_deg = 0;
  double voxel_bl_per_s = std::numeric_limits<double>::quiet_NaN();  // the voxel study's result, if any
  // Foot friction (active / inactive); NaN keeps the template's.
  double mu_foot_active = std::numeric_limits<double>::quiet_NaN();
  double mu_foot_inactive = std::numeric_limits<double>::quiet_NaN();
  // Scene keys set last, "a.b.c=VALUE" (see set_scene_key), e.g. for a diagnostic run.
  std::vector<std::string> overrides = {};
  // The physical preset with pressure actuation (template examples/physical/roll_slice.yaml):
  // the case's matrix, orientation, column length and repeats go into the template's
  // schedule, which keeps its pressures (chambers, core line pressure) and its timing;
  // the fidelity level leaves the template's mesh and time step alone.
  bool physical = false;
  // The voxel-study preset with the lattice's own mechanics (lattice_mechanics_overrides).
  bool lattice_mechanics = false;
};

// The eight cases of baselines.txt: the hand-designed rolling (0 deg, 12 kPa) and
// inching (90 deg, 0 kPa) gaits on flat ground and on the 15 deg hill, and the four
// empty schedules. `source_dir` is the repository (templates in examples/voxel/).
std::vector<RobotCase> voxel_baseline_cases(const std::string& source_dir);

// The baseline cases the physical laminate can play, on two templates:
//  * inflated (core > 0) at heading 0 on the rolling slice (examples/physical/
//    roll_slice.yaml; a plane-strain cross-section cannot move along the body), the
//    core at its line pressure (50 kPa) instead of 12 kPa: roll_flat, roll_hill15,
//    empty_0deg_12kPa_flat;
//  * flat (core 0) on the full-length body (examples/physical/inch_flat.yaml):
//    inch_flat, inch_hill15, empty_0deg_0kPa_flat, empty_90deg_0kPa_hill15.
// The inflated body heading 90 deg (empty_90deg_12kPa_hill15) has no physical scene.
std::vector<RobotCase> physical_baseline_cases(const std::string& source_dir);

// The voxel-study preset with the lattice's own mechanics, as scene keys set after
// the case's (preset "lattice-mechanics" of `robot validate`; docs/validation.md, "With the
// lattice's floor contact and stiff bladders the slice rolls"):
//   contact.lattice_floor   each of the lattice's 1,428 voxels touches the floor as a
//                           sphere (Voxelyze's floor contact) instead of the faces,
//                           skin mu 2.0, bladders 2/3, feet from the schedule;
//   bladder mu x 12.5       a grown lattice voxel keeps its nominal link stiffness,
//                           5-10x stiffer than a grown continuum block (the slice
//                           rolls from 7.5x on, 12.5x is the middle of the plateau);
//   bladder density 15000   the lattice's bladder mass: 2 cm of voxels at 3000 kg/m^3
//                           in the preset's 4 mm blocks [kg/m^3].
// The floor sits 3 mm below the body so that no deflated voxel's sphere starts in it.
// Linear tetrahedra lock in bending and do not roll with it: use order 2.
std::vector<std::string> lattice_mechanics_overrides();
// voxel_baseline_cases with those keys (lattice_mechanics = true).
std::vector<RobotCase> lattice_mechanics_cases(const std::string& source_dir);

// The schedule of a case as the lattice plays it: the voxel study's column length,
// two repeats.
Schedule voxel_study_schedule(Schedule schedule);

// The case's scene document: the template with the keys above set.
YAML::Node robot_scene_yaml(const RobotCase& c, const RobotFidelity& level, const std::string& output_dir);

// The case's scene document as a file: a comment line naming the case, its level and
// its template, then the YAML.
std::string robot_scene_text(const RobotCase& c, const RobotFidelity& level, const YAML::Node& doc);

// Builds and runs the case (no files unless output_dir is given; then the scene
// document is saved beside the results as scene.yaml).
SimulationResult run_robot_case(const RobotCase& c, const RobotFidelity& level, const std::string& output_dir,
                                MPI_Comm comm, bool progress);

// The search fitness "robot": speed [BL/s] of `genome` on the voxel-study preset
// (template examples/voxel/inch_flat.yaml) at fidelity level `fidelity`.
double robot_speed(const Genome& genome, double slope_deg, const std::string& fidelity, MPI_Comm comm);
// Registers "robot" with optim/fitness.h (called by the program before a search).
void register_robot_fitness();

// What a robot run reports to the commands that run many (validate, ladder,
// friction-sweep, spread); completed = 1 if the run and its gait finished.
struct CaseOutcome {
  double speed = 0, displacement = 0, wall_s = 0, dofs = 0, steps = 0, newton = 0, completed = 0;
  static constexpr int kFields = 7;
};
// The folder of a case's results: NAME_LLEVEL, NAME_lattice_LLEVEL (lattice-mechanics
// preset) or NAME_physical.
std::string case_folder(const RobotCase& c, const RobotFidelity& level);
// Runs jobs (case, level) round-robin over the ranks of `comm`, one rank per job, each
// writing into OUT_DIR/NAME_LLEVEL (physical cases: OUT_DIR/NAME_physical; nothing if
// out_dir is empty); every rank returns every outcome, in job order. A progress bar
// with ETA on rank 0.
std::vector<CaseOutcome> run_robot_jobs(const std::vector<std::pair<RobotCase, RobotFidelity>>& jobs,
                                        const std::string& out_dir, MPI_Comm comm);
// The case called `name` (InputError on --case naming the known ones otherwise).
const RobotCase& find_case(const std::vector<RobotCase>& cases, const std::string& name);
// The eight baseline cases of a preset ("voxel", "lattice-mechanics", "physical"; the
// physical preset has fewer); InputError naming `allowed` if `preset` is not in it.
std::vector<RobotCase> preset_cases(const std::string& preset, const std::vector<std::string>& allowed);
// One row of a command's JSON summary: the case, its level and its outcome.
Json outcome_json(const RobotCase& c, const RobotFidelity& level, const CaseOutcome& o);

// `--vary KEY=V1,V2,...` of `robot spread`: the scene key and its values, as given (each
// run sets KEY=V). InputError if it is not KEY=..., has fewer than two values, or
// repeats a value.
std::pair<std::string, std::vector<std::string>> parse_variation(const std::string& spec);
// The runs of `robot spread`, level by level, value by value: `base` named CASE_vK
// with its own keys (a preset's), then `sets` (--set), then KEY=V_k.
std::vector<std::pair<RobotCase, RobotFidelity>> spread_jobs(const RobotCase& base,
                                                             const std::vector<std::string>& sets,
                                                             const std::string& key,
                                                             const std::vector<std::string>& values,
                                                             const std::vector<RobotFidelity>& levels);
// The speeds of an ensemble of runs: n completed (failed ones left out), mean, sample
// standard deviation sqrt(sum (v - mean)^2 / (n - 1)) (NaN for n < 2), median (the
// middle value, or the mean of the two middle ones: robust to one run that tumbles
// differently), range, how many moved forward (v > 0). [BL/s]
struct SpreadStats {
  int n = 0, failed = 0, forward = 0;
  double mean = std::numeric_limits<double>::quiet_NaN(), std = std::numeric_limits<double>::quiet_NaN();
  double median = std::numeric_limits<double>::quiet_NaN();
  double min = std::numeric_limits<double>::quiet_NaN(), max = std::numeric_limits<double>::quiet_NaN();
  // std / sqrt(n): the standard error of the mean (NaN for n < 2).
  double standard_error() const { return n > 1 ? std / std::sqrt(static_cast<double>(n)) : std; }
};
SpreadStats spread_stats(const std::vector<CaseOutcome>& runs);

}  // namespace morphfem
