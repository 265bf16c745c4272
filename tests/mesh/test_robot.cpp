// Robot geometries: named regions, analytic region volumes, closed cavity walls that
// enclose the cavity volumes, feet in the skin's bottom plane, bladder numbering.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "core/errors.h"
#include "mesh/geometry.h"
#include "mesh/robot.h"

namespace morphfem {
namespace {

using Vec3 = Eigen::Vector3d;

ParamSet robot_params(const std::string& type, const std::vector<std::pair<std::string, double>>& values) {
  ParamSet params("geometry");
  params.set_string("type", type);
  for (const auto& [key, value] : values) params.set(key, value);
  return params;
}

Vec3 node(const Mesh& mesh, int n) { return mesh.X.row(n).transpose(); }

// Lowest z [m] of a volume region's cell vertices.
double lowest_z(const Mesh& mesh, const std::string& region) {
  double z = std::numeric_limits<double>::infinity();
  for (int c : mesh.cells_of(region))
    for (int i = 0; i < 4; ++i) z = std::min(z, node(mesh, mesh.cells(c, i)).z());
  return z;
}

Vec3 face_area_normal(const Mesh& mesh, int f) {
  const Vec3 x0 = node(mesh, mesh.faces(f, 0));
  return 0.5 * (node(mesh, mesh.faces(f, 1)) - x0).cross(node(mesh, mesh.faces(f, 2)) - x0);
}

double cell_volume(const Mesh& mesh, int c) {
  const Vec3 x0 = node(mesh, mesh.cells(c, 0));
  return (node(mesh, mesh.cells(c, 1)) - x0)
             .dot((node(mesh, mesh.cells(c, 2)) - x0).cross(node(mesh, mesh.cells(c, 3)) - x0)) /
         6.0;
}

double region_volume(const Mesh& mesh, const std::string& name) {
  double v = 0.0;
  for (int c : mesh.cells_of(name)) v += cell_volume(mesh, c);
  return v;
}

Vec3 region_centroid(const Mesh& mesh, const std::string& name) {
  Vec3 sum = Vec3::Zero();
  double v = 0.0;
  for (int c : mesh.cells_of(name)) {
    const double vc = cell_volume(mesh, c);
    Vec3 x = Vec3::Zero();
    for (int k = 0; k < 4; ++k) x += node(mesh, mesh.cells(c, k)) / 4.0;
    sum += vc * x;
    v += vc;
  }
  return sum / v;
}

// Faces of the surfaces point out of the solid; returns -(1/3) sum x.n A (the volume
// they enclose if they close a cavity) and the residual |sum n A| (0 when closed).
std::pair<double, double> enclosed_volume(const Mesh& mesh, const std::vector<std::string>& surfaces) {
  double v = 0.0;
  Vec3 sum = Vec3::Zero();
  for (const std::string& s : surfaces)
    for (int f : mesh.faces_of(s)) {
      const Vec3 na = face_area_normal(mesh, f);
      v -= node(mesh, mesh.faces(f, 0)).dot(na) / 3.0;
      sum += na;
    }
  return {v, sum.norm()};
}

double area(const Mesh& mesh, const std::string& surface) {
  double a = 0.0;
  for (int f : mesh.faces_of(surface)) a += face_area_normal(mesh, f).norm();
  return a;
}

// Every face of `surface` lies in z = z0 within y in [y0, y1] and faces down.
void expect_downward_in_plane(const Mesh& mesh, const std::string& surface, double z0, double y0, double y1) {
  ASSERT_FALSE(mesh.faces_of(surface).empty()) << surface;
  for (int f : mesh.faces_of(surface)) {
    for (int k = 0; k < mesh.nodes_per_face(); ++k) {
      const Vec3 x = node(mesh, mesh.faces(f, k));
      EXPECT_NEAR(x.z(), z0, 1e-12) << surface << " face " << f;
      EXPECT_GE(x.y(), y0 - 1e-12) << surface << " face " << f;
      EXPECT_LE(x.y(), y1 + 1e-12) << surface << " face " << f;
    }
    EXPECT_LT(face_area_normal(mesh, f).normalized().z(), -1.0 + 1e-12) << surface << " face " << f;
  }
}

std::vector<std::string> sorted(std::vector<std::string> v) {
  std::sort(v.begin(), v.end());
  return v;
}

std::vector<std::string> bladder_names(const std::string& suffix) {
  std::vector<std::string> names;
  for (int k = 1; k <= 8; ++k) names.push_back("bladder_" + std::to_string(k) + suffix);
  return names;
}

// Voxel-study preset, default dimensions [m].
constexpr double kW = 0.15, kL = 0.22, kT = 0.01, kGap = 0.002, kEdge = 0.01, kSeal = 0.01, kHb = 0.02;
constexpr double kBw = 0.03, kBy0 = 0.03, kBy1 = 0.19, kFoot = 0.03;

// "bottom": the lower bladders' bottoms at z = 0 and the uncovered skin bottom at
// z = kHb, all facing down.
// The voxel preset's feet: every face lies in the bottom layer's foot band
// [0, kW] x [y0, y1] x [kHb, kHb + kT] on its outside (x = 0 or kW, y = 0 or kL, or
// z = kHb facing down), and the downward ones have the band's area.
void expect_foot_voxels(const Mesh& mesh, const std::string& surface, double y0, double y1) {
  ASSERT_FALSE(mesh.faces_of(surface).empty()) << surface;
  double down = 0.0;
  for (int f : mesh.faces_of(surface)) {
    const Vec3 n = face_area_normal(mesh, f);
    Vec3 lo = Vec3::Constant(1e9), hi = Vec3::Constant(-1e9);
    for (int k = 0; k < mesh.nodes_per_face(); ++k) {
      const Vec3 x = node(mesh, mesh.faces(f, k));
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    EXPECT_GE(lo.y(), y0 - 1e-12) << surface << " face " << f;
    EXPECT_LE(hi.y(), y1 + 1e-12) << surface << " face " << f;
    EXPECT_GE(lo.z(), kHb - 1e-12) << surface << " face " << f;
    EXPECT_LE(hi.z(), kHb + kT + 1e-12) << surface << " face " << f;
    const bool bottom = hi.z() < kHb + 1e-12 && n.normalized().z() < -1.0 + 1e-12;
    const bool side = (hi.x() < 1e-12 || lo.x() > kW - 1e-12) && std::abs(n.normalized().x()) > 1.0 - 1e-12;
    const bool end = (hi.y() < 1e-12 || lo.y() > kL - 1e-12) && std::abs(n.normalized().y()) > 1.0 - 1e-12;
    EXPECT_TRUE(bottom || side || end) << surface << " face " << f << " is not on the foot voxels' outside";
    if (bottom) down += n.norm();
  }
  EXPECT_NEAR(down, kW * (y1 - y0), 1e-12) << surface;
}

void expect_bottom_levels(const Mesh& mesh) {
  double at_ground = 0.0, at_skin = 0.0;
  for (int f : mesh.faces_of("bottom")) {
    const double z = node(mesh, mesh.faces(f, 0)).z(), a = face_area_normal(mesh, f).norm();
    if (std::abs(z) < 1e-12) at_ground += a;
    if (std::abs(z - kHb) < 1e-12) at_skin += a;
    EXPECT_LT(face_area_normal(mesh, f).normalized().z(), -1.0 + 1e-12);
  }
  EXPECT_NEAR(at_ground, 4 * kBw * (kBy1 - kBy0), 1e-12);
  EXPECT_NEAR(at_skin, kW * kL - 4 * kBw * (kBy1 - kBy0), 1e-12);
}

void expect_voxel_robot(const Mesh& mesh) {
  std::vector<std::string> volumes = bladder_names("");
  volumes.push_back("skin");
  EXPECT_EQ(sorted(mesh.region_names(3)), sorted(volumes));
  EXPECT_EQ(sorted(mesh.region_names(2)), sorted({"core_wall", "bottom", "foot_a", "foot_b", "outer", "skin_surface",
                                                  "bladder_surface", "end_a", "end_b"}));

  // Region volumes: exact for straight-sided tetrahedra filling boxes.
  const double skin = 2 * kW * kL * kT + 2 * kEdge * kL * kGap + 2 * (kW - 2 * kEdge) * kSeal * kGap;
  const double bladder = kBw * (kBy1 - kBy0) * kHb;
  EXPECT_NEAR(region_volume(mesh, "skin"), skin, 1e-10 * skin);
  for (int k = 1; k <= 8; ++k)
    EXPECT_NEAR(region_volume(mesh, "bladder_" + std::to_string(k)), bladder, 1e-10 * bladder) << k;
  EXPECT_NEAR(mesh.volume(), skin + 8 * bladder, 1e-10 * skin);

  // The core wall is closed and encloses the gap.
  const double gap = (kW - 2 * kEdge) * (kL - 2 * kSeal) * kGap;
  const auto [core_volume, core_residual] = enclosed_volume(mesh, {"core_wall"});
  EXPECT_GT(core_volume, 0.0);
  EXPECT_NEAR(core_volume, gap, 1e-10 * gap);
  EXPECT_LT(core_residual, 1e-14);
  // core_wall + bottom + outer is the whole boundary, once: encloses minus the solid.
  const auto [all_volume, all_residual] = enclosed_volume(mesh, {"core_wall", "bottom", "outer"});
  EXPECT_NEAR(all_volume, -(skin + 8 * bladder), 1e-10 * skin);
  EXPECT_LT(all_residual, 1e-14);
  // The friction split of the same outside: feet + skin_surface + bladder_surface, once.
  const auto [split_volume, split_residual] =
      enclosed_volume(mesh, {"core_wall", "foot_a", "foot_b", "skin_surface", "bladder_surface"});
  EXPECT_NEAR(split_volume, -(skin + 8 * bladder), 1e-10 * skin);
  EXPECT_LT(split_residual, 1e-14);
  // Every bladder_surface face belongs to a bladder cell; 4 lower + 4 upper blocks:
  // each block's outside is its box minus the face glued to the skin.
  const double block_faces = 2 * kBw * (kBy1 - kBy0) + 2 * (kBy1 - kBy0) * kHb + 2 * kBw * kHb;
  EXPECT_NEAR(area(mesh, "bladder_surface"), 8 * (block_faces - kBw * (kBy1 - kBy0)), 1e-12);

  // Feet: the outside of the bottom layer's foot voxels, its bottom face (in the skin's
  // bottom plane), its end face and its two side faces; their downward part is the
  // footprint's ends. bottom = lower bladders' bottoms + uncovered skin bottom, which
  // together cover the footprint once.
  expect_foot_voxels(mesh, "foot_a", 0.0, kFoot);
  expect_foot_voxels(mesh, "foot_b", kL - kFoot, kL);
  const double foot = kW * kFoot + kW * kT + 2 * kFoot * kT;
  EXPECT_NEAR(area(mesh, "foot_a"), foot, 1e-12);
  EXPECT_NEAR(area(mesh, "foot_b"), foot, 1e-12);
  EXPECT_NEAR(area(mesh, "bottom"), kW * kL, 1e-12);
  expect_bottom_levels(mesh);
  // The end faces: the sealed cross-section (two layers, the gap's seal) at y = 0 and y = L.
  const double end = 2 * kW * kT + kW * kGap;
  EXPECT_NEAR(area(mesh, "end_a"), end, 1e-12);
  EXPECT_NEAR(area(mesh, "end_b"), end, 1e-12);
}

// Bladders 1..4 on top with increasing x, 5..8 below with decreasing x.
void expect_bladder_numbering(const Mesh& mesh, double pitch, double top_z_min) {
  for (int k = 1; k <= 8; ++k) {
    const Vec3 c = region_centroid(mesh, "bladder_" + std::to_string(k));
    const int column = k <= 4 ? k - 1 : 8 - k;
    EXPECT_NEAR(c.x(), kBw / 2 + column * pitch, 1e-9) << k;
    if (k <= 4) {
      EXPECT_GT(c.z(), top_z_min) << k;
    } else {
      EXPECT_LT(c.z(), kHb) << k;
    }
  }
}

// A geometry the mesher gives up on is an input error naming the geometry and the size,
// not a crash: gmsh 4.8 (Debian 12) throws std::string from its 3-D mesher, here
// "Could not recover boundary mesh" for the laminate with foot pads at 7.5 mm (7 mm and
// 1 cm mesh). Another gmsh may mesh it; then the failure path is not exercised here.
// The message names the scene line of mesh_size, the key a user changes to mend it.
TEST(RobotGeometry, MesherFailureIsAnInputError) {
  auto params = robot_params("robot_physical", {{"foot_pad", 0.004}, {"bladder_wall", 0.0006}});
  params.set("mesh_size", 0.0075, "robot.yaml:4:14");
  try {
    build_geometry(params);
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("gmsh could not mesh the geometry at mesh_size 0.0075"), std::string::npos) << what;
    EXPECT_EQ(what.rfind("robot.yaml:4:14: geometry.mesh_size: ", 0), 0u) << what;
    // gmsh was restarted: the next geometry in the same process meshes completely.
    const Mesh mesh = build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}}));
    EXPECT_TRUE(mesh.has_region("bottom", 2));
    EXPECT_GT(mesh.n_cells(), 0);
    return;
  }
  GTEST_SKIP() << "this gmsh meshes the laminate at 7.5 mm; the mesher-failure path is not exercised";
}

}  // namespace

