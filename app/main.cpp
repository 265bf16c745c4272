// morphfem: finite elements for shape-changing pneumatic soft robots.
//
//   morphfem run SCENE.yaml [--set KEY=VALUE]... [--resume] [PETSc options]   simulate a scene
//   morphfem verify [--case NAME]... [--quick] [--json] [--out DIR]
//   morphfem fit-materials [--data-dir DIR] [--max-strain S] [--json]
//   morphfem hw emulate|play|check ...            regulators (hardware/README.md)
//
// PETSc options (-snes_monitor, -ksp_type, -pc_type, ...) pass through.
#include <dlfcn.h>
#include <petscsys.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "app/calibrate_cli.h"
#include "app/plot.h"
#include "app/robot_study.h"
#include "app/scene.h"
#include "app/search_cli.h"
#include "app/simulation.h"
#include "app/verify.h"
#include "core/errors.h"
#include "core/json.h"
#include "fem/material_fit.h"
#include "hardware/cli.h"

namespace {

const char* kUsage =
    "usage: morphfem <command> [arguments] [PETSc options]\n"
    "commands:\n"
    "  run SCENE.yaml [--set KEY=VALUE]... [--resume]\n"
    "                               simulate a scene; results to the scene's output.directory;\n"
    "                               --set a.b.c=VALUE sets a scene key last (e.g. solver.end_time=5);\n"
    "                               --resume continues an interrupted run from its last checkpoint\n"
    "                               (or extends a finished one to a later solver.end_time)\n"
    "  verify [--case NAME]... [--hard] [--quick] [--json] [--out DIR]\n"
    "                               verification cases (patch, mms, cylinder, cantilever) with\n"
    "                               error against the reference beside wall time\n"
    "  fit-materials [--data-dir DIR] [--max-strain S] [--json]\n"
    "                               fit hyperelastic laws to uniaxial test exports\n"
    "  robot validate|ladder|levels  the robot's gaits against the voxel study, fidelity ladders\n"
    "  search ...                   hill-climbing experiments (morphfem search --help)\n"
    "  calibrate ...                friction, material and morphing calibration (morphfem calibrate --help)\n"
    "  hw emulate|play|check ...    pneumatic regulators (see hardware/README.md)\n";

int rank_of_world() {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  return rank;
}

int cmd_run(const std::vector<std::string>& args) {
  // morphfem run SCENE.yaml [--set KEY=VALUE ...] [PETSc options (one dash)]
  std::string path;
  std::vector<std::string> assignments;
  morphfem::RunOptions options;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--resume") {
      options.resume = true;
    } else if (a == "--set") {
      if (i + 1 >= args.size()) throw morphfem::InputError("morphfem run", "--set needs KEY=VALUE");
      assignments.push_back(args[++i]);
    } else if (a.rfind("--", 0) == 0) {
      throw morphfem::InputError("morphfem run", "unknown option '" + a + "' (run takes --set KEY=VALUE and --resume)");
    } else if (!a.empty() && a[0] != '-' && path.empty()) {
      path = a;
    }
  }
  if (path.empty()) throw morphfem::InputError("morphfem run", "missing the scene file (morphfem run SCENE.yaml)");
  YAML::Node doc = morphfem::load_scene_yaml(path);
  for (const auto& assignment : assignments) morphfem::set_scene_key(doc, assignment, path);
  morphfem::Scene scene = morphfem::scene_from_yaml(doc, path);
  options.scene_text = morphfem::scene_identity(doc);
  auto result = morphfem::run_scene(scene, PETSC_COMM_WORLD, options);
  if (rank_of_world() == 0) {
    if (result.resumed_at >= 0) std::printf("%s: resumed at t = %.6g s\n", scene.name.c_str(), result.resumed_at);
    std::printf("%s: %s, %ld dofs, %d steps, %d Newton iterations, %d step cuts, %.2f s", scene.name.c_str(),
                result.stats.completed ? "completed" : "FAILED", result.dofs, result.stats.steps,
                result.stats.newton_its, result.stats.step_cuts, result.stats.wall_s);
    for (size_t i = 0; i < result.cavity_names.size(); ++i)
      std::printf(", cavity %s: p = %.4g Pa, V = %.4g m^3", result.cavity_names[i].c_str(), result.cavity_pressure[i],
                  result.cavity_volume[i]);
    std::printf("\n");
    if (!result.output_dir.empty())
      std::printf("results: %s/%s.xdmf (open in ParaView), %s/summary.json\n", result.output_dir.c_str(),
                  scene.name.c_str(), result.output_dir.c_str());
    if (!result.stats.completed) std::fprintf(stderr, "morphfem: solve failed: %s\n", result.stats.failure.c_str());
  }
  return result.stats.completed ? 0 : 3;
}

