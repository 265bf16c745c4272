// Scenes take friction coefficients from calibration files
// ({calibration: FILE, parameter: NAME}) and record which file gave which value.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/calibration_file.h"
#include "core/errors.h"
#include "sim/scene.h"

using namespace morphfem;
namespace fs = std::filesystem;

namespace {

class SceneCalibration : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("morphfem_scene_calibration_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    Calibration c;
    c.kind = "friction";
    c.command = "morphfem calibrate friction --weight-N 1.2 wood";
    c.created = "2026-12-01T00:00:00Z";
    c.group = {{"surface", "wood"}, {"foot_state", "inflated"}};
    c.parameters = {{"mu_static", {0.7024, 0.0006, 0.7012, 0.7036, "-"}},
                    {"mu_kinetic", {0.5998, 0.0001, 0.5996, 0.6000, "-"}}};
    write_calibration_file((dir_ / "wood.yaml").string(), c);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string scene(const std::string& friction) {
    const std::string path = (dir_ / "scene.yaml").string();
    std::ofstream(path) << "name: block\n"
                           "geometry: {type: block, lx: 0.01, ly: 0.01, lz: 0.01, mesh_size: 0.01, order: 1}\n"
                           "materials: {body: {model: neo_hookean, mu: 1.0e5, nu: 0.3, density: 1000}}\n"
                           "loads: {gravity: [0, 0, -9.81]}\n"
                           "contact:\n"
                           "  ground: {point: [0, 0, -1.0e-4], normal: [0, 0, 1], surfaces: [zmin]}\n"
                           "  friction: {regions: [{surface: zmin, "
                        << friction
                        << "}]}\n"
                           "dynamics: {scheme: implicit_euler}\n";
    return path;
  }
  fs::path dir_;
};

TEST_F(SceneCalibration, CoefficientsComeFromTheFileAndAreRecorded) {
  const Scene s =
      read_scene(scene("mu_static: {calibration: wood.yaml, parameter: mu_static}, "
                       "mu_kinetic: {calibration: wood.yaml, parameter: mu_kinetic}"));
  ASSERT_EQ(s.friction->regions.size(), 1u);
  EXPECT_DOUBLE_EQ(s.friction->regions[0].mu_static(1.0), 0.7024);
  EXPECT_DOUBLE_EQ(s.friction->regions[0].mu_kinetic(1.0), 0.5998);
  ASSERT_EQ(s.calibrations.size(), 2u);
  EXPECT_EQ(s.calibrations[0].parameter, "mu_static");
  EXPECT_EQ(s.calibrations[0].kind, "friction");
  EXPECT_EQ(s.calibrations[0].sha256, sha256_file((dir_ / "wood.yaml").string()));
  EXPECT_DOUBLE_EQ(s.calibrations[1].std_error, 0.0001);
}

TEST_F(SceneCalibration, UnknownParameterOrMissingFileNamesTheKey) {
  try {
    read_scene(scene("mu: {calibration: wood.yaml, parameter: mu_peak}"));
    FAIL() << "an unknown parameter must be refused";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("scene.yaml:"), std::string::npos) << m;
    EXPECT_NE(m.find("mu_peak"), std::string::npos) << m;
    EXPECT_NE(m.find("mu_static"), std::string::npos) << m;  // lists what the file has
  }
  EXPECT_THROW(read_scene(scene("mu: {calibration: missing.yaml, parameter: mu_static}")), InputError);
  EXPECT_THROW(read_scene(scene("mu: {calibration: wood.yaml}")), InputError);
}

TEST_F(SceneCalibration, MaterialAndValveParametersComeFromFiles) {
  Calibration m;
  m.kind = "materials";
  m.command = "morphfem calibrate materials --out cal";
  m.created = "2026-12-01T00:00:00Z";
  m.parameters = {{"dragonskin10.yeoh.c1", {21590, 100, 21394, 21786, "Pa"}},
                  {"dragonskin10.yeoh.c2", {3044, 30, 2985, 3103, "Pa"}}};
  write_calibration_file((dir_ / "materials.yaml").string(), m);
  Calibration v;
  v.kind = "morphing";
  v.command = "morphfem calibrate morphing";
  v.created = "2026-12-01T00:00:00Z";
  v.parameters = {{"conductance_supply", {2.0e-7, 0, 2.0e-7, 2.0e-7, "mol/(s Pa)"}},
                  {"conductance_vacuum", {5.0e-7, 0, 5.0e-7, 5.0e-7, "mol/(s Pa)"}}};
  write_calibration_file((dir_ / "morphing.yaml").string(), v);
  const std::string path = (dir_ / "tube.yaml").string();
  std::ofstream(path) << "name: tube\n"
                         "geometry: {type: thick_cylinder, inner_radius: 0.01, outer_radius: 0.012, height: 0.004,\n"
                         "           mesh_size: 0.004, order: 1}\n"
                         "materials: {body: {model: yeoh, c1: {calibration: materials.yaml, parameter: "
                         "dragonskin10.yeoh.c1},\n"
                         "                   c2: {calibration: materials.yaml, parameter: dragonskin10.yeoh.c2}, "
                         "c3: 0, kappa: 1.0e6}}\n"
                         "loads:\n"
                         "  gas_cavities:\n"
                         "    - {name: core, surfaces: [inner], volume_axes: [x, y],\n"
                         "       supply_pressure: [[0, 0], [1, 50000], [2, -80000]],\n"
                         "       conductance: {calibration: morphing.yaml, parameter: conductance_supply},\n"
                         "       vacuum_conductance: {calibration: morphing.yaml, parameter: conductance_vacuum}}\n";
  const Scene s = read_scene(path);
  EXPECT_DOUBLE_EQ(s.materials.at("body").number("c1"), 21590);
  EXPECT_DOUBLE_EQ(s.materials.at("body").number("c2"), 3044);
  ASSERT_EQ(s.gas_cavities.size(), 1u);
  const GasCavitySpec& g = s.gas_cavities[0];
  EXPECT_TRUE(g.has_vacuum_conductance);
  EXPECT_DOUBLE_EQ(g.conductance_at(1.0), 2.0e-7);  // the line
  EXPECT_DOUBLE_EQ(g.conductance_at(2.0), 5.0e-7);  // the vacuum pump
  EXPECT_DOUBLE_EQ(g.conductance_at(0.0), 2.0e-7);  // p_s = 0: venting through the line's path
  ASSERT_EQ(s.calibrations.size(), 4u);
  EXPECT_EQ(s.calibrations[0].kind, "materials");
  EXPECT_EQ(s.calibrations[0].parameter, "dragonskin10.yeoh.c1");
  EXPECT_EQ(s.calibrations[3].parameter, "conductance_vacuum");
  // A negative conductance is refused with the key.
  std::ofstream(path) << "name: tube\n"
                         "geometry: {type: thick_cylinder, inner_radius: 0.01, outer_radius: 0.012, height: 0.004,\n"
                         "           mesh_size: 0.004, order: 1}\n"
                         "materials: {body: {model: neo_hookean, mu: 1.0e5, nu: 0.45}}\n"
                         "loads:\n"
                         "  gas_cavities:\n"
                         "    - {name: core, surfaces: [inner], volume_axes: [x, y], vacuum_conductance: -1.0e-7}\n";
  try {
    read_scene(path);
    FAIL() << "a negative vacuum conductance must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vacuum_conductance"), std::string::npos) << e.what();
  }
}

}  // namespace