// gmsh 4.8's boundary recovery can also fail an assert() and abort, which cannot be
// caught: here for strip chambers refined to 8 mm that end flush with the 5 mm end
// seals, with the fabric as a membrane. The mesher then reports the mesh_size key's scene line
// and the size and exits with 2 (bad input),
// not with a core dump. The child exits with 3 if this gmsh meshes the geometry.
TEST(RobotGeometryDeathTest, MesherAbortIsReportedAndExitsWith2) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  auto params = robot_params(
      "robot_physical",
      {{"bladder_mesh_size", 0.008}, {"bladder_wall", 0.0012}, {"bladder_bond_width", 0.004}, {"foot_length", 0.005}});
  params.set_string("fabric", "membrane");
  params.set("mesh_size", 0.019, "robot.yaml:4:14");
  const auto exited_2_or_3 = [](int status) {
    return WIFEXITED(status) && (WEXITSTATUS(status) == 2 || WEXITSTATUS(status) == 3);
  };
  EXPECT_EXIT(
      {
        build_geometry(params);
        std::fprintf(stderr, "this gmsh meshes the geometry\n");
        std::_Exit(3);
      },
      exited_2_or_3,
      "robot.yaml:4:14: geometry.mesh_size: gmsh aborted while meshing the geometry at mesh_size 0.019 m|this gmsh "
      "meshes the geometry");
}

