// Measures of a deformed robot body used by the morphing studies and calibration.
#pragma once
#include <Eigen/Core>

#include "mesh/mesh.h"

namespace morphfem {

// Extents of the deformed mid-length cross-section [m]: x (width), y (length of the
// whole body), z (thickness). The cross-section is the nodes within 10 % of the body
// length of its middle (reference y), away from the sealed ends that stay flat.
Eigen::Vector3d cross_section_extents(const Mesh& mesh, const RowMatrixXd& u);

}  // namespace morphfem
