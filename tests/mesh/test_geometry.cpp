// Geometry builders: regions, exact volumes, positive cells, outward boundary faces,
// nodes on their surfaces, and P2 mid-nodes at edge midpoints or on curved surfaces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "core/errors.h"
#include "mesh/geometry.h"

namespace morphfem {
namespace {

using Vec3 = Eigen::Vector3d;

ParamSet geometry_params(const std::string& type, const std::vector<std::pair<std::string, double>>& values) {
  ParamSet params("geometry");
  params.set_string("type", type);
  for (const auto& [key, value] : values) params.set(key, value);
  return params;
}

// A boundary surface: distance of a point from it [m], its outward unit normal at a
// point, and whether it is curved (then flat faces only approximate the normal).
struct SurfaceSpec {
  std::string name;
  std::function<double(const Vec3&)> distance;
  std::function<Vec3(const Vec3&)> outward_normal;
  bool curved = false;
};

SurfaceSpec plane(const std::string& name, int axis, double position, double outward_sign) {
  Vec3 normal = Vec3::Zero();
  normal(axis) = outward_sign;
  return {name, [=](const Vec3& x) { return std::abs(x(axis) - position); }, [=](const Vec3&) { return normal; }};
}

// Plane through `point` with outward unit normal `normal`.
SurfaceSpec oblique_plane(const std::string& name, const Vec3& point, const Vec3& normal) {
  const Vec3 n = normal.normalized();
  return {name, [=](const Vec3& x) { return std::abs((x - point).dot(n)); }, [=](const Vec3&) { return n; }};
}

// Cylinder of radius r about the z axis; outward_sign +1 if the solid is inside it.
SurfaceSpec cylinder(const std::string& name, double r, double outward_sign) {
  return {name, [=](const Vec3& x) { return std::abs(x.head<2>().norm() - r); },
          [=](const Vec3& x) { return Vec3(outward_sign * Vec3(x(0), x(1), 0).normalized()); }, true};
}

SurfaceSpec sphere(const std::string& name, double r, double outward_sign) {
  return {name, [=](const Vec3& x) { return std::abs(x.norm() - r); },
          [=](const Vec3& x) { return Vec3(outward_sign * x.normalized()); }, true};
}

std::vector<SurfaceSpec> box_surfaces(const Vec3& l, const std::array<std::string, 6>& names) {
  std::vector<SurfaceSpec> specs;
  for (int axis = 0; axis < 3; ++axis) {
    specs.push_back(plane(names[2 * axis], axis, 0.0, -1.0));
    specs.push_back(plane(names[2 * axis + 1], axis, l(axis), +1.0));
  }
  return specs;
}

Vec3 node(const Mesh& mesh, int n) { return mesh.X.row(n).transpose(); }

// Area-weighted normal (x1 - x0) x (x2 - x0) / 2 of the vertex triangle of face f.
Vec3 face_area_normal(const Mesh& mesh, int f) {
  const Vec3 x0 = node(mesh, mesh.faces(f, 0));
  return 0.5 * (node(mesh, mesh.faces(f, 1)) - x0).cross(node(mesh, mesh.faces(f, 2)) - x0);
}

double vertex_polyhedron_volume(const Mesh& mesh) {
  double volume = 0.0;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    const Vec3 x0 = node(mesh, mesh.cells(c, 0));
    volume += (node(mesh, mesh.cells(c, 1)) - x0)
                  .dot((node(mesh, mesh.cells(c, 2)) - x0).cross(node(mesh, mesh.cells(c, 3)) - x0)) /
              6.0;
  }
  return volume;
}

void expect_regions(const Mesh& mesh, std::vector<std::string> surfaces) {
  EXPECT_EQ(mesh.region_names(3), std::vector<std::string>{"body"});
  std::vector<std::string> names = mesh.region_names(2);
  std::sort(names.begin(), names.end());
  std::sort(surfaces.begin(), surfaces.end());
  EXPECT_EQ(names, surfaces);
  for (const std::string& s : surfaces) EXPECT_FALSE(mesh.faces_of(s).empty()) << s;
}

// The faces (each in one group) close the solid and point outward: by the divergence
// theorem sum(n A) = 0 and V = 1/3 sum(x0 . n A) equals the vertex polyhedron's volume.
void expect_closed_outward_boundary(const Mesh& mesh) {
  Vec3 sum_normals = Vec3::Zero();
  double divergence_volume = 0.0;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    const Vec3 n_area = face_area_normal(mesh, f);
    sum_normals += n_area;
    divergence_volume += node(mesh, mesh.faces(f, 0)).dot(n_area) / 3.0;
  }
  const double scale = std::cbrt(std::abs(divergence_volume));
  EXPECT_LT(sum_normals.norm(), 1e-12 * scale * scale);
  EXPECT_NEAR(divergence_volume, vertex_polyhedron_volume(mesh), 1e-12 * std::abs(divergence_volume));
}