TEST(RobotGeometry, VoxelPresetP1) {
  const Mesh mesh = build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.015}}));
  EXPECT_EQ(mesh.order, 1);
  expect_voxel_robot(mesh);
  expect_bladder_numbering(mesh, 0.04, kHb + 2 * kT + kGap);
}

TEST(RobotGeometry, VoxelPresetP2) {
  const Mesh mesh = build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"order", 2}}));
  EXPECT_EQ(mesh.order, 2);
  EXPECT_EQ(mesh.nodes_per_cell(), 10);
  expect_voxel_robot(mesh);
}

TEST(RobotGeometry, PhysicalPreset) {
  // Defaults of robot_physical [m].
  const double W = 0.10, L = 0.15, t = 0.003, tf = 0.0005, g = 0.001, e = 0.005, s = 0.005, hb = 0.003, w = 0.0008;
  const double bw = 0.02, foot = 0.02;
  const Mesh mesh = build_geometry(robot_params("robot_physical", {{"mesh_size", 0.006}}));

  std::vector<std::string> volumes = bladder_names("");
  volumes.push_back("skin");
  volumes.push_back("fabric");
  EXPECT_EQ(sorted(mesh.region_names(3)), sorted(volumes));
  std::vector<std::string> surfaces = bladder_names("_wall");
  for (const char* name :
       {"core_wall", "bottom", "foot_a", "foot_b", "outer", "skin_surface", "bladder_surface", "end_a", "end_b"})
    surfaces.push_back(name);
  EXPECT_EQ(sorted(mesh.region_names(2)), sorted(surfaces));

  const double fabric = 2 * W * L * tf;
  const double skin = 2 * W * L * (t - tf) + 2 * e * L * g + 2 * (W - 2 * e) * s * g;
  const double chamber = (bw - 2 * w) * (L - 2 * foot - 2 * w) * (hb - 2 * w);
  const double bladder = bw * (L - 2 * foot) * hb - chamber;
  EXPECT_NEAR(region_volume(mesh, "fabric"), fabric, 1e-10 * fabric);
  EXPECT_NEAR(region_volume(mesh, "skin"), skin, 1e-10 * skin);
  for (int k = 1; k <= 8; ++k) {
    const std::string name = "bladder_" + std::to_string(k);
    EXPECT_NEAR(region_volume(mesh, name), bladder, 1e-10 * bladder) << k;
    const auto [v, residual] = enclosed_volume(mesh, {name + "_wall"});
    EXPECT_NEAR(v, chamber, 1e-10 * chamber) << k;
    EXPECT_LT(residual, 1e-14) << k;
  }
  const double gap = (W - 2 * e) * (L - 2 * s) * g;
  const auto [core, core_residual] = enclosed_volume(mesh, {"core_wall"});
  EXPECT_NEAR(core, gap, 1e-10 * gap);
  EXPECT_LT(core_residual, 1e-14);

  std::vector<std::string> boundary = bladder_names("_wall");
  for (const char* name : {"core_wall", "bottom", "outer"}) boundary.push_back(name);
  const auto [all, all_residual] = enclosed_volume(mesh, boundary);
  EXPECT_NEAR(all, -(skin + fabric + 8 * bladder), 1e-10 * skin);
  EXPECT_LT(all_residual, 1e-14);

  expect_downward_in_plane(mesh, "foot_a", hb, 0.0, foot);
  expect_downward_in_plane(mesh, "foot_b", hb, L - foot, L);
  EXPECT_NEAR(area(mesh, "foot_a"), W * foot, 1e-12);
  EXPECT_NEAR(area(mesh, "bottom"), W * L, 1e-12);

  // Fabric sheets at mid-thickness of both skin layers; bladders 1..4 on top, 5..8 below.
  double z_min = 1.0, z_max = 0.0;
  for (int c : mesh.cells_of("fabric"))
    for (int k = 0; k < 4; ++k) {
      z_min = std::min(z_min, node(mesh, mesh.cells(c, k)).z());
      z_max = std::max(z_max, node(mesh, mesh.cells(c, k)).z());
    }
  EXPECT_NEAR(z_min, hb + (t - tf) / 2, 1e-12);
  EXPECT_NEAR(z_max, hb + t + g + (t + tf) / 2, 1e-12);
  const double pitch = (W - bw) / 3;
  for (int k = 1; k <= 8; ++k) {
    const Vec3 c = region_centroid(mesh, "bladder_" + std::to_string(k));
    EXPECT_NEAR(c.x(), bw / 2 + (k <= 4 ? k - 1 : 8 - k) * pitch, 1e-9) << k;
    EXPECT_NEAR(c.z(), k <= 4 ? hb + 2 * t + g + hb / 2 : hb / 2, 1e-9) << k;
  }
}

