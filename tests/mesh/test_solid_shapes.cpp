// Solid-shape builders (mesh/solid_shapes.h): regions, volumes against the exact
// solids, nodes on their named surfaces, and the hemisphere's local refinement at
// its pole (the Hertz contact point).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "core/errors.h"
#include "mesh/geometry.h"

namespace morphfem {
namespace {

constexpr double kPi = 3.14159265358979323846;

ParamSet shape_params(const std::string& type, const std::vector<std::pair<std::string, double>>& values) {
  ParamSet params("geometry");
  params.set_string("type", type);
  for (const auto& [key, value] : values) params.set(key, value);
  return params;
}

std::set<std::string> names(const Mesh& mesh, int dim) {
  const auto v = mesh.region_names(dim);
  return {v.begin(), v.end()};
}

// Longest vertex-to-vertex edge of cell c [m].
double longest_edge(const Mesh& mesh, int c) {
  double longest = 0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b)
      longest = std::max(longest, (mesh.X.row(mesh.cells(c, a)) - mesh.X.row(mesh.cells(c, b))).norm());
  return longest;
}

Eigen::Vector3d centroid(const Mesh& mesh, int c) {
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int a = 0; a < 4; ++a) x += mesh.X.row(mesh.cells(c, a)).transpose() / 4.0;
  return x;
}

TEST(Hemisphere, QuarterP2HasItsRegionsVolumeAndSurfaces) {
  const double R = 0.01;
  const Mesh mesh = build_geometry(
      shape_params("hemisphere", {{"radius", R}, {"mesh_size", R / 3}, {"contact_size", R / 10}, {"order", 2}}));
  EXPECT_EQ(names(mesh, 3), std::set<std::string>({"body"}));
  EXPECT_EQ(names(mesh, 2), std::set<std::string>({"flat", "sphere", "sym_x", "sym_y"}));
  // A quarter of the half-ball: pi R^3 / 6; P2 with curved mid-nodes is close.
  EXPECT_NEAR(mesh.volume() / (kPi * R * R * R / 6), 1.0, 2e-3);
  for (int n : mesh.nodes_of_surface("sphere")) EXPECT_NEAR(mesh.X.row(n).norm(), R, 1e-9 * R);
  for (int n : mesh.nodes_of_surface("flat")) EXPECT_NEAR(mesh.X(n, 2), 0.0, 1e-9 * R);
  for (int n : mesh.nodes_of_surface("sym_x")) EXPECT_NEAR(mesh.X(n, 0), 0.0, 1e-9 * R);
  for (int n : mesh.nodes_of_surface("sym_y")) EXPECT_NEAR(mesh.X(n, 1), 0.0, 1e-9 * R);
  // The pole is a node (the first contact point).
  const auto sphere = mesh.nodes_of_surface("sphere");
  double closest = 1e300;
  for (int n : sphere) closest = std::min(closest, (mesh.X.row(n) - Eigen::RowVector3d(0, 0, -R)).norm());
  EXPECT_LT(closest, 1e-9 * R);
}

TEST(Hemisphere, ElementsAreFineNearThePoleAndCoarseFarFromIt) {
  const double R = 0.01, H = R / 3, h = R / 20, r0 = R / 5;
  const Mesh mesh = build_geometry(
      shape_params("hemisphere", {{"radius", R}, {"mesh_size", H}, {"contact_size", h}, {"refine_radius", r0}}));
  const Eigen::Vector3d pole(0, 0, -R);
  double near_longest = 0, far_sum = 0;
  int near_cells = 0, far_cells = 0;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    const double r = (centroid(mesh, c) - pole).norm();
    if (r < 0.5 * r0) {
      near_longest = std::max(near_longest, longest_edge(mesh, c));
      ++near_cells;
    } else if (r > r0 + 2 * (H - h) + H) {
      far_sum += longest_edge(mesh, c);
      ++far_cells;
    }
  }
  ASSERT_GT(near_cells, 20);
  ASSERT_GT(far_cells, 20);
  // Delaunay edges scatter around the target size; the near cells stay below 2 h
  // (h = R/20 against H = R/3 far away), the far ones average above H/2.
  EXPECT_LT(near_longest, 2.0 * h);
  EXPECT_GT(far_sum / far_cells, 0.5 * H);
  // Without refinement the same region holds far fewer cells.
  const Mesh uniform = build_geometry(shape_params("hemisphere", {{"radius", R}, {"mesh_size", H}}));
  int uniform_near = 0;
  for (int c = 0; c < uniform.n_cells(); ++c)
    if ((centroid(uniform, c) - pole).norm() < 0.5 * r0) ++uniform_near;
  EXPECT_GT(near_cells, 10 * std::max(uniform_near, 1));
}

