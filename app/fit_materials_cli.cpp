// `morphfem fit-materials [--data-dir DIR] [--max-strain 2.0] [--json] [--curves FILE.csv]`.
#include <iostream>

#include "app/commands.h"
#include "core/paths.h"
#include "fem/material_fit.h"

namespace morphfem {

int fit_materials_command(const std::vector<std::string>& args) {
  return fit_materials_main(args, shared_data_dir() + "/materials", std::cout);
}

}  // namespace morphfem
