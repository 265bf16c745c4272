// Robot cases (robot/robot_study.h): the template keys a case sets, the baseline
// cases of the voxel study, inline schedules, and one cheap run that must not drift.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "actuation/voxel_growth.h"
#include "core/errors.h"
#include "robot/robot_study.h"
#include "robot/studies.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "tests/support/temp_dir.h"

using namespace morphfem;

namespace {

const RobotCase& baseline(const std::string& name) {
  static const auto cases = voxel_baseline_cases(MORPHFEM_SOURCE_DIR);
  for (const auto& c : cases)
    if (c.name == name) return c;
  throw std::runtime_error("no case " + name);
}

}  // namespace

TEST(RobotStudy, BaselineCasesAreTheVoxelStudys) {
  const auto cases = voxel_baseline_cases(MORPHFEM_SOURCE_DIR);
  ASSERT_EQ(cases.size(), 8u);
  EXPECT_NEAR(baseline("roll_flat").voxel_bl_per_s, 0.1753136, 1e-6);
  EXPECT_NEAR(baseline("inch_hill15").voxel_bl_per_s, 0.0245562, 1e-6);
  EXPECT_EQ(baseline("roll_hill15").slope_deg, 15);
  EXPECT_EQ(baseline("roll_flat").schedule.orientation_deg, 0);
  EXPECT_EQ(baseline("roll_flat").schedule.core_pressure_pa, 12000);
  EXPECT_EQ(baseline("inch_flat").schedule.orientation_deg, 90);
  EXPECT_EQ(baseline("inch_flat").schedule.core_pressure_pa, 0);
  // The lattice's column: 7667 swing steps + 1 + 4001 settle steps of dt.
  const VoxelActuation voxel;
  EXPECT_NEAR(baseline("inch_flat").schedule.column_s, 11669 * voxel.step_s, 1e-12);
  EXPECT_EQ(baseline("inch_flat").schedule.repeats, 2);
  // Empty schedules: nothing inflates, the feet never switch on.
  for (int row = 0; row < kNumRows; ++row)
    for (int k = 0; k < 8; ++k) EXPECT_FALSE(baseline("empty_90deg_0kPa_hill15").schedule.active(row, k));
}

TEST(RobotStudy, CaseSetsScheduleSlopeHeadingAndFidelityInTheTemplate) {
  const RobotCase& c = baseline("inch_hill15");
  const RobotFidelity& level = find_robot_fidelity("0");
  const YAML::Node doc = robot_scene_yaml(c, level, "");
  EXPECT_FALSE(doc["output"]);
  EXPECT_EQ(doc["geometry"]["mesh_size"].as<double>(), level.mesh_size);
  Scene scene = scene_from_yaml(doc, c.template_scene);
  EXPECT_TRUE(scene.output_dir.empty());
  ASSERT_TRUE(scene.gait.enabled);
  // Heading 90 deg: along +y; the study's rotated gravity g(0, -sin 15, -cos 15).
  EXPECT_NEAR(scene.gait.heading.y(), 1.0, 1e-12);
  const double s = std::sin(15 * M_PI / 180);
  EXPECT_NEAR(scene.gravity.y(), -9.80665 * s, 1e-9);
  EXPECT_NEAR(scene.gravity.x(), 0.0, 1e-9);
  EXPECT_NEAR(scene.gait.end - scene.gait.start, voxel_timeline(c.schedule).duration(), 1e-12);
  EXPECT_LE(scene.gait.end, scene.solver.t_end);
  EXPECT_NEAR(scene.gait.nominal_s, 16 * c.schedule.column_s, 1e-8);  // the inline schedule keeps 10 digits
  EXPECT_EQ(scene.growth.size(), 8u);
  EXPECT_THROW(find_robot_fidelity("9"), InputError);
}

