// The scene-key table (sim/scene_keys.h): well formed, the readers refuse what it does
// not declare and check its ranges, and docs/scene-keys.md is its current output.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "sim/scene.h"
#include "sim/scene_keys.h"

using namespace morphfem;

namespace {

const char* kScene = R"(geometry: {type: block, lx: 0.01, ly: 0.01, lz: 0.01, mesh_size: 0.005, order: 1}
materials:
  body: {model: neo_hookean, mu: 1.0e5, kappa: 1.0e6}
solver: {end_time: 1}
)";

// `extra` appended to the scene, or replacing its solver line if it starts with "solver:".
Scene read(const std::string& extra) {
  std::string text = kScene;
  if (extra.rfind("solver:", 0) == 0)
    text.replace(text.find("solver:"), std::string::npos, extra + "\n");
  else
    text += extra + "\n";
  return scene_from_yaml(YAML::Load(text), "scene.yaml");
}

std::string error_of(const std::string& extra) {
  try {
    read(extra);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SceneKeys, TheDocumentationIsTheTablesOutput) {
  std::ifstream in(std::string(MORPHFEM_SOURCE_DIR) + "/docs/scene-keys.md");
  ASSERT_TRUE(in) << "docs/scene-keys.md is missing";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_TRUE(text.str() == scene_keys_markdown())
      << "docs/scene-keys.md differs from the table: build/app/morphfem scene-keys > docs/scene-keys.md";
}

TEST(SceneKeys, EveryKeyIsDeclaredOnceUnderADeclaredMapping) {
  std::set<std::string> paths;
  for (const SceneKey& k : scene_keys()) {
    EXPECT_TRUE(paths.insert(k.path).second) << k.path << " declared twice";
    EXPECT_FALSE(k.doc.empty()) << k.path;
    const auto dot = k.path.rfind('.');
    if (dot != std::string::npos && k.path.rfind("(calibrated value)", 0) != 0) {
      const SceneKey* parent = find_scene_key(k.path.substr(0, dot));
      ASSERT_NE(parent, nullptr) << k.path << ": its mapping is not declared";
      EXPECT_TRUE(parent->type == KeyType::mapping || parent->type == KeyType::list ||
                  parent->type == KeyType::parameters)
          << k.path;
    }
    EXPECT_TRUE(k.type != KeyType::choice || !k.choices.empty()) << k.path;
    EXPECT_TRUE((k.type != KeyType::number && k.type != KeyType::integer) || !k.unit.empty()) << k.path;
    EXPECT_TRUE(!k.range || !k.requirement().empty()) << k.path;
  }
  EXPECT_GT(paths.size(), 100u);
  EXPECT_EQ(find_scene_key("materials.body.model")->path, "materials.<region>.model");
  EXPECT_EQ(find_scene_key("contact.lattice_floor.mu.skin")->path, "contact.lattice_floor.mu.<region>");
  EXPECT_EQ(find_scene_key("contact.ground.kapa"), nullptr);
  EXPECT_EQ(scene_key_children("contact"), (std::vector<std::string>{"friction", "ground", "lattice_floor", "self"}));
  EXPECT_TRUE(scene_key_children("actuation.bladders").empty());  // channel names: checked by the reader
}

TEST(SceneKeys, UnknownKeysAreRefusedWithTheDeclaredOnes) {
  std::string e = error_of("contact: {ground: {surfaces: [zmin], kapa: 1}}");
  EXPECT_NE(e.find("scene.yaml:5:38: 'contact.ground.kapa': unknown key (allowed: dhat, kappa, normal, point, "
                   "surfaces)"),
            std::string::npos)
      << e;
  e = error_of("solver: {end_time: 1, extrapolate: false, newton_velocity_tl: 1}");
  EXPECT_NE(e.find("'solver.newton_velocity_tl': unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("newton_velocity_tol"), std::string::npos) << e;
}

TEST(SceneKeys, DeclaredRangesAreChecked) {
  for (const auto& [extra, message] : std::vector<std::pair<std::string, std::string>>{
           {"solver: {end_time: 0}", "scene.yaml:4:20: 'solver.end_time': must be positive [s]"},
           {"solver: {newton_velocity_tol: -1}", "'solver.newton_velocity_tol': must not be negative [m/s]"},
           {"solver: {max_newton_its: 0}", "'solver.max_newton_its': must be a positive integer"},
           {"solver: {quadrature_degree: 7}", "'solver.quadrature_degree': must be an integer in [0, 6]"},
           {"output: {every: 1.5}", "'output.every': must be a positive integer"},
           {"output: {checkpoint_s: -1}", "'output.checkpoint_s': must not be negative [s]"},
           {"dynamics: {bulk_viscosity: -1}", "'dynamics.bulk_viscosity': must not be negative [Pa s]"},
           {"environment: {slope_deg: 91}", "'environment.slope_deg': must be in [-90, 90] [deg]"},
           {"contact: {ground: {surfaces: zmin}, friction: {lag_updates: 0.5, regions: []}}",
            "'contact.friction.lag_updates': must be an integer >= 0"},
           {"loads: {pulls: [{surface: zmax, stiffness: 0, velocity: [1, 0, 0]}]}",
            "'loads.pulls.stiffness': must be positive [N/m]"},
       }) {
    const std::string e = error_of(extra);
    EXPECT_NE(e.find(message), std::string::npos) << extra << ": " << e;
  }
}

TEST(SceneKeys, SolverKeysReachTheSolverOptions) {
  Scene scene = read("");
  EXPECT_EQ(scene.solver.newton_velocity_tol, 0.0);
  EXPECT_TRUE(scene.solver.extrapolate);
  scene = read("solver: {end_time: 2, newton_velocity_tol: 1.0e-4, extrapolate: false}");
  EXPECT_EQ(scene.solver.t_end, 2.0);
  EXPECT_EQ(scene.solver.newton_velocity_tol, 1e-4);
  EXPECT_FALSE(scene.solver.extrapolate);
  const std::string e = error_of("solver: {extrapolate: 0}");
  EXPECT_NE(e.find("'solver.extrapolate': expected true or false, got '0'"), std::string::npos) << e;
}
