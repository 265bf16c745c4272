// `morphfem robot COMMAND ...`: the robot's studies (robot/studies.h).
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "robot/studies.h"

namespace morphfem {

namespace {

using Args = std::vector<std::string>;

const char* kSetHelp =
    "sets a scene key last, e.g. --set geometry.order=2 or --set 'materials.bladder_*.density=15000' "
    "(a key ending in '*': every key with that prefix)";
const char* kRanks = "Cases are spread over the MPI ranks, one rank per case: mpirun -n 2 morphfem robot ...";

CommandLine robot_command_line(const std::string& name, const std::string& synopsis, const std::string& text) {
  CommandLine cl("morphfem robot " + name, synopsis, text);
  cl.petsc_options();
  return cl;
}

int validate(const Args& args, MPI_Comm comm) {
  CommandLine cl = robot_command_line(
      "validate", "[options]",
      "The voxel study's baselines (hand-designed rolling and inching, flat and 15 deg hill, four empty "
      "schedules): the voxel speed beside the finite-element speed of each preset, wall time, dofs, steps. "
      "Presets: voxel (the voxel-study preset, growth actuation), lattice-mechanics (the voxel-study preset "
      "with the lattice's floor spheres, bladder stiffness and mass; needs order 2), physical (the laminate "
      "with pressure actuation: examples/physical/roll_slice.yaml inflated, examples/physical/inch_flat.yaml "
      "flat).");
  cl.value("--fidelity", "L", "fidelity level (morphfem robot levels; or MESH:ORDER:MAX_STEP), default 0")
      .value("--cases", "A,B,...", "these cases only (default: all eight)")
      .value("--presets", "P,...", "voxel, lattice-mechanics, physical (default voxel,physical)")
      .value("--out", "DIR", "results (default results/robot/validate)")
      .repeated("--set", "KEY=VALUE", kSetHelp)
      .repeated("--set-physical", "KEY=VALUE", "a scene key of both physical templates")
      .repeated("--set-physical-round", "KEY=VALUE", "a scene key of the inflated physical template")
      .repeated("--set-physical-flat", "KEY=VALUE", "a scene key of the flat physical template")
      .epilog(kRanks);
  if (!cl.parse(args, std::cout)) return 0;
  ValidateOptions o;
  o.fidelity = cl.get("--fidelity", o.fidelity);
  o.cases = split_list(cl.get("--cases", ""));
  o.presets = split_list(cl.get("--presets", "voxel,physical"));
  o.out_dir = cl.get("--out", o.out_dir);
  o.set = cl.all("--set");
  o.set_physical = cl.all("--set-physical");
  o.set_physical_round = cl.all("--set-physical-round");
  o.set_physical_flat = cl.all("--set-physical-flat");
  return robot_validate(o, comm);
}

int ladder(const Args& args, MPI_Comm comm) {
  CommandLine cl = robot_command_line(
      "ladder", "--case NAME [options]",
      "One case on several fidelity levels: speed against wall time, and the cheapest level within 5 % of "
      "the finest.");
  cl.value("--case", "NAME", "the case (e.g. inch_flat)")
      .value("--levels", "L,...", "fidelity levels, coarsest first (default 0,1,2)")
      .value("--preset", "P", "voxel or lattice-mechanics (default voxel)")
      .value("--out", "DIR", "results (default results/robot/ladder)")
      .repeated("--set", "KEY=VALUE", kSetHelp)
      .epilog(kRanks);
  if (!cl.parse(args, std::cout)) return 0;
  LadderOptions o;
  o.case_name = cl.get("--case", "");
  o.levels = split_list(cl.get("--levels", "0,1,2"));
  o.preset = cl.get("--preset", o.preset);
  o.out_dir = cl.get("--out", o.out_dir);
  o.set = cl.all("--set");
  return robot_ladder(o, comm);
}

int spread(const Args& args, MPI_Comm comm) {
  CommandLine cl = robot_command_line(
      "spread", "--case NAME --vary KEY=V1,V2,... [options]",
      "One case run once per value of one scene key (a perturbation ensemble, e.g. --vary "
      "environment.heading_deg=-1,-0.5,0,0.5,1), on each level: every speed, their mean, standard deviation "
      "and range, and whether the levels' means agree; JSON and PNG.");
  cl.value("--case", "NAME", "the case (e.g. roll_hill15)")
      .value("--vary", "KEY=V1,V2,...", "the scene key varied and its values (at least two)")
      .value("--levels", "L,...", "fidelity levels (default 0; the physical preset uses its templates' own)")
      .value("--preset", "P", "voxel, lattice-mechanics or physical (default voxel)")
      .value("--out", "DIR", "results (default results/robot/spread_CASE)")
      .repeated("--set", "KEY=VALUE", kSetHelp)
      .epilog(kRanks);
  if (!cl.parse(args, std::cout)) return 0;
  SpreadOptions o;
  o.case_name = cl.get("--case", "");
  o.vary = cl.get("--vary", "");
  o.levels = split_list(cl.get("--levels", ""));
  o.preset = cl.get("--preset", o.preset);
  o.out_dir = cl.get("--out", "");
  o.set = cl.all("--set");
  return robot_spread(o, comm);
}

int morph(const Args& args, MPI_Comm comm) {
  CommandLine cl = robot_command_line(
      "morph", "[options]",
      "Shape change under core pressure: width and thickness of the mid-length cross-section against the "
      "core pressure; table, CSV, PNG.");
  cl.value("--scene", "FILE", "the scene (default examples/voxel/morph.yaml)")
      .value("--out", "DIR", "results (default the scene's output.directory, else results/robot/morph)")
      .repeated("--set", "KEY=VALUE", kSetHelp);
  if (!cl.parse(args, std::cout)) return 0;
  MorphOptions o;
  o.scene = cl.get("--scene", "");
  o.out_dir = cl.get("--out", "");
  o.set = cl.all("--set");
  return robot_morph(o, comm);
}

int friction_sweep(const Args& args, MPI_Comm comm) {
  CommandLine cl = robot_command_line(
      "friction-sweep", "[options]",
      "Inching on flat ground against the feet's mean friction (the voxel study's sfrict_results.csv: "
      "active - inactive = 2.0), beside the voxel points; PNG.");
  cl.value("--fidelity", "L", "fidelity level (default 0)")
      .value("--points", "N|all", "rows of the study's sweep, picked evenly (default 6)")
      .value("--out", "DIR", "results (default results/robot/friction_sweep)")
      .epilog(kRanks);
  if (!cl.parse(args, std::cout)) return 0;
  FrictionSweepOptions o;
  o.fidelity = cl.get("--fidelity", o.fidelity);
  o.points = cl.get("--points", o.points);
  o.out_dir = cl.get("--out", o.out_dir);
  return robot_friction_sweep(o, comm);
}

int friction_drag(const Args& args, MPI_Comm comm) {
  CommandLine cl = robot_command_line(
      "friction-drag", "[options]",
      "The test-machine pull test on a robot scene: the robot pulled at the scene's speed with its feet in "
      "each state; force against crosshead travel as exports `morphfem calibrate pull-tests` reads, their "
      "coefficients, PNG. Foot states are spread over the MPI ranks.");
  cl.value("--scene", "FILE", "the scene (default examples/physical/friction_drag.yaml)")
      .value("--feet", "S,...", "foot states: inflated, deflated (default both)")
      .value("--travel-mm", "D", "crosshead travel [mm] (default the scene's)")
      .value("--surface", "NAME", "surface named in the exports (default wood)")
      .value("--out", "DIR", "results (default results/robot/friction_drag)")
      .repeated("--set", "KEY=VALUE", kSetHelp);
  if (!cl.parse(args, std::cout)) return 0;
  FrictionDragOptions o;
  o.scene = cl.get("--scene", "");
  o.feet = split_list(cl.get("--feet", "inflated,deflated"));
  o.travel_mm = cl.get("--travel-mm", "");
  o.surface = cl.get("--surface", o.surface);
  o.out_dir = cl.get("--out", o.out_dir);
  o.set = cl.all("--set");
  return robot_friction_drag(o, comm);
}

int benchmark(const Args& args, MPI_Comm comm) {
  CommandLine cl = robot_command_line(
      "benchmark", "[options]",
      "Each hand-designed gait (19.8 s) on one rank: wall time beside the voxel simulator's 136-145 s on this "
      "machine, dofs, steps, Newton iterations, factorisations, the speed against its reference, and where the "
      "time went (physical: the templates' own meshes). Run it without mpirun.");
  cl.value("--fidelity", "L", "fidelity level (default 0)")
      .value("--presets", "P,...", "voxel, lattice-mechanics, physical (default voxel,physical)")
      .value("--gaits", "G,...", "roll_flat, roll_hill15, inch_flat, inch_hill15 (default all four)")
      .flag("--profile", "every logged event's seconds, share and calls per gait (PETSc's log)");
  if (!cl.parse(args, std::cout)) return 0;
  BenchmarkOptions o;
  o.profile = cl.has("--profile");
  if (cl.has("--gaits")) o.gaits = split_list(cl.get("--gaits", ""));
  o.fidelity = cl.get("--fidelity", o.fidelity);
  o.presets = split_list(cl.get("--presets", "voxel,physical"));
  return robot_benchmark(o, comm);
}

int scene(const Args& args, MPI_Comm) {
  CommandLine cl = robot_command_line(
      "scene", "--case NAME [options]",
      "Writes the scene one case runs (the template with the case's schedule, slope, fidelity level and the "
      "preset's keys) as a file for morphfem run. The gait examples (examples/gaits/) are these files.");
  cl.value("--case", "NAME", "the case (e.g. roll_flat)")
      .value("--preset", "P", "voxel, lattice-mechanics or physical (default voxel)")
      .value("--fidelity", "L", "fidelity level (default 0; the physical preset keeps its template's)")
      .value("--results", "DIR", "the scene's output.directory (default results/CASE)")
      .value("--out", "FILE", "the scene file written (default: standard output)")
      .repeated("--set", "KEY=VALUE", kSetHelp);
  if (!cl.parse(args, std::cout)) return 0;
  SceneFileOptions o;
  o.case_name = cl.get("--case", "");
  o.preset = cl.get("--preset", o.preset);
  o.fidelity = cl.get("--fidelity", o.fidelity);
  o.output_dir = cl.get("--results", "");
  o.out_file = cl.get("--out", "");
  o.set = cl.all("--set");
  return robot_scene_file(o);
}

int levels(const Args& args, MPI_Comm) {
  CommandLine cl("morphfem robot levels", "", "The fidelity levels (mesh size, element order, largest step).");
  if (!cl.parse(args, std::cout)) return 0;
  return robot_levels();
}

// The subcommands, each run on this command's communicator.
std::vector<Subcommand> subcommands(MPI_Comm comm) {
  return {
      {"validate", "the voxel study's baselines on each preset", on_comm(validate, comm)},
      {"ladder", "one case on several fidelity levels", on_comm(ladder, comm)},
      {"spread", "one case under a perturbation ensemble", on_comm(spread, comm)},
      {"morph", "shape change under core pressure", on_comm(morph, comm)},
      {"friction-sweep", "inching against the feet's friction", on_comm(friction_sweep, comm)},
      {"friction-drag", "the pull test on a robot scene", on_comm(friction_drag, comm)},
      {"benchmark", "wall time of each gait against the voxel simulator", on_comm(benchmark, comm)},
      {"scene", "the scene file of one case, for morphfem run", on_comm(scene, comm)},
      {"levels", "the fidelity levels", on_comm(levels, comm)},
  };
}

}  // namespace

int robot_command(const std::vector<std::string>& args, MPI_Comm comm) {
  return run_subcommand("morphfem robot", subcommands(comm), args, std::cout, std::cerr);
}

}  // namespace morphfem