// fabric: membrane: no fabric volume, DS10 throughout each 3 mm skin layer, and an
// internal surface fabric_sheet at each layer's mid-thickness (both sheets cover the
// whole W x L), whose triangles are faces shared by two skin cells.
TEST(RobotGeometry, PhysicalMembraneFabricSheets) {
  const double W = 0.10, L = 0.15, t = 0.003, g = 0.001, e = 0.005, s = 0.005, hb = 0.003;
  ParamSet params = robot_params("robot_physical", {{"mesh_size", 0.02}});
  params.set_string("fabric", "membrane");
  const Mesh mesh = build_geometry(params);
  EXPECT_FALSE(mesh.has_region("fabric", 3));
  ASSERT_TRUE(mesh.has_region("fabric_sheet", 2));
  const double skin = 2 * W * L * t + 2 * e * L * g + 2 * (W - 2 * e) * s * g;
  EXPECT_NEAR(region_volume(mesh, "skin"), skin, 1e-10 * skin);
  EXPECT_NEAR(area(mesh, "fabric_sheet"), 2 * W * L, 1e-12);
  int lower = 0, upper = 0;
  for (int f : mesh.faces_of("fabric_sheet"))
    for (int k = 0; k < 3; ++k) {
      const double z = node(mesh, mesh.faces(f, k)).z();
      lower += std::abs(z - (hb + t / 2)) < 1e-12;
      upper += std::abs(z - (hb + t + g + t / 2)) < 1e-12;
    }
  EXPECT_EQ(lower + upper, 3 * static_cast<int>(mesh.faces_of("fabric_sheet").size()));
  EXPECT_GT(lower, 0);
  EXPECT_GT(upper, 0);
  // Unchanged outer boundary: the closed surfaces still enclose the solid.
  std::vector<std::string> boundary = bladder_names("_wall");
  for (const char* name : {"core_wall", "bottom", "outer"}) boundary.push_back(name);
  EXPECT_LT(enclosed_volume(mesh, boundary).second, 1e-14);
  params.set_string("fabric", "felt");
  EXPECT_THROW(build_geometry(params), InputError);
}

