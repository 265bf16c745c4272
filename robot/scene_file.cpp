// `morphfem robot scene` (robot/studies.h): one case's scene as a file.
#include <cstdio>
#include <string>

#include "core/errors.h"
#include "core/json.h"
#include "robot/robot_study.h"
#include "robot/studies.h"

namespace morphfem {

int robot_scene_file(const SceneFileOptions& o) {
  if (o.case_name.empty()) throw InputError("morphfem robot scene", "needs --case NAME");
  RobotCase c = find_case(preset_cases(o.preset, {"voxel", "lattice-mechanics", "physical"}), o.case_name);
  c.overrides.insert(c.overrides.end(), o.set.begin(), o.set.end());
  const RobotFidelity& level = find_robot_fidelity(o.fidelity);
  const std::string output_dir = o.output_dir.empty() ? "results/" + c.name : o.output_dir;
  const std::string text = robot_scene_text(c, level, robot_scene_yaml(c, level, output_dir));
  if (o.out_file.empty()) {
    std::fputs(text.c_str(), stdout);
    return 0;
  }
  write_file_atomic(o.out_file, text);
  std::printf("scene: %s (morphfem run %s)\n", o.out_file.c_str(), o.out_file.c_str());
  return 0;
}

}  // namespace morphfem
