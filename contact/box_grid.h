#pragma once

// A uniform grid of axis-aligned boxes, the broad phase of self-contact's candidate
// search and of the lattice floor's cell location. Each box is listed in every grid
// cell [i, i+1) x [j, j+1) x [k, k+1) (times the spacing) that it touches, so the boxes
// that may contain a point are the ones listed in the point's cell, and the boxes that
// may overlap a box are the ones listed in the cells that box touches. Cells no smaller
// than a typical box keep the lists short.

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <vector>

namespace morphfem {

class BoxGrid {
 public:
  explicit BoxGrid(double spacing) : spacing_(spacing) {}  // h [m] > 0

  // Lists `id` in every cell that the box [lo, hi] touches.
  void insert(int id, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    const auto [x0, y0, z0] = cell(lo);
    const auto [x1, y1, z1] = cell(hi);
    for (long i = x0; i <= x1; ++i)
      for (long j = y0; j <= y1; ++j)
        for (long k = z0; k <= z1; ++k) cells_[{i, j, k}].push_back(id);
  }

  // The ids listed in the cell of y, in insertion order (nullptr if none).
  const std::vector<int>* at(const Eigen::Vector3d& y) const {
    const auto it = cells_.find(cell(y));
    return it == cells_.end() ? nullptr : &it->second;
  }

  // Adds to `ids` every id listed in a cell that the box [lo, hi] touches.
  void near(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::set<int>& ids) const {
    const auto [x0, y0, z0] = cell(lo);
    const auto [x1, y1, z1] = cell(hi);
    for (long i = x0; i <= x1; ++i)
      for (long j = y0; j <= y1; ++j)
        for (long k = z0; k <= z1; ++k) {
          const auto it = cells_.find({i, j, k});
          if (it != cells_.end()) ids.insert(it->second.begin(), it->second.end());
        }
  }

 private:
  using Cell = std::tuple<long, long, long>;
  // (floor(y_x / h), floor(y_y / h), floor(y_z / h)): monotone in y, so a box's
  // points fall in the cells between those of its corners lo and hi.
  Cell cell(const Eigen::Vector3d& y) const {
    return {static_cast<long>(std::floor(y[0] / spacing_)), static_cast<long>(std::floor(y[1] / spacing_)),
            static_cast<long>(std::floor(y[2] / spacing_))};
  }

  double spacing_;
  std::map<Cell, std::vector<int>> cells_;
};

}  // namespace morphfem