void print_table(const std::vector<morphfem::VerificationRecord>& records) {
  std::printf("%-11s %-48s %3s %2s %9s %8s %12s %12s %9s %6s %8s %6s\n", "case", "quantity", "lvl", "P", "h [m]",
              "dofs", "value", "reference", "rel_err", "rate", "wall_s", "newton");
  for (const auto& r : records)
    std::printf("%-11s %-48s %3d %2d %9.3g %8ld %12.6g %12.6g %9.2e %6s %8.2f %6d\n", r.case_name.c_str(),
                r.quantity.c_str(), r.level, r.order, r.h, r.dofs, r.value, r.reference, r.rel_error,
                r.rate != 0 ? std::to_string(r.rate).substr(0, 5).c_str() : "-", r.wall_s, r.newton_its);
}

int cmd_verify(const std::vector<std::string>& args) {
  morphfem::VerifyOptions options;
  bool json = false;
  std::string out_dir = "results/verify";
  for (size_t i = 0; i < args.size(); ++i) {
    if (args[i] == "--case" && i + 1 < args.size())
      options.cases.push_back(args[++i]);
    else if (args[i] == "--quick")
      options.quick = true;
    else if (args[i] == "--hard")
      options.hard = true;
    else if (args[i] == "--json")
      json = true;
    else if (args[i] == "--out" && i + 1 < args.size())
      out_dir = args[++i];
    else if (args[i].rfind("--", 0) == 0)
      throw morphfem::InputError("morphfem verify", "unknown option " + args[i]);
  }
  options.progress = !json;
  auto records = morphfem::run_verification(options, PETSC_COMM_WORLD);
  if (rank_of_world() != 0) return 0;
  std::string lines;
  for (const auto& r : records) lines += r.json() + "\n";
  if (json)
    std::fputs(lines.c_str(), stdout);
  else
    print_table(records);
  std::filesystem::create_directories(out_dir);
  const std::string jsonl = out_dir + "/verification.jsonl";
  morphfem::write_file_atomic(jsonl, lines);
  morphfem::run_plot_script("plot_verification.py", {jsonl, out_dir}, "the verification");
  if (!json) std::printf("records: %s; plots: %s/*.png\n", jsonl.c_str(), out_dir.c_str());
  return 0;
}

}  // namespace

// Parallelism is MPI through PETSc: one BLAS thread per rank. OpenBLAS's own
// threads (MUMPS calls it) contend with the other ranks and with themselves on
// small fronts; measured on the 4,326-dof voxel robot with another job on the
// second core: LU factorisation 48 ms -> 16 ms. OPENBLAS_NUM_THREADS, if set, wins.
static void single_threaded_blas() {
  if (std::getenv("OPENBLAS_NUM_THREADS")) return;
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) set(1);
}

int main(int argc, char** argv) {
  single_threaded_blas();
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::fputs(kUsage, args.empty() ? stderr : stdout);
    return args.empty() ? 2 : 0;
  }
  const std::string command = args[0];
  std::vector<std::string> rest(args.begin() + 1, args.end());
  // Commands that need neither MPI nor PETSc.
  try {
    if (command == "hw") return morphfem::hardware_main(rest);
    if (command == "fit-materials")
      return morphfem::fit_materials_main(rest, std::string(MORPHFEM_SOURCE_DIR) + "/../shared/data/materials");
  } catch (const morphfem::InputError& e) {
    std::fprintf(stderr, "morphfem: error: %s\n", e.what());
    return 2;
  }
  if (command != "run" && command != "verify" && command != "search" && command != "calibrate" && command != "robot") {
    std::fprintf(stderr, "morphfem: unknown command '%s'\n%s", command.c_str(), kUsage);
    return 2;
  }
  if (PetscInitialize(&argc, &argv, nullptr, nullptr)) return 1;
  int status = 0;
  try {
    if (command == "run")
      status = cmd_run(rest);
    else if (command == "verify")
      status = cmd_verify(rest);
    else if (command == "search") {
      morphfem::register_robot_fitness();
      status = morphfem::search_main(rest, PETSC_COMM_WORLD);
    } else if (command == "robot")
      status = morphfem::robot_main(rest, PETSC_COMM_WORLD);
    else
      status = morphfem::calibrate_main(rest, PETSC_COMM_WORLD);
  } catch (const morphfem::InputError& e) {
    if (rank_of_world() == 0) std::fprintf(stderr, "morphfem: error: %s\n", e.what());
    status = 2;
  } catch (const morphfem::SolveError& e) {
    if (rank_of_world() == 0) std::fprintf(stderr, "morphfem: solve failed: %s\n", e.what());
    status = 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "morphfem: internal error: %s\n", e.what());
    status = 4;
  }
  PetscFinalize();
  return status;
}
