// .msh import/export: round trips, a gmsh-written file, node-order and orientation
// fixes of imported elements, and bad files rejected with the file named.
#include <gmsh.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>

#include "core/errors.h"
#include "mesh/geometry.h"

namespace morphfem {
namespace {

namespace fs = std::filesystem;

std::string temp_path(const std::string& name) {
  return (fs::temp_directory_path() / ("morphfem_test_mesh_" + std::to_string(::getpid()) + "_" + name)).string();
}

ParamSet geometry_params(const std::string& type, const std::vector<std::pair<std::string, double>>& values) {
  ParamSet params("geometry");
  params.set_string("type", type);
  for (const auto& [key, value] : values) params.set(key, value);
  return params;
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  EXPECT_EQ(a.order, b.order);
  ASSERT_EQ(a.n_nodes(), b.n_nodes());
  ASSERT_EQ(a.n_cells(), b.n_cells());
  ASSERT_EQ(a.n_faces(), b.n_faces());
  EXPECT_LT((a.X - b.X).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_EQ(a.cells, b.cells);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.cell_region, b.cell_region);
  EXPECT_EQ(a.face_region, b.face_region);
  ASSERT_EQ(a.regions.size(), b.regions.size());
  for (size_t r = 0; r < a.regions.size(); ++r) {
    EXPECT_EQ(a.regions[r].name, b.regions[r].name);
    EXPECT_EQ(a.regions[r].dim, b.regions[r].dim);
    EXPECT_EQ(a.regions[r].id, b.regions[r].id);
  }
  EXPECT_NEAR(a.volume(), b.volume(), 1e-14 * a.volume());
}

std::string error_message(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

TEST(MshIo, WriteReadRoundTripP1AndP2) {
  for (int order : {1, 2}) {
    const Mesh built = build_geometry(geometry_params(
        "thick_cylinder", {{"inner_radius", 0.5}, {"outer_radius", 1.0}, {"mesh_size", 0.25}, {"order", order}}));
    const std::string path = temp_path("roundtrip_p" + std::to_string(order) + ".msh");
    write_msh(built, path);
    const Mesh read = read_msh(path);
    std::remove(path.c_str());
    expect_same_mesh(built, read);
  }
}

// A mesh written by gmsh itself from a CAD model (geometric entities, physical groups
// set through the API) reads back as the same Mesh the extraction gives in memory.
TEST(MshIo, ReadsFileWrittenByGmsh) {
  initialize_gmsh();
  const std::string path = temp_path("gmsh_box.msh");
  gmsh::model::add("test_gmsh_box");
  gmsh::model::occ::addBox(0, 0, 0, 0.2, 0.1, 0.1);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.05);
  gmsh::option::setNumber("Mesh.ElementOrder", 2);
  gmsh::model::mesh::generate(3);
  gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {1}), "rubber");
  gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, {1, 2}), "x_ends");
  gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, {1}), "x_start");  // face in two groups
  const Mesh in_memory = mesh_from_current_gmsh_model("in memory");
  gmsh::option::setNumber("Mesh.SaveAll", 0);
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::write(path);
  gmsh::model::remove();

  const Mesh read = read_msh(path);
  std::remove(path.c_str());
  EXPECT_EQ(read.order, 2);
  EXPECT_EQ(read.region_names(3), std::vector<std::string>{"rubber"});
  EXPECT_EQ(read.faces_of("x_ends").size(), 2 * read.faces_of("x_start").size());
  EXPECT_NEAR(read.volume(), 0.2 * 0.1 * 0.1, 1e-15);
  expect_same_mesh(in_memory, read);
}

