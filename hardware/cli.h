// `morphfem hw ...`: the hardware subcommands (args exclude "morphfem hw").
//   morphfem hw check SCHEDULE [--map MAP]
//   morphfem hw play SCHEDULE --map MAP [--port [DEVICE=]PATH]... [--mode fixed|settle|step]
//                    [--time-scale S] [--tick-ms N] [--reply-timeout-ms N] [--reconnect-s S]
//                    [--settle-timeout-s S] [--min-hold-s S] [--tracking-fault-pa P] [--tracking-fault-s S]
//                    [--tracking-fault-samples N] [--log FILE.csv] [--dry-run] [--no-display]
//   morphfem hw emulate --map MAP [--link DEVICE=PATH]... [--time-scale S] [--seed N]
//                    [--noise-pa P] [--rupture-pa P] [--fault KIND@T[:ARG]]... [--duration-s S]
// Returns the process exit code (see hardware/player.h); messages go to stderr.
#pragma once
#include <string>
#include <vector>

namespace morphfem {
int hardware_main(const std::vector<std::string>& args);
}  // namespace morphfem