// Every node of every face lies on its surface; every face normal points along the
// surface's outward normal (exactly for planes, within 0.1 rad-ish for curved ones).
void expect_faces_on_surfaces(const Mesh& mesh, const std::vector<SurfaceSpec>& specs, double length_scale) {
  for (const SurfaceSpec& spec : specs) {
    const double min_alignment = spec.curved ? 0.9 : 1.0 - 1e-12;
    for (int f : mesh.faces_of(spec.name)) {
      Vec3 centroid = Vec3::Zero();
      for (int k = 0; k < mesh.nodes_per_face(); ++k) {
        const Vec3 x = node(mesh, mesh.faces(f, k));
        EXPECT_LT(spec.distance(x), 1e-9 * length_scale) << spec.name << " face " << f << " node " << k;
        if (k < 3) centroid += x / 3.0;
      }
      const Vec3 normal = face_area_normal(mesh, f).normalized();
      EXPECT_GT(normal.dot(spec.outward_normal(centroid)), min_alignment) << spec.name << " face " << f;
    }
  }
}

// P2: every mid-node is at its edge's midpoint, unless both ends lie on one curved
// surface, where it must lie on that surface (checks the gmsh -> VTK node order).
void expect_mid_nodes_placed(const Mesh& mesh, const std::vector<SurfaceSpec>& specs, double length_scale) {
  if (mesh.order != 2) return;
  static constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  const double tol = 1e-9 * length_scale;
  int curved_mid_nodes = 0;
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (int e = 0; e < 6; ++e) {
      const Vec3 a = node(mesh, mesh.cells(c, kEdges[e][0])), b = node(mesh, mesh.cells(c, kEdges[e][1]));
      const Vec3 mid = node(mesh, mesh.cells(c, 4 + e));
      if ((mid - 0.5 * (a + b)).norm() < tol) continue;
      bool on_curved = false;
      for (const SurfaceSpec& s : specs)
        on_curved = on_curved || (s.curved && s.distance(a) < tol && s.distance(b) < tol && s.distance(mid) < tol);
      EXPECT_TRUE(on_curved) << "cell " << c << " edge " << e;
      ++curved_mid_nodes;
    }
  const bool has_curved = std::any_of(specs.begin(), specs.end(), [](const SurfaceSpec& s) { return s.curved; });
  if (has_curved) {
    EXPECT_GT(curved_mid_nodes, 0);
  }
}

void expect_valid_geometry(const Mesh& mesh, const std::vector<SurfaceSpec>& specs, double length_scale) {
  EXPECT_NO_THROW(validate_mesh(mesh, "test"));
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);
  expect_regions(mesh, names);
  expect_closed_outward_boundary(mesh);
  expect_faces_on_surfaces(mesh, specs, length_scale);
  expect_mid_nodes_placed(mesh, specs, length_scale);
}

class Builders : public ::testing::TestWithParam<int> {};  // parameter: element order

