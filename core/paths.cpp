#include "core/paths.h"

namespace morphfem {

std::string resource_dir() { return MORPHFEM_SOURCE_DIR; }

std::string shared_data_dir() { return resource_dir() + "/../shared/data"; }

}  // namespace morphfem
