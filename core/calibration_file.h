// Calibration files: fitted model parameters with their uncertainty and the data
// and command that produced them, as YAML that scenes load (`calibration: FILE`).
//
//   # morphfem calibration file
//   kind: friction                       # friction | materials | ...
//   command: "morphfem calibrate friction --weight-N 1.2 data/wood"
//   created: 2026-11-22T08:00:00Z
//   group: {surface: wood, foot_state: inflated}
//   parameters:
//     mu_static: {value: 0.7001, std_error: 0.0004, ci95: [0.6993, 0.7009], unit: "-"}
//   fit: {method: "PETSc TAO POUNDERS", residual_rms: 0.0021, residuals: 480, evaluations: 31,
//         converged: true, reason: CONVERGED_GATOL}
//   data:
//     - {file: data/wood/wood_inflated_01.csv, sha256: 3f1e..., specimen: wood_inflated_01}
//
// Written atomically; read back with every key checked (InputError naming file,
// line and key otherwise), and the data checksums can be verified.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace morphfem {

struct CalibratedValue {
  double value = 0, std_error = 0, ci_low = 0, ci_high = 0;
  std::string unit;
};

struct CalibrationData {
  std::string file, sha256, specimen;
};

struct Calibration {
  std::string kind, command, created;
  std::map<std::string, std::string> group;                         // e.g. surface, foot_state
  std::vector<std::pair<std::string, CalibratedValue>> parameters;  // in file order
  std::map<std::string, std::string> fit;                           // method, residual_rms, ... (as text)
  std::vector<CalibrationData> data;
  const CalibratedValue& parameter(const std::string& name) const;  // InputError if absent
};

// SHA-256 of a file's bytes, lower-case hex (FIPS 180-4). InputError if unreadable.
std::string sha256_file(const std::string& path);
std::string sha256_hex(const std::string& bytes);

std::string calibration_yaml(const Calibration& c);
void write_calibration_file(const std::string& path, const Calibration& c);
Calibration read_calibration_file(const std::string& path);
// Files whose checksum no longer matches (or that are missing), as "file: reason".
std::vector<std::string> verify_calibration_data(const Calibration& c);

// The time stamp of calibration files: UTC, "2026-11-22T08:00:00Z".
std::string now_utc();

}  // namespace morphfem
