#include "optim/material_calibration.h"

#include <cctype>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>

#include "core/calibration_file.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/plot.h"
#include "fem/material_fit.h"

namespace morphfem {

int calibrate_materials(const MaterialCalibrationOptions& o) {
  const std::string& dir = o.out_dir;
  const std::string& data_dir = o.data_dir;
  const double max_strain =
      o.max_strain.empty() ? 2.0 : number_option("materials", "--max-strain", o.max_strain, 0.05, 20);
  FitMaterialsOptions table;
  table.data_dir = data_dir;
  table.max_strain = max_strain;
  if (dir.empty()) return fit_materials(table, std::cout);
  std::filesystem::create_directories(dir);
  FitMaterialsOptions with_json = table;
  with_json.json = true;
  with_json.curves_file = (std::filesystem::path(dir) / "material_fit_curves.csv").string();
  std::ostringstream json;
  fit_materials(with_json, json);
  write_file_atomic((std::filesystem::path(dir) / "material_fit.json").string(), json.str());
  fit_materials(table, std::cout);
  const std::string png = (std::filesystem::path(dir) / "material_fit.png").string();
  if (run_plot_script("plot_calibration.py", {"materials", with_json.curves_file, png}, "the calibration"))
    std::cout << "plot: " << png << "\n";
  // The calibration file scenes load: {calibration: materials.yaml, parameter: dragonskin10.yeoh.c1}.
  Calibration cal;
  cal.kind = "materials";
  cal.command = "morphfem calibrate materials";
  cal.command += o.command_arguments;
  cal.created = now_utc();
  cal.group = {{"data_dir", data_dir}, {"max_strain", json_number(max_strain)}};
  std::set<std::string> seen, files;
  for (const MaterialFits& m : fit_material_directory(data_dir, max_strain)) {
    std::string slug;  // "DragonSkin10" -> "dragonskin10"
    for (char ch : m.test.material)
      if (std::isalnum(static_cast<unsigned char>(ch))) slug += static_cast<char>(std::tolower(ch));
    for (int k = 2; seen.count(slug); ++k) slug += "_" + std::to_string(k);
    seen.insert(slug);
    for (const FitResult& f : m.fits) {
      if (f.std_errors.empty()) continue;  // the linear fits (neo-Hookean, Yeoh) carry standard errors
      for (size_t j = 0; j < f.names.size(); ++j) {
        const double v = f.values[j], se = f.std_errors[j];
        cal.parameters.emplace_back(slug + "." + f.model + "." + f.names[j],
                                    CalibratedValue{v, se, v - 1.96 * se, v + 1.96 * se, "Pa"});
      }
      cal.fit[slug + "." + f.model + ".r2"] = json_number(f.r2);
      cal.fit[slug + "." + f.model + ".rms_Pa"] = json_number(f.rms);
    }
    if (files.insert(m.test.file).second) cal.data.push_back({m.test.file, sha256_file(m.test.file), m.test.material});
  }
  cal.fit["method"] = "linear least squares on the uniaxial nominal stress (fem/material_fit.h)";
  const std::string yaml = (std::filesystem::path(dir) / "materials.yaml").string();
  write_calibration_file(yaml, cal);
  std::cout << "calibration: " << yaml << "\n";
  return 0;
}

}  // namespace morphfem