// Elements given in a discrete model with a negatively oriented tetrahedron and a
// triangle facing inward come out positive, outward and in VTK node order.
TEST(MshIo, ImportFixesOrientationAndNodeOrder) {
  initialize_gmsh();
  gmsh::model::add("test_flipped");
  const int volume = gmsh::model::addDiscreteEntity(3);
  const int surface = gmsh::model::addDiscreteEntity(2);
  // Vertices 1..4 of the unit tetrahedron; 5..10 mid-nodes in gmsh order for the
  // element (1, 3, 2, 4): edges (1,3) (3,2) (2,1) (4,1) (4,2) (4,3) are nodes 5 6 7 8 10 9.
  const std::vector<double> coords = {0, 0,   0, 1,   0,   0, 0,   1, 0, 0, 0, 1,  // vertices
                                      0, 0.5, 0, 0.5, 0.5, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0.5, 0.5, 0.5, 0, 0.5};
  std::vector<size_t> tags(10);
  std::iota(tags.begin(), tags.end(), size_t{1});
  gmsh::model::mesh::addNodes(3, volume, tags, coords);
  gmsh::model::mesh::addElementsByType(volume, 11, {1}, {1, 3, 2, 4, 5, 6, 7, 8, 10, 9});
  // The face z = 0 listed counter-clockwise from +z, i.e. pointing into the solid.
  gmsh::model::mesh::addElementsByType(surface, 9, {2}, {1, 2, 3, 7, 6, 5});
  gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {volume}), "body");
  gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, {surface}), "base");
  const Mesh mesh = mesh_from_current_gmsh_model("flipped");
  gmsh::model::remove();

  ASSERT_EQ(mesh.n_cells(), 1);
  EXPECT_NEAR(mesh.volume(), 1.0 / 6.0, 1e-15);
  static constexpr int kEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  for (int e = 0; e < 6; ++e) {
    const Eigen::RowVector3d mid =
        0.5 * (mesh.X.row(mesh.cells(0, kEdges[e][0])) + mesh.X.row(mesh.cells(0, kEdges[e][1])));
    EXPECT_LT((mesh.X.row(mesh.cells(0, 4 + e)) - mid).norm(), 1e-15) << "edge " << e;
  }
  ASSERT_EQ(mesh.n_faces(), 1);
  const Eigen::RowVector3d x0 = mesh.X.row(mesh.faces(0, 0));
  const Eigen::RowVector3d e1 = mesh.X.row(mesh.faces(0, 1)) - x0, e2 = mesh.X.row(mesh.faces(0, 2)) - x0;
  const Eigen::RowVector3d normal = e1.cross(e2);
  EXPECT_LT(normal.z(), 0.0);  // out of the solid, which lies at z > 0
  static constexpr int kTriangleEdges[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  for (int e = 0; e < 3; ++e) {
    const Eigen::RowVector3d mid =
        0.5 * (mesh.X.row(mesh.faces(0, kTriangleEdges[e][0])) + mesh.X.row(mesh.faces(0, kTriangleEdges[e][1])));
    EXPECT_LT((mesh.X.row(mesh.faces(0, 3 + e)) - mid).norm(), 1e-15) << "face edge " << e;
  }
}

TEST(MshIo, MissingFileIsNamed) {
  const std::string path = temp_path("does_not_exist.msh");
  EXPECT_NE(error_message([&] { read_msh(path); }).find(path), std::string::npos);
}

TEST(MshIo, NotAMshFileIsNamed) {
  const std::string path = temp_path("garbage.msh");
  std::ofstream(path) << "hello\n";
  const std::string message = error_message([&] { read_msh(path); });
  std::remove(path.c_str());
  EXPECT_NE(message.find(path), std::string::npos) << message;
}

TEST(MshIo, NoPhysicalGroupsIsNamed) {
  initialize_gmsh();
  const std::string path = temp_path("no_groups.msh");
  gmsh::model::add("test_no_groups");
  gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.5);
  gmsh::option::setNumber("Mesh.ElementOrder", 1);
  gmsh::model::mesh::generate(3);
  gmsh::option::setNumber("Mesh.SaveAll", 1);
  gmsh::write(path);
  gmsh::option::setNumber("Mesh.SaveAll", 0);
  gmsh::model::remove();
  const std::string message = error_message([&] { read_msh(path); });
  std::remove(path.c_str());
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("physical"), std::string::npos) << message;
}

TEST(MshIo, MixedOrdersAreRejected) {
  initialize_gmsh();
  const std::string path = temp_path("mixed.msh");
  gmsh::model::add("test_mixed");
  // Two volumes (gmsh 4.8 cannot read back two tetrahedron orders in one entity).
  const int volume = gmsh::model::addDiscreteEntity(3);
  const int other_volume = gmsh::model::addDiscreteEntity(3);
  const std::vector<double> coords = {0,   0, 0, 1,   0,   0, 0, 1,   0, 0, 0, 1,   1,   1, 1,  // 5 vertices
                                      0.5, 0, 0, 0.5, 0.5, 0, 0, 0.5, 0, 0, 0, 0.5, 0.5, 0, 0.5, 0, 0.5, 0.5};
  std::vector<size_t> tags(11);
  std::iota(tags.begin(), tags.end(), size_t{1});
  gmsh::model::mesh::addNodes(3, volume, tags, coords);
  gmsh::model::mesh::addElementsByType(volume, 11, {1}, {1, 2, 3, 4, 6, 7, 8, 9, 11, 10});
  gmsh::model::mesh::addElementsByType(other_volume, 4, {2}, {2, 3, 4, 5});
  gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, {volume, other_volume}), "body");
  gmsh::write(path);
  gmsh::model::remove();
  const std::string message = error_message([&] { read_msh(path); });
  std::remove(path.c_str());
  EXPECT_NE(message.find(path), std::string::npos) << message;
  EXPECT_NE(message.find("mixes"), std::string::npos) << message;
}

}  // namespace
}  // namespace morphfem