// The physical laminate's cases: only the inflated, heading-0 baselines (a plane-strain
// cross-section can roll but not inch); the template keeps its pressures, mesh and
// time step, the case sets matrix, timing, slope and heading.
TEST(RobotStudy, PhysicalCasesPlayTheBaselineScheduleOnTheRollingSlice) {
  const auto cases = physical_baseline_cases(MORPHFEM_SOURCE_DIR);
  std::vector<std::string> names;
  for (const auto& c : cases) names.push_back(c.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"roll_flat", "roll_hill15", "inch_flat", "inch_hill15", "empty_0deg_12kPa_flat",
                                      "empty_0deg_0kPa_flat", "empty_90deg_0kPa_hill15"}));
  for (const auto& c : cases)
    EXPECT_NE(c.template_scene.find(c.schedule.core_pressure_pa > 0 ? "roll_slice.yaml" : "inch_flat.yaml"),
              std::string::npos)
        << c.name;
  const RobotCase& hill = cases[1];
  ASSERT_TRUE(hill.physical);
  const YAML::Node doc = robot_scene_yaml(hill, find_robot_fidelity("2"), "");
  EXPECT_EQ(doc["geometry"]["mesh_size"].as<double>(), 0.003);  // the template's, not level 2's
  EXPECT_EQ(doc["solver"]["max_step"].as<double>(), 0.05);
  const Scene scene = scene_from_yaml(doc, hill.template_scene);
  ASSERT_TRUE(scene.gait.enabled);
  EXPECT_NEAR(scene.gait.end - scene.gait.start, 16 * hill.schedule.column_s, 1e-8);
  EXPECT_LE(scene.gait.end, scene.solver.t_end);
  EXPECT_NEAR(scene.gravity.x(), -9.80665 * std::sin(15 * M_PI / 180), 1e-9);  // uphill along +x
  // Chamber 8 is on in column 1 at the template's 35 kPa (after its 0.8 s ramp), off in
  // column 2; the core at the 50 kPa line pressure.
  const CavitySpec* b8 = nullptr;
  const CavitySpec* core = nullptr;
  for (const auto& cav : scene.cavities) {
    if (cav.name == "b8") b8 = &cav;
    if (cav.name == "core") core = &cav;
  }
  ASSERT_TRUE(b8 && core);
  const double t1 = scene.gait.start + 0.9 * hill.schedule.column_s, t2 = t1 + hill.schedule.column_s;
  EXPECT_NEAR(b8->pressure(t1), 35000, 1e-6);
  EXPECT_NEAR(b8->pressure(t2), 0, 1e-6);
  EXPECT_NEAR(core->pressure(t1), 50000, 1e-6);
  EXPECT_EQ(b8->open_axis, 1);
}

// The flat cases play on the full-length body: inching on the hill has the body length
// uphill, the top chambers on in the odd columns at 35 kPa, foot B gripping (0.70) and
// foot A sliding (0.56) in them, the other way round in the even columns.
TEST(RobotStudy, PhysicalInchingCasesPlayOnTheFullLengthBody) {
  const auto cases = physical_baseline_cases(MORPHFEM_SOURCE_DIR);
  const RobotCase* inch = nullptr;
  for (const auto& c : cases)
    if (c.name == "inch_hill15") inch = &c;
  ASSERT_TRUE(inch && inch->physical);
  const YAML::Node doc = robot_scene_yaml(*inch, find_robot_fidelity("2"), "");
  EXPECT_EQ(doc["geometry"]["mesh_size"].as<double>(), 0.01);  // the template's
  const Scene scene = scene_from_yaml(doc, inch->template_scene);
  ASSERT_TRUE(scene.gait.enabled);
  EXPECT_NEAR(scene.gravity.y(), -9.80665 * std::sin(15 * M_PI / 180), 1e-9);  // the body length uphill
  EXPECT_NEAR(scene.gravity.x(), 0.0, 1e-12);
  const double odd = scene.gait.start + 0.9 * inch->schedule.column_s, even = odd + inch->schedule.column_s;
  int chambers = 0;
  for (const auto& cav : scene.cavities) {
    if (cav.name == "core") ADD_FAILURE() << "the flat body has no pressurised core";
    const bool top = cav.name == "b1" || cav.name == "b2" || cav.name == "b3" || cav.name == "b4";
    EXPECT_NEAR(cav.pressure(odd), top ? 35000 : 0, 1e-6) << cav.name;
    EXPECT_NEAR(cav.pressure(even), 0, 1e-6) << cav.name;
    ++chambers;
  }
  EXPECT_EQ(chambers, 8);
  ASSERT_TRUE(scene.friction);
  std::map<std::string, const FrictionRegion*> regions;
  for (const auto& r : scene.friction->regions) regions[r.surface] = &r;
  ASSERT_TRUE(regions.count("foot_a") && regions.count("foot_b"));
  EXPECT_NEAR(regions["foot_b"]->mu_static(odd), 0.70, 1e-9);
  EXPECT_NEAR(regions["foot_a"]->mu_static(odd), 0.56, 1e-9);
  EXPECT_NEAR(regions["foot_b"]->mu_static(even), 0.56, 1e-9);
  EXPECT_NEAR(regions["foot_a"]->mu_static(even), 0.70, 1e-9);
}