TEST(RobotGeometry, OverridesAndBadParameters) {
  // A thinner gap and narrower bonded edges change the core volume accordingly.
  const Mesh mesh =
      build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"core_gap", 0.001}, {"edge_width", 0.02}}));
  const auto [core, residual] = enclosed_volume(mesh, {"core_wall"});
  EXPECT_NEAR(core, (kW - 0.04) * (kL - 2 * kSeal) * 0.001, 1e-10 * core);

  EXPECT_THROW(build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"edge_width", 0.08}})), InputError);
  EXPECT_THROW(build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"bladder_width", 0.04}})), InputError);
  EXPECT_THROW(build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"core_gapp", 0.001}})), InputError);
  EXPECT_THROW(build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"core_gap", 0.0}})), InputError);
  EXPECT_THROW(build_geometry(robot_params("robot_physical", {{"mesh_size", 0.03}, {"bladder_wall", 0.002}})),
               InputError);
  EXPECT_THROW(build_geometry(robot_params("robot_physical", {{"mesh_size", 0.03}, {"fabric_thickness", 0.003}})),
               InputError);
}

// end_seal 0: the core is open at both ends. Its wall is the gap's top, bottom and
// sides only (area exact), the open sleeve's volume over x and z is the gap, and the
// end faces lack the gap.
TEST(RobotGeometry, OpenEndedCore) {
  const Mesh mesh = build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"end_seal", 0.0}}));
  EXPECT_NEAR(area(mesh, "core_wall"), 2 * (kW - 2 * kEdge) * kL + 2 * kGap * kL, 1e-12);
  const double skin = 2 * kW * kL * kT + 2 * kEdge * kL * kGap;
  EXPECT_NEAR(region_volume(mesh, "skin"), skin, 1e-10 * skin);
  EXPECT_NEAR(area(mesh, "end_a"), 2 * kW * kT + 2 * kEdge * kGap, 1e-12);
  EXPECT_NEAR(area(mesh, "end_b"), 2 * kW * kT + 2 * kEdge * kGap, 1e-12);
  for (int f : mesh.faces_of("core_wall")) EXPECT_LT(std::abs(face_area_normal(mesh, f).normalized().y()), 1e-12);
  EXPECT_THROW(build_geometry(robot_params("robot_voxel", {{"mesh_size", 0.03}, {"end_seal", -0.01}})), InputError);
}

