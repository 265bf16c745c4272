// METIS partitioning: balanced parts, contiguous node blocks, geometry unchanged,
// deterministic; single part: a valid fill-reducing permutation.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/errors.h"
#include "mesh/geometry.h"
#include "mesh/partition.h"

namespace morphfem {
namespace {

Mesh structured_block(int order) {
  ParamSet params("geometry");
  params.set_string("type", "block");
  for (const auto& [key, value] : std::vector<std::pair<std::string, double>>{
           {"lx", 0.6}, {"ly", 0.4}, {"lz", 0.4}, {"mesh_size", 0.1}, {"order", order}, {"structured", 1}})
    params.set(key, value);
  return build_geometry(params);
}

// Face geometry independent of node numbering: the coordinates of each face's nodes
// in face order, with its region, sorted.
std::vector<std::vector<double>> face_geometry(const Mesh& mesh) {
  std::vector<std::vector<double>> faces;
  for (int f = 0; f < mesh.n_faces(); ++f) {
    std::vector<double> row = {static_cast<double>(mesh.face_region[f])};
    for (int k = 0; k < mesh.nodes_per_face(); ++k)
      for (int c = 0; c < 3; ++c) row.push_back(mesh.X(mesh.faces(f, k), c));
    faces.push_back(row);
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

std::vector<std::vector<double>> cell_geometry(const Mesh& mesh) {
  std::vector<std::vector<double>> cells;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    std::vector<double> row;
    for (int k = 0; k < mesh.nodes_per_cell(); ++k)
      for (int d = 0; d < 3; ++d) row.push_back(mesh.X(mesh.cells(c, k), d));
    cells.push_back(row);
  }
  return cells;
}

void expect_same_geometry(const Mesh& before, const Mesh& after) {
  ASSERT_EQ(before.n_nodes(), after.n_nodes());
  EXPECT_NEAR(after.volume(), before.volume(), 1e-14);
  EXPECT_EQ(cell_geometry(after), cell_geometry(before));  // cells keep their order
  EXPECT_EQ(face_geometry(after), face_geometry(before));
  EXPECT_NO_THROW(validate_mesh(after, "partitioned"));
}

// Each node lies in the block of the lowest part among the cells that use it.
void expect_contiguous_owned_nodes(const Mesh& mesh, const Partition& partition) {
  ASSERT_EQ(static_cast<int>(partition.node_begin.size()), partition.n_parts + 1);
  EXPECT_EQ(partition.node_begin.front(), 0);
  EXPECT_EQ(partition.node_begin.back(), mesh.n_nodes());
  EXPECT_TRUE(std::is_sorted(partition.node_begin.begin(), partition.node_begin.end()));
  std::vector<int> lowest_part(mesh.n_nodes(), partition.n_parts);
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (int k = 0; k < mesh.nodes_per_cell(); ++k)
      lowest_part[mesh.cells(c, k)] = std::min(lowest_part[mesh.cells(c, k)], partition.cell_part[c]);
  for (int p = 0; p < partition.n_parts; ++p)
    for (int n = partition.node_begin[p]; n < partition.node_begin[p + 1]; ++n) ASSERT_EQ(lowest_part[n], p) << n;
}

TEST(Partition, BalancedContiguousAndGeometryPreserving) {
  for (int order : {1, 2})
    for (int n_parts : {2, 3, 4}) {
      const Mesh original = structured_block(order);
      Mesh mesh = original;
      const Partition partition = partition_mesh(mesh, n_parts);
      EXPECT_EQ(partition.n_parts, n_parts);
      ASSERT_EQ(static_cast<int>(partition.cell_part.size()), mesh.n_cells());
      std::vector<int> cells_per_part(n_parts, 0);
      for (int p : partition.cell_part) {
        ASSERT_GE(p, 0);
        ASSERT_LT(p, n_parts);
        ++cells_per_part[p];
      }
      const double ideal = static_cast<double>(mesh.n_cells()) / n_parts;
      for (int count : cells_per_part) {
        EXPECT_GT(count, 0.9 * ideal);
        EXPECT_LT(count, 1.1 * ideal);
      }
      expect_contiguous_owned_nodes(mesh, partition);
      expect_same_geometry(original, mesh);
    }
}

TEST(Partition, SinglePartReordersNodes) {
  for (int order : {1, 2}) {
    const Mesh original = structured_block(order);
    Mesh mesh = original;
    const Partition partition = partition_mesh(mesh, 1);
    EXPECT_EQ(partition.node_begin, (std::vector<int>{0, mesh.n_nodes()}));
    EXPECT_EQ(partition.cell_part, std::vector<int>(mesh.n_cells(), 0));
    EXPECT_NE(mesh.cells, original.cells);  // actually permuted
    expect_same_geometry(original, mesh);
  }
}

TEST(Partition, Deterministic) {
  Mesh first = structured_block(1), second = structured_block(1);
  const Partition a = partition_mesh(first, 3), b = partition_mesh(second, 3);
  EXPECT_EQ(a.cell_part, b.cell_part);
  EXPECT_EQ(a.node_begin, b.node_begin);
  EXPECT_EQ(first.X, second.X);
  EXPECT_EQ(first.cells, second.cells);
}

TEST(Partition, RejectsBadPartCounts) {
  Mesh mesh = structured_block(1);
  EXPECT_THROW(partition_mesh(mesh, 0), InputError);
  EXPECT_THROW(partition_mesh(mesh, mesh.n_cells() + 1), InputError);
}

}  // namespace
}  // namespace morphfem