TEST(Hemisphere, FullHalfBallP1) {
  const double R = 0.01;
  const Mesh mesh = build_geometry(shape_params("hemisphere", {{"radius", R}, {"mesh_size", R / 4}, {"quarter", 0}}));
  EXPECT_EQ(names(mesh, 2), std::set<std::string>({"flat", "sphere"}));
  // P1 facets cut inside the sphere: the volume is below 2/3 pi R^3 by O(h^2 / R^2).
  const double exact = 2.0 / 3.0 * kPi * R * R * R;
  EXPECT_LT(mesh.volume(), exact);
  EXPECT_GT(mesh.volume(), 0.95 * exact);
}

TEST(SolidCylinder, SolidP2HasItsRegionsAndVolume) {
  const double R = 0.02, L = 0.01;
  const Mesh mesh = build_geometry(
      shape_params("solid_cylinder", {{"radius", R}, {"length", L}, {"mesh_size", R / 3}, {"order", 2}}));
  EXPECT_EQ(names(mesh, 3), std::set<std::string>({"body"}));
  EXPECT_EQ(names(mesh, 2), std::set<std::string>({"outer", "ymin", "ymax"}));
  EXPECT_NEAR(mesh.volume() / (kPi * R * R * L), 1.0, 2e-3);
  for (int n : mesh.nodes_of_surface("outer")) EXPECT_NEAR(std::hypot(mesh.X(n, 0), mesh.X(n, 2)), R, 1e-9 * R);
  for (int n : mesh.nodes_of_surface("ymin")) EXPECT_NEAR(mesh.X(n, 1), 0.0, 1e-9 * L);
  for (int n : mesh.nodes_of_surface("ymax")) EXPECT_NEAR(mesh.X(n, 1), L, 1e-9 * L);
}

TEST(SolidCylinder, TubeHasAnInnerWall) {
  const double R = 0.02, r = 0.015, L = 0.01;
  const Mesh mesh = build_geometry(shape_params(
      "solid_cylinder", {{"radius", R}, {"inner_radius", r}, {"length", L}, {"mesh_size", 0.003}, {"order", 2}}));
  EXPECT_EQ(names(mesh, 2), std::set<std::string>({"inner", "outer", "ymin", "ymax"}));
  EXPECT_NEAR(mesh.volume() / (kPi * (R * R - r * r) * L), 1.0, 2e-3);
  for (int n : mesh.nodes_of_surface("inner")) EXPECT_NEAR(std::hypot(mesh.X(n, 0), mesh.X(n, 2)), r, 1e-9 * R);
}

TEST(SolidShapes, BadParametersAreInputErrors) {
  EXPECT_THROW(
      build_geometry(shape_params("solid_cylinder",
                                  {{"radius", 0.01}, {"inner_radius", 0.01}, {"length", 0.01}, {"mesh_size", 0.005}})),
      InputError);
  EXPECT_THROW(
      build_geometry(shape_params("hemisphere", {{"radius", 0.01}, {"mesh_size", 0.002}, {"contact_size", 0.004}})),
      InputError);
  EXPECT_THROW(build_geometry(shape_params("hemisphere", {{"radius", 0.01}, {"mesh_size", 0.002}, {"height", 1}})),
               InputError);
}

}  // namespace
}  // namespace morphfem