// A plane-strain slice of the physical laminate: no feet (foot_length 0) and chambers
// without end walls (bladder_end_walls 0) running through the slice as open sleeves.
// Each chamber wall is then the chamber's floor, roof and sides only (area exact, no
// face normal along y), the DS30 walls lose their end caps, and there are no feet.
TEST(RobotGeometry, PhysicalSliceWithOpenChambers) {
  const double W = 0.10, L = 0.006, t = 0.003, tf = 0.0005, g = 0.001, e = 0.005, hb = 0.003, w = 0.0008, bw = 0.02;
  const Mesh mesh = build_geometry(robot_params(
      "robot_physical",
      {{"mesh_size", 0.003}, {"length", L}, {"end_seal", 0.0}, {"foot_length", 0.0}, {"bladder_end_walls", 0}}));
  const auto names = mesh.region_names(2);
  EXPECT_EQ(std::count(names.begin(), names.end(), "foot_a"), 0);
  EXPECT_EQ(std::count(names.begin(), names.end(), "foot_b"), 0);
  const double bladder = (bw * hb - (bw - 2 * w) * (hb - 2 * w)) * L;
  for (int k = 1; k <= 8; ++k) {
    const std::string name = "bladder_" + std::to_string(k);
    EXPECT_NEAR(region_volume(mesh, name), bladder, 1e-10 * bladder) << k;
    EXPECT_NEAR(area(mesh, name + "_wall"), 2 * ((bw - 2 * w) + (hb - 2 * w)) * L, 1e-12) << k;
    for (int f : mesh.faces_of(name + "_wall"))
      EXPECT_LT(std::abs(face_area_normal(mesh, f).normalized().y()), 1e-12) << k;
  }
  const double skin = 2 * W * L * (t - tf) + 2 * e * L * g;
  EXPECT_NEAR(region_volume(mesh, "skin"), skin, 1e-10 * skin);
  EXPECT_NEAR(area(mesh, "bottom"), W * L, 1e-12);
  // With end walls the chambers need room for them along the slice (2 x 0.8 mm).
  try {
    build_geometry(robot_params("robot_physical",
                                {{"mesh_size", 0.003}, {"length", 0.0015}, {"end_seal", 0.0}, {"foot_length", 0.0}}));
    ADD_FAILURE() << "a 1.5 mm slice with chamber end walls was accepted";
  } catch (const InputError& err) {
    EXPECT_NE(std::string(err.what()).find("bladder_wall"), std::string::npos) << err.what();
  }
  EXPECT_THROW(build_geometry(robot_params("robot_physical", {{"mesh_size", 0.003}, {"bladder_end_walls", 2}})),
               InputError);
}

