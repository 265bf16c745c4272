// The morphing calibration (`morphfem calibrate morphing`): the core valve's supply and
// vacuum conductances so that the morph scene turns flat -> cylinder and back in the
// measured times; the inflated diameter and the flat height beside the measured ones;
// a calibration file.
#pragma once
#include <mpi.h>

#include <string>
#include <vector>

namespace morphfem {

struct MorphingOptions {
  std::string scene;  // empty: examples/physical/morph_valve_vacuum_slice.yaml
  std::string out = "results/calibrate/morphing";
  std::vector<std::string> sets;  // scene keys set last, KEY=VALUE
  // Measured: flat -> cylinder and cylinder -> flat times [s], inflated diameter and
  // flat height [m] (ROBOT.md, averages of 20 cycles).
  double inflate_s = 11.5, deflate_s = 4.7, diameter_m = 0.07, height_m = 0.012;
  double fraction = 0.9;    // a transition ends at this fraction of the shape change
  double tolerance = 0.02;  // relative error of both times at which the fit stops
  int max_runs = 5;
  std::string command_arguments;  // recorded in the calibration file after "morphfem calibrate morphing"
};

// Returns the exit status (0: the calibration file was written).
int calibrate_morphing(const MorphingOptions& options, MPI_Comm comm);

}  // namespace morphfem
