// `morphfem calibrate COMMAND ...`: test-machine exports and morphing data -> friction
// coefficients, material parameters and calibration files that scenes load (optim/).
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/paths.h"
#include "optim/friction_calibration.h"
#include "optim/material_calibration.h"
#include "optim/morph_calibration.h"
#include "optim/pull_test.h"

namespace morphfem {

namespace {

using Args = std::vector<std::string>;

// The arguments as given, recorded in calibration files after the command's name.
std::string as_given(const Args& args) {
  std::string out;
  for (const auto& a : args) out += " " + a;
  return out;
}

int pull_tests(const Args& args, MPI_Comm) {
  CommandLine cl("morphfem calibrate pull-tests", "--weight-N W FILES_OR_DIRS... [options]",
                 "Static (the study's: end of the linear regime; ASTM D1894: peak) and kinetic friction "
                 "coefficients of test-machine pull tests, with statistics per surface and foot state.");
  cl.value("--weight-N", "W", "the robot's weight [N] (required)")
      .value("--out", "DIR", "pull_tests.csv, pull_summary.json and a box plot")
      .positionals(1, -1, "FILES_OR_DIRS");
  if (!cl.parse(args, std::cout)) return 0;
  PullTestsOptions o;
  if (!cl.has("--weight-N"))
    throw InputError("calibrate pull-tests", "--weight-N W (the robot's weight [N]) is required");
  o.weight_N = cl.number("--weight-N", 0, 1e-9, 1e6);
  o.inputs = cl.positional();
  o.out_dir = cl.get("--out", "");
  o.plot_script = resource_dir() + "/scripts/plot_calibration.py";
  o.command_arguments = as_given(args);
  return analyse_pull_tests(o, std::cout);
}

int synth_pull(const Args& args, MPI_Comm) {
  CommandLine cl("morphfem calibrate synth-pull", "--out DIR [options]",
                 "Synthetic Instron-like pull-test exports with known coefficients (for testing the analysis).");
  cl.value("--out", "DIR", "where the exports go (required)")
      .value("--surface", "NAME", "surface (default wood)")
      .value("--foot", "STATE", "foot state (default inflated)")
      .value("--mu-linear", "M", "coefficient at the end of the linear regime (default 0.70)")
      .value("--mu-peak", "M", "peak coefficient (default 0.74)")
      .value("--mu-kinetic", "M", "kinetic coefficient (default 0.60)")
      .value("--weight-N", "W", "weight [N] (default 1)")
      .value("--stiffness", "K", "pre-slip slope [N/m] (default 250)")
      .value("--noise-N", "S", "load-cell noise [N] (default 0.005)")
      .value("--repeats", "N", "exports written (default 10)")
      .value("--seed", "N", "base seed (default 1)")
      .value("--rate-Hz", "F", "sampling rate [Hz] (default 50)")
      .flag("--decimal-comma", "write decimal commas");
  if (!cl.parse(args, std::cout)) return 0;
  SyntheticPullSet set;
  SyntheticPull& p = set.model;
  p.mu_linear = cl.number("--mu-linear", 0.70, 1e-3, 10);
  p.mu_peak = cl.number("--mu-peak", 0.74, 1e-3, 10);
  p.mu_kinetic = cl.number("--mu-kinetic", 0.60, 1e-3, 10);
  p.weight_N = cl.number("--weight-N", p.weight_N, 1e-3, 1e4);
  p.stiffness_N_per_m = cl.number("--stiffness", p.stiffness_N_per_m, 1.0, 1e7);
  p.noise_N = cl.number("--noise-N", p.noise_N, 0.0, 1e3);
  p.rate_Hz = cl.number("--rate-Hz", p.rate_Hz, 1.0, 1e4);
  p.seed = static_cast<unsigned>(cl.number("--seed", p.seed, 0, 1e9));
  set.repeats = cl.integer("--repeats", set.repeats, 1, 1000);
  set.out_dir = cl.get("--out", "");
  set.surface = cl.get("--surface", set.surface);
  set.foot = cl.get("--foot", set.foot);
  set.decimal_comma = cl.has("--decimal-comma");
  return write_synthetic_pulls(set, std::cout);
}

int drag(const Args& args, MPI_Comm comm) {
  CommandLine cl("morphfem calibrate drag", "--out FILE.csv [options]",
                 "A simulated pull test (the friction fit's model: a block on a spring pulled at constant speed) "
                 "written as a test-machine export.");
  cl.value("--out", "FILE.csv", "the export written")
      .value("--mu-static", "M", "static friction coefficient")
      .value("--mu-kinetic", "M", "kinetic friction coefficient")
      .value("--stiffness", "K", "pull-spring stiffness [N/m]")
      .value("--weight-N", "W", "the block's weight [N]")
      .value("--travel-mm", "D", "crosshead travel [mm]")
      .value("--dt", "S", "time step [s]")
      .value("--eps-v", "V", "friction's stick-slip velocity [m/s]")
      .value("--noise-N", "S", "standard deviation of Gaussian force noise [N] (default 0)")
      .value("--seed", "N", "seed of the noise (default 1)")
      .value("--surface", "NAME", "surface named in the export (default simulated)")
      .value("--foot", "STATE", "foot state named in the export (default unknown)")
      .petsc_options();
  if (!cl.parse(args, std::cout)) return 0;
  SimulatedPullOptions o;
  DragParameters& p = o.model;
  p.mu_static = cl.number("--mu-static", p.mu_static, 1e-3, 10);
  p.mu_kinetic = cl.number("--mu-kinetic", p.mu_kinetic, 1e-3, 10);
  p.stiffness = cl.number("--stiffness", p.stiffness, 1, 1e7);
  p.weight_N = cl.number("--weight-N", p.weight_N, 1e-3, 1e4);
  p.travel = 1e-3 * cl.number("--travel-mm", 1e3 * p.travel, 0.1, 1000);
  p.dt = cl.number("--dt", p.dt, 1e-5, 1);
  p.eps_v = cl.number("--eps-v", p.eps_v, 1e-9, 1);
  o.noise_N = cl.number("--noise-N", 0, 0, 1e3);
  o.seed = static_cast<unsigned>(cl.number("--seed", 1, 0, 1e9));
  o.surface = cl.get("--surface", o.surface);
  o.foot = cl.get("--foot", o.foot);
  o.out_file = cl.get("--out", "");
  if (o.out_file.empty()) throw InputError("calibrate drag", "--out FILE.csv is required");
  return write_simulated_pull(o, comm);
}

int friction(const Args& args, MPI_Comm comm) {
  CommandLine cl("morphfem calibrate friction", "--weight-N W FILES_OR_DIRS... [options]",
                 "Fits mu_static, mu_kinetic and the pull-spring stiffness so that the simulated drag test "
                 "reproduces the measured curves of one surface and foot state (PETSc TAO POUNDERS): values, "
                 "residuals, 95 % confidence intervals, overlay plot, calibration file.");
  cl.value("--weight-N", "W", "the robot's weight [N] (required)")
      .value("--surface", "NAME", "fit the curves of this surface only")
      .value("--foot", "STATE", "fit the curves of this foot state only")
      .value("--travel-mm", "D", "fitted crosshead travel [mm] (default 8)")
      .value("--dt", "S", "the model's time step [s]")
      .value("--start", "MS,MK,K", "start values mu_static,mu_kinetic,stiffness (default from the curves)")
      .value("--max-evals", "N", "simulations at most (default 60)")
      .value("--out", "DIR", "calibration file, overlay CSV and plot")
      .positionals(1, -1, "FILES_OR_DIRS")
      .petsc_options();
  if (!cl.parse(args, std::cout)) return 0;
  FrictionCalibrationOptions o;
  o.weight_N = cl.number("--weight-N", 0, 1e-3, 1e4);
  if (!cl.has("--weight-N"))
    throw InputError("calibrate friction", "--weight-N W (the robot's weight [N]) is required");
  o.inputs = cl.positional();
  o.surface = cl.get("--surface", "");
  o.foot = cl.get("--foot", "");
  o.out_dir = cl.get("--out", "");
  o.fit.travel = 1e-3 * cl.number("--travel-mm", 1e3 * o.fit.travel, 0.5, 1000);
  o.fit.model.dt = cl.number("--dt", o.fit.model.dt, 1e-4, 0.5);
  o.fit.max_evaluations = cl.integer("--max-evals", o.fit.max_evaluations, 5, 10000);
  if (cl.has("--start")) {
    for (const auto& item : split_list(cl.get("--start", "")))
      o.fit.start.push_back(number_option("friction", "--start", item, 1e-6, 1e7));
    if (o.fit.start.size() != 3) throw InputError("calibrate friction", "--start takes mu_static,mu_kinetic,stiffness");
  }
  o.command_arguments = as_given(args);
  return calibrate_friction(o, comm);
}

int materials(const Args& args, MPI_Comm) {
  CommandLine cl("morphfem calibrate materials", "[options]",
                 "Neo-Hookean, Yeoh and Ogden fits to uniaxial tensile exports with R^2, RMS and plots; with "
                 "--out, a calibration file scenes load ({calibration: materials.yaml, parameter: "
                 "dragonskin10.yeoh.c1}).");
  cl.value("--data-dir", "DIR", "the tensile exports (default ../shared/data/materials)")
      .value("--max-strain", "S", "largest engineering strain fitted (default 2.0)")
      .value("--out", "DIR", "fits as JSON, curves as CSV, plot, calibration file");
  if (!cl.parse(args, std::cout)) return 0;
  MaterialCalibrationOptions o;
  o.data_dir = cl.get("--data-dir", shared_data_dir() + "/materials");
  o.max_strain = cl.get("--max-strain", "");
  o.out_dir = cl.get("--out", "");
  o.command_arguments = as_given(args);
  return calibrate_materials(o);
}

int morphing(const Args& args, MPI_Comm comm) {
  CommandLine cl("morphfem calibrate morphing", "[options]",
                 "The core valve's supply and vacuum conductances so that the morph scene turns flat -> "
                 "cylinder and back in the measured times; the inflated diameter and the flat height against "
                 "the measured ones; calibration file.");
  MorphingOptions o;
  cl.value("--scene", "FILE", "the morph scene (default examples/physical/morph_valve_vacuum_slice.yaml)")
      .value("--inflate-s", "S", "measured flat -> cylinder time [s] (default 11.5)")
      .value("--deflate-s", "S", "measured cylinder -> flat time [s] (default 4.7)")
      .value("--diameter-m", "D", "measured inflated diameter [m] (default 0.07)")
      .value("--height-m", "H", "measured flat height [m] (default 0.012)")
      .value("--fraction", "F", "a transition ends at this fraction of the shape change (default 0.9)")
      .value("--tolerance", "T", "relative error of both times at which the fit stops (default 0.02)")
      .value("--max-runs", "N", "simulations at most (default 5)")
      .value("--out", "DIR", "results (default results/calibrate/morphing)")
      .repeated("--set", "KEY=VALUE", "sets a scene key last")
      .petsc_options();
  if (!cl.parse(args, std::cout)) return 0;
  o.scene = cl.get("--scene", "");
  o.out = cl.get("--out", o.out);
  o.sets = cl.all("--set");
  o.inflate_s = cl.number("--inflate-s", o.inflate_s, 1e-3, 1e4);
  o.deflate_s = cl.number("--deflate-s", o.deflate_s, 1e-3, 1e4);
  o.diameter_m = cl.number("--diameter-m", o.diameter_m, 1e-3, 10);
  o.height_m = cl.number("--height-m", o.height_m, 1e-4, 10);
  o.fraction = cl.number("--fraction", o.fraction, 0.5, 0.99);
  o.tolerance = cl.number("--tolerance", o.tolerance, 1e-4, 0.5);
  o.max_runs = cl.integer("--max-runs", o.max_runs, 1, 50);
  o.command_arguments = as_given(args);
  return calibrate_morphing(o, comm);
}

// The subcommands, each run on this command's communicator.
std::vector<Subcommand> subcommands(MPI_Comm comm) {
  return {
      {"pull-tests", "friction coefficients of test-machine pull tests, statistics per group",
       on_comm(pull_tests, comm)},
      {"synth-pull", "synthetic pull-test exports with known coefficients", on_comm(synth_pull, comm)},
      {"drag", "a simulated pull test written as an export", on_comm(drag, comm)},
      {"friction", "mu_static, mu_kinetic and stiffness fitted with the simulator", on_comm(friction, comm)},
      {"materials", "hyperelastic fits to tensile exports, calibration file", on_comm(materials, comm)},
      {"morphing", "the core valve's conductances from the morphing times", on_comm(morphing, comm)},
  };
}

}  // namespace

int calibrate_command(const std::vector<std::string>& args, MPI_Comm comm) {
  return run_subcommand("morphfem calibrate", subcommands(comm), args, std::cout, std::cerr);
}

}  // namespace morphfem