// --set: keys set last, '*' over a mapping's keys, a new last key; bad paths and
// assignments are refused with the path named.
TEST(RobotStudy, OverridesSetSceneKeysLast) {
  RobotCase c = baseline("roll_flat");
  c.overrides = {"materials.bladder_*.density=15000", "actuation.weightless_inflated=true", "geometry.order=2"};
  const YAML::Node doc = robot_scene_yaml(c, find_robot_fidelity("0"), "");
  EXPECT_EQ(doc["geometry"]["order"].as<int>(), 2);  // after the fidelity level's order 1
  for (const auto& kv : doc["materials"])
    EXPECT_EQ(kv.second["density"].as<double>(), kv.first.as<std::string>() == "skin" ? 3000 : 15000) << kv.first;
  const Scene scene = scene_from_yaml(doc, c.template_scene);
  EXPECT_TRUE(scene.weightless_inflated);

  YAML::Node root = YAML::Load("{a: {b: 1}}");
  auto error = [&](const std::string& assignment) {
    try {
      set_scene_key(root, assignment, "scene.yaml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error("a.b").find("expected KEY=VALUE"), std::string::npos);
  EXPECT_NE(error("x.y=1").find("no key 'x'"), std::string::npos);
  EXPECT_NE(error("a.b.c=1").find("'b' is not a mapping"), std::string::npos);
  EXPECT_NE(error("a..b=1").find("empty key"), std::string::npos);
  EXPECT_NE(error("a.*=1").find("'*' cannot be in the last key"), std::string::npos);
  EXPECT_NE(error("q*.b=1").find("no key matches 'q*'"), std::string::npos);
  EXPECT_NE(error("a.c=[1, 2").find("not YAML"), std::string::npos);
  EXPECT_EQ(error("a.c=[1, 2]"), "");
  EXPECT_EQ(root["a"]["c"][1].as<int>(), 2);
}

// The lattice-mechanics preset: every baseline case, inflated or flat, reads with the
// lattice's floor spheres in place of face contact (the feet go to the spheres), the
// bladders 12.5x stiffer with the lattice's mass, and the skin unchanged; --set keys
// still come last. An unknown preset is refused with the known ones named.
TEST(RobotStudy, LatticeMechanicsCasesPutTheBodyOnTheLatticesSpheres) {
  const auto cases = lattice_mechanics_cases(MORPHFEM_SOURCE_DIR);
  ASSERT_EQ(cases.size(), voxel_baseline_cases(MORPHFEM_SOURCE_DIR).size());
  for (RobotCase c : cases) {
    EXPECT_TRUE(c.lattice_mechanics);
    c.overrides.push_back("materials.skin.density=2900");
    const YAML::Node doc = robot_scene_yaml(c, find_robot_fidelity("0.02:2:0.05"), "");
    const Scene scene = scene_from_yaml(doc, c.template_scene);
    EXPECT_TRUE(scene.lattice_floor) << c.name;
    EXPECT_FALSE(scene.ground) << c.name;
    EXPECT_FALSE(scene.friction) << c.name;  // feet switch on the spheres
    EXPECT_EQ(scene.lattice_floor->feet.size(), 2u) << c.name;
    EXPECT_EQ(scene.materials.at("bladder_5").number("mu"), 1388889) << c.name;  // 12.5 x 111111 Pa
    EXPECT_EQ(scene.materials.at("skin").number("mu"), 200000) << c.name;
    EXPECT_EQ(doc["materials"]["bladder_3"]["density"].as<double>(), 15000) << c.name;
    EXPECT_EQ(doc["materials"]["skin"]["density"].as<double>(), 2900) << c.name;
  }
  try {
    ValidateOptions o;
    o.presets = {"voxel", "lattice"};
    robot_validate(o, PETSC_COMM_WORLD);
    FAIL() << "an unknown preset must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("lattice-mechanics"), std::string::npos) << e.what();
  }
}

TEST(RobotStudy, CustomFidelityLevelsParseAndBadOnesAreRefused) {
  const RobotFidelity& l = find_robot_fidelity("0.01:2:0.1");
  EXPECT_DOUBLE_EQ(l.mesh_size, 0.01);
  EXPECT_EQ(l.order, 2);
  EXPECT_DOUBLE_EQ(l.max_step, 0.1);
  EXPECT_EQ(&find_robot_fidelity("0.01:2:0.1"), &l);  // the same level again
  for (const char* bad : {"0.01:3:0.1", "0.01:1", "-1:1:0.1", "0.01:1:0", "0.01:1:0.1x", "a:b:c"})
    EXPECT_THROW(find_robot_fidelity(bad), InputError) << bad;
}

TEST(RobotStudy, BadInlineScheduleNamesTheScene) {
  YAML::Node doc = robot_scene_yaml(baseline("inch_flat"), find_robot_fidelity("0"), "");
  doc["actuation"]["schedule"]["matrix"][3] = "10102010";
  try {
    scene_from_yaml(doc, "template.yaml");
    FAIL() << "a matrix entry of 2 must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("template.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("matrix"), std::string::npos) << e.what();
  }
}

// Without actuation the robot must stay where it settled: the voxel study's empty
// schedule on flat ground moved -9e-5 BL/s; the bound is 0.005 BL/s.
TEST(RobotStudy, EmptyScheduleOnFlatGroundStaysPut) {
  const SimulationResult r =
      run_robot_case(baseline("empty_0deg_0kPa_flat"), find_robot_fidelity("0"), "", PETSC_COMM_WORLD, false);
  ASSERT_TRUE(r.stats.completed) << r.stats.failure;
  ASSERT_TRUE(r.gait_complete);
  EXPECT_LT(std::abs(r.speed_bl_per_s), 0.005);
  EXPECT_GT(r.min_J, 0.0);
}

// A case's saved scene.yaml extends its run: `morphfem run DIR/scene.yaml --resume
// --set solver.end_time=LATER` finds the checkpoint's scene identical (the case run
// records its scene like `morphfem run` does).
TEST(RobotStudy, SavedCaseSceneResumesItsRun) {
  const std::filesystem::path dir = temp_dir("case_resume");
  RobotCase c = baseline("empty_0deg_0kPa_flat");
  c.overrides = {"solver.end_time=0.1"};
  const SimulationResult first = run_robot_case(c, find_robot_fidelity("0"), dir.string(), PETSC_COMM_WORLD, false);
  ASSERT_TRUE(first.stats.completed) << first.stats.failure;
  const std::string saved = first.output_dir + "/scene.yaml";
  YAML::Node doc = load_scene_yaml(saved);
  set_scene_key(doc, "solver.end_time=0.2", saved);
  const Scene scene = scene_from_yaml(doc, saved);
  RunOptions options{true, false};
  options.resume = true;
  options.scene_text = scene_identity(doc);
  const SimulationResult extended = run_scene(scene, PETSC_COMM_WORLD, options);
  EXPECT_TRUE(extended.stats.completed) << extended.stats.failure;
  EXPECT_NEAR(extended.resumed_at, 0.1, 1e-9);
  std::filesystem::remove_all(dir);
}

// A killed case leaves its scene beside its checkpoint (OUTPUT.partial/scene.yaml,
// written when the run starts), and that file resumes it.
TEST(RobotStudy, InterruptedCaseResumesFromThePartialScene) {
  const std::filesystem::path dir = temp_dir("case_partial");
  RobotCase c = baseline("empty_0deg_0kPa_flat");
  c.overrides = {"solver.end_time=0.1"};
  const YAML::Node doc = robot_scene_yaml(c, find_robot_fidelity("0"), (dir / c.name).string());
  YAML::Emitter out;
  out << doc;
  RunOptions options{true, false};
  options.scene_text = scene_identity(doc);
  options.scene_file = std::string(out.c_str()) + "\n";
  options.stop_after_steps = 2;  // as a kill would: the output stays in OUTPUT.partial
  const SimulationResult killed = run_scene(scene_from_yaml(doc, c.template_scene), PETSC_COMM_WORLD, options);
  ASSERT_FALSE(killed.stats.completed);
  const std::string saved = (dir / (c.name + ".partial") / "scene.yaml").string();
  ASSERT_TRUE(std::filesystem::exists(saved));
  const YAML::Node again = load_scene_yaml(saved);
  RunOptions resume{true, false};
  resume.resume = true;
  resume.scene_text = scene_identity(again);
  const SimulationResult finished = run_scene(scene_from_yaml(again, saved), PETSC_COMM_WORLD, resume);
  EXPECT_TRUE(finished.stats.completed) << finished.stats.failure;
  EXPECT_GT(finished.resumed_at, 0.0);
  EXPECT_TRUE(std::filesystem::exists(dir / c.name / "scene.yaml"));  // moved with the finished output
  std::filesystem::remove_all(dir);
}

// Every term is an energy, so the assembled Hessian is symmetric and the default
// factorisation, MUMPS's LDL^T, must take LU's Newton iterates: checked on a case with
// every kind of term the gaits use (elasticity, grown bladders, inertia, damping,
// gravity, the lattice's floor spheres with friction and switching feet), through
// the settle and into the first column of the gait (it starts at 1.5 s). A term with
// an unsymmetric Hessian would make the two differ: LDL^T reads one triangle.
TEST(RobotStudy, SymmetricFactorisationTakesLusNewtonIterates) {
  RobotCase c = find_case(lattice_mechanics_cases(MORPHFEM_SOURCE_DIR), "inch_flat");
  c.overrides = {"solver.end_time=1.8"};
  const RobotFidelity level = find_robot_fidelity("0.02:1:0.05");
  std::vector<SimulationResult> runs;
  for (const char* solver : {"mumps", "mumps_lu"}) {
    RobotCase with = c;
    with.overrides.push_back(std::string("solver.linear_solver=") + solver);
    runs.push_back(run_robot_case(with, level, "", PETSC_COMM_WORLD, false));
    ASSERT_TRUE(runs.back().stats.completed) << solver << ": " << runs.back().stats.failure;
  }
  EXPECT_EQ(runs[0].stats.steps, runs[1].stats.steps);
  EXPECT_EQ(runs[0].stats.newton_its, runs[1].stats.newton_its);
  EXPECT_GT(runs[0].stats.newton_its, runs[0].stats.steps);  // the steps were solved, not skipped
  const double scale = runs[1].u.cwiseAbs().maxCoeff();
  EXPECT_GT(scale, 1e-3);  // the body settled and started to move
  EXPECT_LT((runs[0].u - runs[1].u).cwiseAbs().maxCoeff(), 1e-9 * scale);
}
