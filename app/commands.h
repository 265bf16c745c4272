// The program's commands: each parses its arguments (core/command_line.h) and calls a
// library. Every one returns the process's exit status and throws InputError on a bad
// command line or input (exit 2) and SolveError on a failed solve (exit 3).
#pragma once
#include <mpi.h>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace morphfem {

int run_command(const std::vector<std::string>& args, MPI_Comm comm);
int verify_command(const std::vector<std::string>& args, MPI_Comm comm);
int fit_materials_command(const std::vector<std::string>& args);
// fit-materials reading `default_data_dir` unless --data-dir is given, printing to `out`;
// --help prints the usage and returns 0.
int fit_materials_main(const std::vector<std::string>& args, const std::string& default_data_dir, std::ostream& out);
int robot_command(const std::vector<std::string>& args, MPI_Comm comm);
int search_command(const std::vector<std::string>& args, MPI_Comm comm);
int calibrate_command(const std::vector<std::string>& args, MPI_Comm comm);
int scene_keys_command(const std::vector<std::string>& args);

// A subcommand's runner on `comm`, as core/command_line.h's Subcommand takes it.
inline std::function<int(const std::vector<std::string>&)> on_comm(int (*run)(const std::vector<std::string>&,
                                                                              MPI_Comm),
                                                                   MPI_Comm comm) {
  return [run, comm](const std::vector<std::string>& args) { return run(args, comm); };
}

}  // namespace morphfem
