// A one-cell mesh for element tests: one tetrahedron about 1 cm across (vertices of a
// skewed unit tet scaled by 0.01 m), region "body". For order 2 the mid-edge nodes are
// moved off the edge midpoints by up to 0.03 (x 0.01 m), seeded: a curved cell.
#pragma once
#include <random>

#include "mesh/mesh.h"

namespace morphfem::testing {

inline Mesh one_tet(int order, unsigned seed) {
  Mesh m;
  m.order = order;
  const int n = order == 1 ? 4 : 10;
  m.X.resize(n, 3);
  m.X.row(0) << 0, 0, 0;
  m.X.row(1) << 1, 0.1, 0;
  m.X.row(2) << 0.2, 0.9, 0.1;
  m.X.row(3) << 0.1, 0.2, 1.1;
  if (order == 2) {
    const int edge[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> d(-0.03, 0.03);
    for (int e = 0; e < 6; ++e)
      for (int i = 0; i < 3; ++i) m.X(4 + e, i) = 0.5 * (m.X(edge[e][0], i) + m.X(edge[e][1], i)) + d(rng);
  }
  m.X *= 0.01;  // 1 cm
  m.cells.resize(1, n);
  for (int a = 0; a < n; ++a) m.cells(0, a) = a;
  m.cell_region = {0};
  m.regions = {Region{"body", 3, 0}};
  return m;
}

}  // namespace morphfem::testing
