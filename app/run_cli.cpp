// `morphfem run SCENE.yaml [--set KEY=VALUE]... [--resume] [PETSc options]`.
#include <cstdio>
#include <iostream>

#include "app/commands.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "sim/scene.h"
#include "sim/simulation.h"

namespace morphfem {

namespace {

int rank_of(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

void print_summary(const Scene& scene, const SimulationResult& result) {
  if (result.resumed_at >= 0) std::printf("%s: resumed at t = %.6g s\n", scene.name.c_str(), result.resumed_at);
  std::printf("%s: %s, %ld dofs, %d steps, %d Newton iterations, %d step cuts, %.2f s", scene.name.c_str(),
              result.stats.completed ? "completed" : "FAILED", result.dofs, result.stats.steps, result.stats.newton_its,
              result.stats.step_cuts, result.stats.wall_s);
  for (size_t i = 0; i < result.cavity_names.size(); ++i)
    std::printf(", cavity %s: p = %.4g Pa, V = %.4g m^3", result.cavity_names[i].c_str(), result.cavity_pressure[i],
                result.cavity_volume[i]);
  std::printf("\n");
  if (!result.output_dir.empty())
    std::printf("results: %s/%s.xdmf (open in ParaView), %s/summary.json\n", result.output_dir.c_str(),
                scene.name.c_str(), result.output_dir.c_str());
  if (!result.stats.completed) std::fprintf(stderr, "morphfem: solve failed: %s\n", result.stats.failure.c_str());
}

}  // namespace

int run_command(const std::vector<std::string>& args, MPI_Comm comm) {
  CommandLine cl("morphfem run", "SCENE.yaml [options] [PETSc options]",
                 "Simulates a scene: builds its mesh and only the energy terms it declares, solves in adaptive "
                 "steps, and writes XDMF + HDF5 (ParaView) and summary.json to the scene's output.directory.");
  cl.repeated("--set", "KEY=VALUE", "sets a scene key after the file is read, e.g. --set solver.end_time=5")
      .flag("--resume",
            "continues an interrupted run from its last checkpoint (OUTPUT.partial), or extends a finished one "
            "to a later solver.end_time")
      .positionals(1, 1, "SCENE.yaml")
      .petsc_options();
  if (!cl.parse(args, std::cout)) return 0;
  const std::string path = cl.positional().front();
  YAML::Node doc = load_scene_yaml(path);
  for (const auto& assignment : cl.all("--set")) set_scene_key(doc, assignment, path);
  const Scene scene = scene_from_yaml(doc, path);
  RunOptions options;
  options.resume = cl.has("--resume");
  options.scene_text = scene_identity(doc);
  const SimulationResult result = run_scene(scene, comm, options);
  if (rank_of(comm) == 0) print_summary(scene, result);
  return result.stats.completed ? 0 : 3;
}

}  // namespace morphfem
