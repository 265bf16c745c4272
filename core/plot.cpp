#include "core/plot.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "core/paths.h"

namespace morphfem {

bool run_plot_script(const std::string& script, const std::vector<std::string>& args, const std::string& what) {
  const std::string python = "/usr/bin/python3", path = resource_dir() + "/scripts/" + script;
  if (!std::filesystem::exists(python) || !std::filesystem::exists(path)) {
    std::fprintf(stderr, "morphfem: no plot of %s (%s or %s missing)\n", what.c_str(), python.c_str(), path.c_str());
    return false;
  }
  std::string cmd = python + " '" + path + "'";
  for (const auto& a : args) cmd += " '" + a + "'";
  cmd += " >&2";
  if (std::system(cmd.c_str()) == 0) return true;
  std::fprintf(stderr, "morphfem: plotting %s failed (%s)\n", what.c_str(), script.c_str());
  return false;
}

}  // namespace morphfem
