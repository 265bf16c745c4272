// `morphfem fit-materials [--data-dir DIR] [--max-strain 2.0] [--json] [--curves FILE.csv]`:
// the arguments, then fem/material_fit.h's fit_materials.
#include <iostream>

#include "app/commands.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/paths.h"
#include "core/test_machine_export.h"
#include "fem/material_fit.h"

namespace morphfem {

int fit_materials_main(const std::vector<std::string>& args, const std::string& default_data_dir, std::ostream& out) {
  CommandLine cl("morphfem fit-materials", "[--data-dir DIR] [--max-strain 2.0] [--json] [--curves FILE.csv]",
                 "Fits neo-Hookean, Yeoh and Ogden (N = 1, 2, 3) laws to every *.csv tensile-test export in a "
                 "directory and prints a table per material and model, or JSON.");
  cl.value("--data-dir", "DIR", "the tensile-test exports (default: the shared materials data)")
      .value("--max-strain", "STRAIN",
             "fit the points with 0 < engineering strain <= STRAIN, in (0.05, 20] (default 2.0)")
      .flag("--json", "print JSON instead of the table")
      .value("--curves", "FILE.csv", "write data and fitted curves as CSV (for scripts/plot_material_fit.py)");
  if (!cl.parse(args, out)) return 0;
  FitMaterialsOptions o;
  o.data_dir = cl.get("--data-dir", default_data_dir);
  if (cl.has("--max-strain")) {
    const std::string v = cl.get("--max-strain", "");
    double x = 0;
    if (!parse_export_number(v, true, x) || x <= 0.05 || x > 20.0)
      throw InputError("fit-materials", "--max-strain '" + v + "' must be an engineering strain in (0.05, 20]");
    o.max_strain = x;
  }
  o.json = cl.has("--json");
  o.curves_file = cl.get("--curves", "");
  return fit_materials(o, out);
}

int fit_materials_command(const std::vector<std::string>& args) {
  return fit_materials_main(args, shared_data_dir() + "/materials", std::cout);
}

}  // namespace morphfem
