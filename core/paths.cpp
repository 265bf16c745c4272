#include "core/paths.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace morphfem {

namespace {

namespace fs = std::filesystem;

// The installed resources beside the running program: EXE_DIR/../share/morphfem.
fs::path installed_resources() {
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  if (error) return {};
  return exe.parent_path().parent_path() / "share" / "morphfem";
}

}  // namespace

std::string resource_dir() {
  if (const char* dir = std::getenv("MORPHFEM_DATA_DIR"); dir && *dir) return dir;
  std::error_code error;
  if (const fs::path installed = installed_resources(); !installed.empty() && fs::is_directory(installed, error))
    return installed.string();
  return MORPHFEM_SOURCE_DIR;
}

std::string shared_data_dir() {
  const fs::path resources = resource_dir();
  std::error_code error;
  if (fs::is_directory(resources / "data", error)) return (resources / "data").string();
  return (resources / ".." / "shared" / "data").lexically_normal().string();
}

}  // namespace morphfem
