// `morphfem hw ...`: the hardware subcommands (args exclude "morphfem hw").
//   morphfem hw check SCHEDULE [--map MAP [--allow-map-override]]
//   morphfem hw play SCHEDULE --map MAP [--port [DEVICE=]PATH]... [options]
//   morphfem hw emulate --map MAP [--link DEVICE=PATH]... [options]
//   morphfem hw [COMMAND] --help       usage on standard output, exit 0
// Unknown, repeated or malformed options are refused (exit 2). Returns the
// process exit code (hardware/player.h); messages go to stderr.
#pragma once
#include <string>
#include <vector>

namespace morphfem {
int hardware_main(const std::vector<std::string>& args);
}  // namespace morphfem
