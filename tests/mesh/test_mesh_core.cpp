// Mesh queries and validate_mesh on hand-made single-tetrahedron meshes.
#include <gtest/gtest.h>

#include "core/errors.h"
#include "mesh/mesh.h"

namespace morphfem {
namespace {

// Unit tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1) with a volume region "body" and
// its face opposite the origin as surface "slant".
Mesh unit_tet_p1() {
  Mesh mesh;
  mesh.order = 1;
  mesh.X.resize(4, 3);
  mesh.X << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  mesh.cells.resize(1, 4);
  mesh.cells << 0, 1, 2, 3;
  mesh.cell_region = {0};
  mesh.faces.resize(1, 3);
  mesh.faces << 1, 2, 3;
  mesh.face_region = {1};
  mesh.regions = {{"body", 3, 0}, {"slant", 2, 1}};
  return mesh;
}

// P2 unit tetrahedron mapped by x = phi(xi) = (xi + a xi^2, eta + b eta^2, zeta + c zeta^2):
// the quadratic map is represented exactly, nodes are phi(reference node).
Mesh mapped_tet_p2(double a, double b, double c) {
  const Eigen::Matrix<double, 10, 3> ref = (Eigen::Matrix<double, 10, 3>() << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5,
                                            0, 0, 0.5, 0.5, 0, 0, 0.5, 0, 0, 0, 0.5, 0.5, 0, 0.5, 0, 0.5, 0.5)
                                               .finished();
  Mesh mesh;
  mesh.order = 2;
  mesh.X.resize(10, 3);
  for (int n = 0; n < 10; ++n) {
    const Eigen::RowVector3d xi = ref.row(n);
    mesh.X.row(n) << xi(0) + a * xi(0) * xi(0), xi(1) + b * xi(1) * xi(1), xi(2) + c * xi(2) * xi(2);
  }
  mesh.cells.resize(1, 10);
  for (int k = 0; k < 10; ++k) mesh.cells(0, k) = k;
  mesh.cell_region = {0};
  mesh.faces.resize(0, 6);
  mesh.regions = {{"body", 3, 0}};
  return mesh;
}

TEST(MeshCore, VolumeAndEdgesOfUnitTet) {
  const Mesh mesh = unit_tet_p1();
  EXPECT_NEAR(mesh.volume(), 1.0 / 6.0, 1e-15);
  const auto [shortest, longest] = mesh.edge_length_range();
  EXPECT_NEAR(shortest, 1.0, 1e-15);
  EXPECT_NEAR(longest, std::sqrt(2.0), 1e-15);
  EXPECT_NO_THROW(validate_mesh(mesh, "unit"));
}

// det J = (1 + 2a xi)(1 + 2b eta)(1 + 2c zeta) is cubic; over the unit tetrahedron
// int xi^p eta^q zeta^r = p! q! r! / (p + q + r + 3)!.
TEST(MeshCore, P2VolumeIsExactForCubicJacobian) {
  const double a = 0.3, b = -0.2, c = 0.4;
  const double exact = 1.0 / 6 + 2 * (a + b + c) / 24 + 4 * (a * b + b * c + a * c) / 120 + 8 * a * b * c / 720;
  const Mesh mesh = mapped_tet_p2(a, b, c);
  EXPECT_NEAR(mesh.volume(), exact, 1e-14);
  EXPECT_NO_THROW(validate_mesh(mesh, "mapped"));
}

TEST(MeshCore, RegionLookup) {
  const Mesh mesh = unit_tet_p1();
  EXPECT_TRUE(mesh.has_region("body", 3));
  EXPECT_FALSE(mesh.has_region("body", 2));
  EXPECT_EQ(mesh.region("slant", 2).id, 1);
  EXPECT_EQ(mesh.region_names(2), std::vector<std::string>{"slant"});
  EXPECT_EQ(mesh.faces_of("slant"), std::vector<int>{0});
  EXPECT_EQ(mesh.nodes_of_surface("slant"), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(mesh.cells_of("body"), std::vector<int>{0});
  try {
    mesh.region("skin", 2);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("skin"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("slant"), std::string::npos);
  }
}

TEST(MeshCore, ValidateRejectsBadMeshes) {
  Mesh inverted = unit_tet_p1();
  inverted.cells << 0, 2, 1, 3;
  EXPECT_THROW(validate_mesh(inverted, "inv"), InputError);

  Mesh bad_index = unit_tet_p1();
  bad_index.cells(0, 3) = 7;
  EXPECT_THROW(validate_mesh(bad_index, "idx"), InputError);

  Mesh bad_region = unit_tet_p1();
  bad_region.cell_region = {1};  // a surface region
  EXPECT_THROW(validate_mesh(bad_region, "reg"), InputError);

  try {
    validate_mesh(inverted, "my_source.msh");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("my_source.msh"), std::string::npos);
  }
}

}  // namespace
}  // namespace morphfem
