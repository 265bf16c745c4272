// morphfem: finite elements for shape-changing pneumatic soft robots. One program,
// one command per task (app/commands.h); `morphfem COMMAND --help` tells each one's
// arguments. PETSc options (-snes_monitor, -ksp_type, ...) pass through.
#include <dlfcn.h>
#include <petscsys.h>

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "core/errors.h"
#include "core/paths.h"
#include "hardware/cli.h"

namespace {

using Args = std::vector<std::string>;

struct Command {
  const char* name;
  const char* summary;
  // Commands that need neither MPI nor PETSc run without initialising them.
  std::function<int(const Args&)> without_petsc;
  std::function<int(const Args&, MPI_Comm)> with_petsc;
};

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"run", "simulate a scene (results to its output.directory)", {}, morphfem::run_command},
      {"verify", "verification cases: error against exact references beside wall time", {}, morphfem::verify_command},
      {"fit-materials", "fit hyperelastic laws to uniaxial tensile exports", morphfem::fit_materials_command, {}},
      {"robot", "the robot's gaits: validate, ladder, spread, morph, friction, benchmark", {}, morphfem::robot_command},
      {"search", "hill climbing / CMA-ES over shape, orientation and schedule", {}, morphfem::search_command},
      {"calibrate", "friction, material and morphing calibration from measurements", {}, morphfem::calibrate_command},
      {"scene-keys", "every scene key's type, unit, default and range", morphfem::scene_keys_command, {}},
      {"hw", "play schedules on the pneumatic regulators (check, play, emulate)", morphfem::hardware_main, {}},
  };
  return table;
}

std::string usage() {
  std::string out = "usage: morphfem COMMAND [arguments] [PETSc options]\ncommands:\n";
  for (const Command& c : commands()) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-14s %s\n", c.name, c.summary);
    out += line;
  }
  out += "morphfem COMMAND --help tells a command's arguments.\n";
  out += "examples, scripts and data: " + morphfem::resource_dir() + " (MORPHFEM_DATA_DIR overrides)\n";
  return out;
}

int rank_of_world() {
  int rank = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank);
  return rank;
}

int run_with_petsc(const Command& command, const Args& rest, int argc, char** argv) {
  if (PetscInitialize(&argc, &argv, nullptr, nullptr)) return 1;
  int status = 0;
  try {
    status = command.with_petsc(rest, PETSC_COMM_WORLD);
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
  const Args args(argv + 1, argv + argc);
  if (args.empty()) {
    std::fputs(usage().c_str(), stderr);
    return 2;
  }
  if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::fputs(usage().c_str(), stdout);
    return 0;
  }
  const Args rest(args.begin() + 1, args.end());
  for (const Command& command : commands()) {
    if (args[0] != command.name) continue;
    if (command.with_petsc) return run_with_petsc(command, rest, argc, argv);
    try {
      return command.without_petsc(rest);
    } catch (const morphfem::InputError& e) {
      std::fprintf(stderr, "morphfem: error: %s\n", e.what());
      return 2;
    }
  }
  std::fprintf(stderr, "morphfem: unknown command '%s'\n%s", args[0].c_str(), usage().c_str());
  return 2;
}
