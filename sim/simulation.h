// Runs a scene: builds the mesh and only the energy terms the scene declares,
// solves in adaptive load steps, writes XDMF/HDF5 results and summary.json.
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
#include "sim/scene.h"

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

// Shear modulus [Pa] of the material under most of the surfaces' area (each
// boundary face takes the material of the cell it bounds; 0 if none). The
// default contact barrier stiffness is E ~ 3 mu of the material a contact presses
// into, not of the stiffest material in the body: with kappa 2,300x the skin's E
// (the 100 MPa fabric sheet, whose 0.5 mm edges reach the outer surface, inside a
// 43 kPa skin) a node entering the barrier rests within sqrt(p / 3 kappa) dhat of
// its edge, where the barrier is nearly cubic, and Newton converges linearly
// (residual / 4 per iteration) until it gets there.
double contact_shear_modulus(const Mesh& mesh, const std::vector<std::shared_ptr<const Material>>& materials,
                             const std::vector<std::string>& surfaces);

// Builds the mesh the scene asks for on rank 0 and broadcasts it; checks every
// region name the scene uses. Throws InputError on bad input before any output
// directory is created.
Mesh build_scene_mesh(const Scene& scene, MPI_Comm comm);

// The lattice voxels of a robot_voxel scene with contact.lattice_floor as floor
// contact points (contact/lattice_floor.h): the material point at each voxel box's
// centre, its footprint, its sphere radius L (s_x + s_y + s_z)/6 growing with the
// region's actuation.growth, and its friction coefficient: the region's, or for skin
// voxels over a foot's y range (both layers, as the lattice's foot voxels) the
// foot's mu(t) from actuation.feet. Throws InputError naming the scene key.
std::vector<LatticePoint> lattice_points(const Scene& scene, const Mesh& mesh);

// Runs the scene. A solve that fails after all step cuts returns with
// stats.completed == false and stats.failure set; the last converged state is
// in `u` and in the output (written with status "failed").
SimulationResult run_scene(const Scene& scene, MPI_Comm comm, const RunOptions& options = {});

}  // namespace morphfem
