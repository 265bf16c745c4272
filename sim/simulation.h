// Runs a scene: builds the model (the mesh and only the energy terms the scene
// declares: build_scene_mesh and build_model in sim/model.h, the term builders,
// contact_shear_modulus and lattice_points in sim/terms.h), steps it in adaptive
// load steps with checkpoints (sim/stepper.h), writes XDMF/HDF5 results and
// summary.json (sim/observers.h).
#pragma once
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fem/assembly.h"
#include "fem/material.h"
#include "fem/solver.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"
#include "sim/model.h"
#include "sim/scene.h"
#include "sim/terms.h"

namespace morphfem {

struct SimulationResult {
  Mesh mesh;      // as solved (nodes renumbered by the partitioner)
  RowMatrixXd u;  // final displacement, n_nodes x 3 [m] (every rank)
  RunStats stats;
  long dofs = 0;
  std::vector<std::string> cavity_names;
  std::vector<double> cavity_pressure, cavity_volume;  // final [Pa], [m^3]
  double min_J = 0;                                    // smallest det F over quadrature points at the end
  double mass_kg = 0;                                  // sum of rho V over the cells [kg]
  std::string output_dir;                              // where results went ("" if none)
  // Gait (scenes with an actuation schedule): centroid path (t, x, y, z) every step,
  // displacement along the heading over the gait [m] and speed [body lengths / s].
  std::vector<std::array<double, 4>> trajectory;
  bool gait_complete = false;
  double gait_displacement_m = 0, speed_bl_per_s = 0;
  // The cadence the speed belongs to: the schedule's (cadence.mode, min_hold_s), the
  // simulation times at which the columns began (settle mode: as the run decided
  // them so far; a (K+1)-th entry is the gait's end) and the gait time the speed
  // divides by (fixed: the nominal one, settle: the realised one) [s].
  Cadence cadence;
  std::vector<double> column_starts;
  double gait_s = 0;
  bool stopped = false;    // stopped by RunOptions::stop_after_steps (output left in OUTPUT.partial)
  double resumed_at = -1;  // time of the checkpoint this run resumed from [s] (-1: not resumed)
};

struct RunOptions {
  RunOptions(bool write_output = true, bool progress = true) : write_output(write_output), progress(progress) {}
  bool write_output = true;  // honour scene.output_dir
  bool progress = true;      // progress line with ETA on stderr (rank 0)
  // Optional hook after each converged step (e.g. a verification case sampling a
  // quantity along the load path): time, displacement (all nodes), cavity data.
  std::function<void(double t, const Mesh&, const RowMatrixXd& u, const SimulationResult&)> on_step;
  // Checkpoints (scene key output.checkpoint_s): the run's whole state goes to
  // OUTPUT.partial/checkpoint.h5 every checkpoint_s of wall time and, at the end, to
  // OUTPUT/checkpoint.h5. resume = true continues from the checkpoint of an
  // interrupted run (OUTPUT.partial) or extends a finished one (OUTPUT, to a later
  // solver.end_time) as if it had never stopped: same steps, same results.
  // scene_text identifies the scene (scene_identity() of its document); a
  // checkpoint of another scene is refused.
  bool resume = false;
  std::string scene_text;
  // If not empty: written as OUTPUT.partial/scene.yaml when the run starts (so it ends
  // up in OUTPUT), for a scene built in memory (robot cases): an interrupted run then
  // resumes with `morphfem run OUTPUT.partial/scene.yaml --resume`.
  std::string scene_file;
  // Test hook: after this many steps of this process, save a checkpoint and stop
  // as a killed run would (the output stays in OUTPUT.partial); 0: no stop.
  int stop_after_steps = 0;
};

// The scene document as checkpoints identify it: every key but solver.end_time and
// output.checkpoint_s.
std::string scene_identity(const YAML::Node& doc);

// Runs the scene. A solve that fails after all step cuts returns with
// stats.completed == false and stats.failure set; the last converged state is
// in `u` and in the output (written with status "failed").
SimulationResult run_scene(const Scene& scene, MPI_Comm comm, const RunOptions& options = {});

}  // namespace morphfem
