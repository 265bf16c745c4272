// `morphfem robot morph` (robot/studies.h): the shape change under core pressure.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/json.h"
#include "core/paths.h"
#include "core/plot.h"
#include "robot/studies.h"
#include "sim/cross_section.h"
#include "sim/scene.h"
#include "sim/simulation.h"

namespace morphfem {

int robot_morph(const MorphOptions& o, MPI_Comm comm) {
  const std::string path = o.scene.empty() ? resource_dir() + "/examples/voxel/morph.yaml" : o.scene;
  YAML::Node doc = load_scene_yaml(path);
  for (const std::string& assignment : o.set) set_scene_key(doc, assignment, path);
  Scene scene = scene_from_yaml(doc, path);
  if (scene.cavities.empty() && scene.gas_cavities.empty())
    throw InputError(path, "morph needs a pressurised core (loads.cavities or loads.gas_cavities)");
  const std::string out_dir = !o.out_dir.empty()         ? o.out_dir
                              : scene.output_dir.empty() ? "results/robot/morph"
                                                         : scene.output_dir;
  scene.output_dir = out_dir;
  struct Sample {
    double t, p, width, length, thickness;
  };
  std::vector<Sample> samples;
  RunOptions options;
  options.on_step = [&](double t, const Mesh& mesh, const RowMatrixXd& u, const SimulationResult& r) {
    const Eigen::Vector3d e = cross_section_extents(mesh, u);
    samples.push_back({t, r.cavity_pressure.at(0), e.x(), e.y(), e.z()});
  };
  const SimulationResult r = run_scene(scene, comm, options);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return r.stats.completed ? 0 : 3;
  std::string csv = "time_s,core_pressure_pa,width_m,length_m,thickness_m,width_over_thickness\n";
  std::string table = "    t [s]  core [Pa]  width [cm]  thickness [cm]  width/thickness\n";
  char line[200];
  double last_p = -1;
  for (size_t i = 0; i < samples.size(); ++i) {
    const Sample& s = samples[i];
    std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", s.t, s.p, s.width, s.length, s.thickness,
                  s.width / s.thickness);
    csv += line;
    // The table: the first sample, every 1 kPa change of pressure, the last sample.
    if (i == 0 || i + 1 == samples.size() || std::abs(s.p - last_p) >= 999.0) {
      std::snprintf(line, sizeof line, "%9.3f  %9.0f  %10.2f  %14.2f  %15.2f\n", s.t, s.p, 100 * s.width,
                    100 * s.thickness, s.width / s.thickness);
      table += line;
      last_p = s.p;
    }
  }
  std::fputs(table.c_str(), stdout);
  if (!r.stats.completed) std::printf("run failed: %s\n", r.stats.failure.c_str());
  if (!r.output_dir.empty()) {
    write_file_atomic(r.output_dir + "/morph.csv", csv);
    run_plot_script("plot_morph.py", {r.output_dir + "/morph.csv"}, "the shape change");
    std::printf("results: %s/morph.csv, %s/morph.png\n", r.output_dir.c_str(), r.output_dir.c_str());
  }
  return r.stats.completed ? 0 : 3;
}

}  // namespace morphfem
