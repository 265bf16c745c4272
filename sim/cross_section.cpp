#include "sim/cross_section.h"

#include <algorithm>
#include <cmath>

namespace morphfem {

Eigen::Vector3d cross_section_extents(const Mesh& mesh, const RowMatrixXd& u) {
  const double y0 = mesh.X.col(1).minCoeff(), y1 = mesh.X.col(1).maxCoeff(), mid = 0.5 * (y0 + y1);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  double ylo = 1e300, yhi = -1e300;
  for (int n = 0; n < mesh.n_nodes(); ++n) {
    const Eigen::Vector3d x = mesh.X.row(n).transpose() + u.row(n).transpose();
    ylo = std::min(ylo, x.y());
    yhi = std::max(yhi, x.y());
    if (std::abs(mesh.X(n, 1) - mid) > 0.1 * (y1 - y0)) continue;
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return {hi.x() - lo.x(), yhi - ylo, hi.z() - lo.z()};
}

}  // namespace morphfem
