// The scene-key table (sim/scene_keys.h): well formed, the readers refuse what it does
// not declare and check its ranges, and docs/scene-keys.md is its current output.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "core/errors.h"
#include "fem/inertia.h"
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

// Every documented default that is a number, true/false or one of the key's choices is
// what the readers leave in the scene when the key is absent: a scene with each section
// present but (nearly) empty reads to the table's defaults.
TEST(SceneKeys, DocumentedDefaultsAreTheReadersDefaults) {
  const std::string schedule = std::string(MORPHFEM_SOURCE_DIR) + "/examples/schedules/rolling.yaml";
  const Scene quiet = read(R"(loads:
  gas_cavities: [{surfaces: [zmax]}]
  volume_cavities: [{surfaces: [zmax], volume_ratio: [[0, 1], [1, 2]], penalty_modulus: 1.0e5}]
  pulls: [{surface: xmax, stiffness: 1, velocity: [1, 0, 0]}]
contact:
  ground: {surfaces: zmin}
  friction: {regions: []}
  lattice_floor: {kappa: 1, mu: {body: 1}}
  self: {pairs: [[zmax, zmax]]}
actuation: {schedule: )" + schedule +
                           R"(, bladders: {b1: zmax}, feet: {foot_a: zmin}, valves: {fill_time_s: 1}}
environment: {}
output: {})");
  const Scene dynamic = read("dynamics: {}");  // friction would need implicit Euler
  auto foot_mu = [&](bool active) {
    double mu = active ? 0 : 1e300;
    for (double t = 0; t < 30; t += 0.01) {
      const double m = quiet.friction->regions.at(0).mu_static(t);
      mu = active ? std::max(mu, m) : std::min(mu, m);
    }
    return mu;
  };
  auto scheme = [&] {
    for (const auto& [name, s] : time_schemes())
      if (s == dynamic.dynamics->inertia.scheme) return name;
    return std::string("?");
  };
  const Eigen::Vector3d g = quiet.gravity;
  using Value = std::function<double()>;
  const std::map<std::string, Value> numbers = {
      {"loads.gas_cavities.symmetry_factor", [&] { return quiet.gas_cavities.at(0).wall.symmetry_factor; }},
      {"loads.gas_cavities.temperature", [&] { return quiet.gas_cavities.at(0).temperature; }},
      {"loads.gas_cavities.initial_gauge_pressure", [&] { return quiet.gas_cavities.at(0).initial_gauge_pressure; }},
      {"loads.gas_cavities.supply_pressure", [&] { return quiet.gas_cavities.at(0).supply_gauge_pressure(0.5); }},
      {"loads.gas_cavities.conductance", [&] { return quiet.gas_cavities.at(0).conductance(0.5); }},
      {"loads.volume_cavities.tolerance", [&] { return quiet.volume_cavities.at(0).tolerance; }},
      {"loads.pulls.start", [&] { return quiet.pulls.at(0).start; }},
      {"solver.end_time", [&] { return quiet.solver.t_end; }},
      {"solver.initial_step", [&] { return quiet.solver.dt_initial; }},
      {"solver.min_step", [&] { return quiet.solver.dt_min; }},
      {"solver.max_step", [&] { return quiet.solver.dt_max; }},
      {"solver.rtol", [&] { return quiet.solver.rtol; }},
      {"solver.newton_velocity_tol", [&] { return quiet.solver.newton_velocity_tol; }},
      {"solver.quadrature_degree", [&] { return quiet.quadrature_degree; }},
      {"solver.max_newton_its", [&] { return quiet.solver.max_newton_its; }},
      {"solver.easy_newton_its", [&] { return quiet.solver.easy_newton_its; }},
      {"output.every", [&] { return quiet.output_every; }},
      {"output.checkpoint_s", [&] { return quiet.checkpoint_s; }},
      {"dynamics.lumped", [&] { return dynamic.dynamics->inertia.lumped; }},
      {"dynamics.adaptive", [&] { return dynamic.dynamics->inertia.adaptive; }},
      {"dynamics.error_tolerance", [&] { return dynamic.dynamics->inertia.error_tolerance; }},
      {"dynamics.shear_viscosity", [&] { return dynamic.dynamics->shear_viscosity; }},
      {"dynamics.bulk_viscosity", [&] { return dynamic.dynamics->bulk_viscosity; }},
      {"contact.ground.dhat", [&] { return quiet.ground->dhat; }},
      {"contact.ground.kappa", [&] { return quiet.ground->kappa; }},
      {"contact.friction.eps_v", [&] { return quiet.friction->eps_v; }},
      {"contact.friction.lag_updates", [&] { return quiet.friction->lag_updates; }},
      {"contact.lattice_floor.dhat", [&] { return quiet.lattice_floor->floor.dhat; }},
      {"contact.lattice_floor.eps_v", [&] { return quiet.lattice_floor->floor.eps_v; }},
      {"contact.lattice_floor.voxel_size", [&] { return quiet.lattice_floor->voxel_size; }},
      {"contact.lattice_floor.gap_foot_columns", [&] { return quiet.lattice_floor->gap_foot_columns; }},
      {"contact.self.dhat", [&] { return quiet.self_contact->dhat; }},
      {"contact.self.kappa", [&] { return quiet.self_contact->kappa; }},
      {"contact.self.inflation", [&] { return quiet.self_contact->inflation; }},
      {"contact.self.max_trust_radius", [&] { return quiet.self_contact->max_trust_radius; }},
      {"contact.self.project_hessian", [&] { return quiet.self_contact->project_hessian; }},
      {"actuation.start", [&] { return quiet.gait.start; }},
      {"actuation.feet.mu_active", [&] { return foot_mu(true); }},
      {"actuation.feet.mu_inactive", [&] { return foot_mu(false); }},
      {"actuation.valves.temperature", [&] { return quiet.gas_cavities.back().temperature; }},
      {"actuation.weightless_inflated", [&] { return quiet.weightless_inflated; }},
      {"environment.slope_deg", [&] { return std::atan2(std::hypot(g.x(), g.y()), -g.z()) * 180 / M_PI; }},
      {"environment.gravity", [&] { return g.norm(); }},
      {"solver.extrapolate", [&] { return quiet.solver.extrapolate; }},
      {"solver.land_on_breakpoints", [&] { return quiet.solver.land_on_breakpoints; }},
  };
  const std::map<std::string, std::function<std::string()>> choices = {
      {"solver.linear_solver", [&] { return quiet.solver.linear_solver; }},
      {"solver.formulation", [&] { return quiet.formulation; }},
      {"solver.hessian_projection",
       [&] {
         return std::string(quiet.solver.hessian_projection == HessianProjection::always ? "always" : "adaptive");
       }},
      {"dynamics.scheme", scheme},
  };
  int checked = 0;
  for (const SceneKey& k : scene_keys()) {
    size_t used = 0;
    double fallback = 0;
    try {
      fallback = std::stod(k.fallback, &used);
    } catch (const std::exception&) {
    }
    if (k.fallback == "true" || k.fallback == "false") {
      fallback = k.fallback == "true";
      used = k.fallback.size();
    }
    if (!k.fallback.empty() && used == k.fallback.size()) {
      const auto value = numbers.find(k.path);
      ASSERT_NE(value, numbers.end()) << k.path << ": add its value to this test";
      EXPECT_NEAR(value->second(), fallback, 1e-12 * std::abs(fallback)) << k.path;
      ++checked;
    } else if (std::find(k.choices.begin(), k.choices.end(), k.fallback) != k.choices.end()) {
      const auto value = choices.find(k.path);
      ASSERT_NE(value, choices.end()) << k.path << ": add its value to this test";
      EXPECT_EQ(value->second(), k.fallback) << k.path;
      ++checked;
    }
  }
  EXPECT_EQ(checked, int(numbers.size() + choices.size()));
}