TEST_P(Builders, Block) {
  const int order = GetParam();
  const Vec3 l(0.4, 0.3, 0.2);
  for (int structured : {0, 1}) {
    const Mesh mesh = build_geometry(geometry_params(
        "block",
        {{"lx", l(0)}, {"ly", l(1)}, {"lz", l(2)}, {"mesh_size", 0.1}, {"order", order}, {"structured", structured}}));
    EXPECT_EQ(mesh.order, order);
    EXPECT_NEAR(mesh.volume(), l.prod(), 1e-12 * l.prod());
    expect_valid_geometry(mesh, box_surfaces(l, {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}), 0.4);
    if (structured && order == 1) {
      EXPECT_EQ(mesh.n_nodes(), 5 * 4 * 3);
    }
  }
}

TEST_P(Builders, DistortedBlockKeepsBoundaryAndVolume) {
  const int order = GetParam();
  const Vec3 l(0.3, 0.3, 0.3);
  auto params = [&](double distort) {
    return geometry_params("block", {{"lx", 0.3},
                                     {"ly", 0.3},
                                     {"lz", 0.3},
                                     {"mesh_size", 0.1},
                                     {"order", order},
                                     {"structured", 1},
                                     {"distort", distort}});
  };
  const Mesh straight = build_geometry(params(0.0));
  const Mesh distorted = build_geometry(params(0.3));
  ASSERT_EQ(straight.n_nodes(), distorted.n_nodes());
  const double moved = (straight.X - distorted.X).rowwise().norm().maxCoeff();
  EXPECT_GT(moved, 0.005);
  EXPECT_LE(moved, 0.3 * 0.1 + 1e-12);
  EXPECT_NEAR(distorted.volume(), l.prod(), 1e-12 * l.prod());
  expect_valid_geometry(distorted, box_surfaces(l, {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"}), 0.3);
}

TEST_P(Builders, Cantilever) {
  const int order = GetParam();
  const Vec3 l(1.0, 0.1, 0.05);
  for (int structured : {0, 1}) {
    const Mesh mesh = build_geometry(geometry_params(
        "cantilever",
        {{"L", l(0)}, {"b", l(1)}, {"h", l(2)}, {"mesh_size", 0.1}, {"order", order}, {"structured", structured}}));
    EXPECT_NEAR(mesh.volume(), l.prod(), 1e-12 * l.prod());
    expect_valid_geometry(mesh, box_surfaces(l, {"root", "tip", "ymin", "ymax", "zmin", "zmax"}), 1.0);
    if (structured && order == 1) {
      EXPECT_EQ(mesh.n_nodes(), 11 * 2 * 2);
    }
  }
}

// V = pi/4 (B^2 - A^2) H.
TEST_P(Builders, ThickCylinder) {
  const int order = GetParam();
  const double A = 0.5, B = 1.0, h = 0.2;
  for (int layers : {0, 2}) {
    auto p = geometry_params("thick_cylinder",
                             {{"inner_radius", A}, {"outer_radius", B}, {"mesh_size", h}, {"order", order}});
    double height = h;
    if (layers > 0) {
      height = 0.3;
      p.set("layers", layers);
      p.set("height", height);
    }
    const Mesh mesh = build_geometry(p);
    const double exact = M_PI / 4 * (B * B - A * A) * height;
    EXPECT_NEAR(mesh.volume(), exact, (order == 1 ? 2e-3 : 1e-4) * exact);
    expect_valid_geometry(mesh,
                          {cylinder("inner", A, -1), cylinder("outer", B, +1), plane("sym_x", 0, 0, -1),
                           plane("sym_y", 1, 0, -1), plane("zmin", 2, 0, -1), plane("zmax", 2, height, +1)},
                          B);
  }
}

// V = pi/6 (B^3 - A^3).
TEST_P(Builders, SphericalShell) {
  const int order = GetParam();
  const double A = 0.6, B = 1.0;
  const Mesh mesh = build_geometry(geometry_params(
      "spherical_shell", {{"inner_radius", A}, {"outer_radius", B}, {"mesh_size", 0.2}, {"order", order}}));
  const double exact = M_PI / 6 * (B * B * B - A * A * A);
  EXPECT_NEAR(mesh.volume(), exact, (order == 1 ? 2e-2 : 1e-4) * exact);
  expect_valid_geometry(mesh,
                        {sphere("inner", A, -1), sphere("outer", B, +1), plane("sym_x", 0, 0, -1),
                         plane("sym_y", 1, 0, -1), plane("sym_z", 2, 0, -1)},
                        B);
}

// Trapezoid (0,0) (48,44) (48,60) (0,44) mm has area 1440 mm^2.
TEST_P(Builders, CookMembrane) {
  const int order = GetParam();
  const double s = 1e-3, h = 0.006;
  for (int structured : {0, 1}) {
    const Mesh mesh = build_geometry(
        geometry_params("cook_membrane", {{"mesh_size", h}, {"order", order}, {"structured", structured}}));
    const double exact = 1440 * s * s * h;
    EXPECT_NEAR(mesh.volume(), exact, 1e-12 * exact);
    const Vec3 origin(0, 0, 0), top_left(0, 44 * s, 0);
    expect_valid_geometry(
        mesh,
        {plane("left", 0, 0, -1), plane("right", 0, 48 * s, +1), oblique_plane("bottom", origin, Vec3(44, -48, 0)),
         oblique_plane("top", top_left, Vec3(-16, 48, 0)), plane("zmin", 2, 0, -1), plane("zmax", 2, h, +1)},
        0.06);
    if (structured) {
      const int n = 8;  // round(48 mm / 6 mm) divisions per side, one layer
      EXPECT_EQ(mesh.faces_of("left").size(), static_cast<size_t>(2 * n));
      if (order == 1) {
        EXPECT_EQ(mesh.n_nodes(), 2 * (n + 1) * (n + 1));
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Orders, Builders, ::testing::Values(1, 2),
                         [](const ::testing::TestParamInfo<int>& info) { return "P" + std::to_string(info.param); });

TEST(Geometry, BuildsAreDeterministic) {
  const auto p = geometry_params("spherical_shell", {{"inner_radius", 0.5}, {"outer_radius", 1.0}, {"mesh_size", 0.3}});
  const Mesh first = build_geometry(p), second = build_geometry(p);
  ASSERT_EQ(first.n_nodes(), second.n_nodes());
  EXPECT_EQ(first.X, second.X);
  EXPECT_EQ(first.cells, second.cells);
  EXPECT_EQ(first.faces, second.faces);
}

TEST(Geometry, RegistryAndBadParameters) {
  for (const char* name : {"block", "thick_cylinder", "spherical_shell", "cook_membrane", "cantilever"})
    EXPECT_EQ(geometry_registry().count(name), 1u) << name;
  EXPECT_THROW(build_geometry(geometry_params("blob", {{"mesh_size", 0.1}})), InputError);
  EXPECT_THROW(build_geometry(geometry_params("block", {{"lx", 1}, {"ly", 1}, {"lz", 1}})),
               InputError);  // no mesh_size
  EXPECT_THROW(
      build_geometry(geometry_params("block", {{"lx", 1}, {"ly", 1}, {"lz", 1}, {"mesh_size", 0.5}, {"lw", 1}})),
      InputError);  // unknown key
  EXPECT_THROW(
      build_geometry(geometry_params("block", {{"lx", 1}, {"ly", 1}, {"lz", 1}, {"mesh_size", 0.5}, {"order", 3}})),
      InputError);
  EXPECT_THROW(build_geometry(
                   geometry_params("thick_cylinder", {{"inner_radius", 1}, {"outer_radius", 0.5}, {"mesh_size", 0.1}})),
               InputError);
}

}  // namespace
}  // namespace morphfem