// bladder_bond_width: each chamber bonded to the skin only along a central DS30 strip,
// standing bladder_gap off the skin. In a slice: the DS30 volume gains the strip, the
// chambers keep their cavities, the top chambers rise by the gap and the bottom ones
// stay on the ground, the skin is lifted by the gap, and the gap's faces are outside
// faces (the boundary still closes around every solid).
TEST(RobotGeometry, PhysicalChambersBondedAlongAStrip) {
  const double L = 0.006, t = 0.003, g = 0.001, hb = 0.003, w = 0.0008, bw = 0.02;
  const double bond = 0.006, gap = 0.0005;
  const std::vector<std::pair<std::string, double>> slice = {
      {"mesh_size", 0.003}, {"length", L}, {"end_seal", 0.0}, {"foot_length", 0.0}, {"bladder_end_walls", 0}};
  auto with = [&](std::vector<std::pair<std::string, double>> extra) {
    auto p = slice;
    p.insert(p.end(), extra.begin(), extra.end());
    return robot_params("robot_physical", p);
  };
  const Mesh mesh = build_geometry(with({{"bladder_bond_width", bond}, {"bladder_gap", gap}}));
  const double bladder = (bw * hb - (bw - 2 * w) * (hb - 2 * w) + bond * gap) * L;
  EXPECT_NEAR(lowest_z(mesh, "skin"), hb + gap, 1e-12);
  const double z_upper = hb + gap + 2 * t + g;
  for (int k = 1; k <= 8; ++k) {
    const std::string name = "bladder_" + std::to_string(k);
    EXPECT_NEAR(region_volume(mesh, name), bladder, 1e-10 * bladder) << k;
    EXPECT_NEAR(area(mesh, name + "_wall"), 2 * ((bw - 2 * w) + (hb - 2 * w)) * L, 1e-12) << k;
    EXPECT_NEAR(lowest_z(mesh, name), k <= 4 ? z_upper : 0.0, 1e-12) << k;  // a top chamber's strip starts on the skin
  }
  // The boundary still closes around every solid, the strips included.
  std::vector<std::string> boundary = bladder_names("_wall");
  for (const char* name : {"core_wall", "bottom", "outer"}) boundary.push_back(name);
  double solid = 0.0;
  for (const std::string& v : mesh.region_names(3)) solid += region_volume(mesh, v);
  const auto [all, residual] = enclosed_volume(mesh, boundary);
  EXPECT_NEAR(all, -solid, 1e-10 * solid);
  EXPECT_LT(residual, 1e-14);
  // New outside faces per chamber against the bonded body: the floor's underside and the
  // skin beside the strip (bw - bond wide each), the strip's two sides (gap high), and
  // the strip's ends at y = 0 and y = L.
  const Mesh bonded = build_geometry(with({}));
  const double added = 8 * ((2 * (bw - bond) + 2 * gap) * L + 2 * bond * gap);
  EXPECT_NEAR(area(mesh, "bottom") + area(mesh, "outer") - area(bonded, "bottom") - area(bonded, "outer"), added,
              1e-12);
  for (auto bad :
       std::vector<std::vector<std::pair<std::string, double>>>{{{"bladder_bond_width", 0.03}},
                                                                {{"bladder_gap", 0.001}},
                                                                {{"bladder_bond_width", 0.01}, {"bladder_gap", 0.0}}})
    EXPECT_THROW(build_geometry(with(bad)), InputError);
}

