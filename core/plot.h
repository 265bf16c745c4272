// PNG plots are drawn by the Python scripts in scripts/ (matplotlib from Debian's
// python3 packages). One runner for every command that plots.
#pragma once
#include <string>
#include <vector>

namespace morphfem {

// Runs /usr/bin/python3 scripts/SCRIPT ARGS... (stdout to stderr). Returns false,
// after a message on stderr naming `what`, if python3 or the script is missing or
// the script fails; results already written are not affected.
bool run_plot_script(const std::string& script, const std::vector<std::string>& args, const std::string& what);

}  // namespace morphfem
