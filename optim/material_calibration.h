// The material calibration (`morphfem calibrate materials`): neo-Hookean, Yeoh and
// Ogden fits to uniaxial tensile exports (fem/material_fit.h) with R^2, RMS and plots,
// and with out_dir a calibration file scenes load
// ({calibration: materials.yaml, parameter: dragonskin10.yeoh.c1}).
#pragma once
#include <string>

namespace morphfem {

struct MaterialCalibrationOptions {
  std::string data_dir;           // the tensile exports (*.csv)
  std::string max_strain;         // largest engineering strain fitted (empty: 2.0)
  std::string out_dir;            // empty: print the table only
  std::string command_arguments;  // recorded in the calibration file
};
int calibrate_materials(const MaterialCalibrationOptions& options);

}  // namespace morphfem