// bladder_mesh_size refines the chambers only: their cells get shorter edges and are
// more, and every region keeps its exact volume.
TEST(RobotGeometry, PhysicalChamberRefinement) {
  auto longest_edge = [](const Mesh& mesh, const std::string& region) {
    double longest = 0.0;
    for (int c : mesh.cells_of(region))
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          longest = std::max(longest, (node(mesh, mesh.cells(c, i)) - node(mesh, mesh.cells(c, j))).norm());
    return longest;
  };
  const double h = 0.03, hc = 0.01;
  const Mesh coarse = build_geometry(robot_params("robot_physical", {{"mesh_size", h}}));
  const Mesh fine = build_geometry(robot_params("robot_physical", {{"mesh_size", h}, {"bladder_mesh_size", hc}}));
  for (int k = 1; k <= 8; ++k) {
    const std::string name = "bladder_" + std::to_string(k);
    EXPECT_GT(fine.cells_of(name).size(), 2 * coarse.cells_of(name).size()) << k;
    EXPECT_LT(longest_edge(fine, name), 1.5 * hc) << k;
    EXPECT_GT(longest_edge(coarse, name), 2.0 * hc) << k;
  }
  for (const std::string& v : coarse.region_names(3))
    EXPECT_NEAR(region_volume(fine, v), region_volume(coarse, v), 1e-10 * region_volume(coarse, v)) << v;
  EXPECT_THROW(build_geometry(robot_params("robot_physical", {{"mesh_size", h}, {"bladder_mesh_size", 0.05}})),
               InputError);
}

// foot_pad: a DS10 pad under the skin in each foot band (volume `foot`) whose bottom
// is the foot. A pad 1 mm thicker than the lower bladders lifts the body by 1 mm: the
// feet are the lowest faces (z = 0), the lower bladders' bottoms 1 mm above the ground.
TEST(RobotGeometry, PhysicalFootPadsCarryTheBody) {
  const double W = 0.10, L = 0.15, foot = 0.02, hb = 0.003, pad = 0.004;
  const Mesh mesh = build_geometry(robot_params("robot_physical", {{"mesh_size", 0.01}, {"foot_pad", pad}}));
  const auto volumes = mesh.region_names(3);
  ASSERT_EQ(std::count(volumes.begin(), volumes.end(), "foot"), 1);
  EXPECT_NEAR(region_volume(mesh, "foot"), 2 * W * foot * pad, 1e-10 * W * foot * pad);
  expect_downward_in_plane(mesh, "foot_a", 0.0, 0.0, foot);
  expect_downward_in_plane(mesh, "foot_b", 0.0, L - foot, L);
  EXPECT_NEAR(area(mesh, "foot_a"), W * foot, 1e-12);
  EXPECT_NEAR(area(mesh, "foot_b"), W * foot, 1e-12);
  EXPECT_NEAR(area(mesh, "bottom"), W * L, 1e-12);
  for (int k = 5; k <= 8; ++k) {
    EXPECT_NEAR(lowest_z(mesh, "bladder_" + std::to_string(k)), pad - hb, 1e-12) << k;
  }
  double lowest = 1.0;
  for (int n = 0; n < mesh.X.rows(); ++n) lowest = std::min(lowest, mesh.X(n, 2));
  EXPECT_NEAR(lowest, 0.0, 1e-12);
  // The boundary still closes around every solid, the pads included.
  std::vector<std::string> boundary = bladder_names("_wall");
  for (const char* name : {"core_wall", "bottom", "outer"}) boundary.push_back(name);
  double solid = 0.0;
  for (const std::string& v : volumes) solid += region_volume(mesh, v);
  const auto [all, residual] = enclosed_volume(mesh, boundary);
  EXPECT_NEAR(all, -solid, 1e-10 * solid);
  EXPECT_LT(residual, 1e-14);
  EXPECT_THROW(
      build_geometry(robot_params("robot_physical",
                                  {{"mesh_size", 0.01}, {"foot_pad", 0.004}, {"foot_length", 0.0}, {"length", 0.01}})),
      InputError);
}

TEST(RobotGeometry, PhysicalPresetP2) {
  const Mesh mesh = build_geometry(robot_params("robot_physical", {{"mesh_size", 0.03}, {"order", 2}}));
  EXPECT_EQ(mesh.order, 2);
  const double chamber = (0.02 - 0.0016) * (0.15 - 0.04 - 0.0016) * (0.003 - 0.0016);
  for (int k = 1; k <= 8; ++k) {
    const auto [v, residual] = enclosed_volume(mesh, {"bladder_" + std::to_string(k) + "_wall"});
    EXPECT_NEAR(v, chamber, 1e-10 * chamber) << k;
  }
  EXPECT_NEAR(mesh.volume(),
              region_volume(mesh, "skin") + region_volume(mesh, "fabric") + 8 * region_volume(mesh, "bladder_1"),
              1e-9 * mesh.volume());
  expect_downward_in_plane(mesh, "foot_b", 0.003, 0.13, 0.15);
}

}  // namespace morphfem
