// Where the program finds its resources: the example scenes, the plot scripts and
// the public data beside the repository.
#pragma once
#include <string>

namespace morphfem {

// The directory holding examples/ and scripts/ (the source tree the program was
// built from).
std::string resource_dir();
// The public data (voxel-study results, tensile curves): RESOURCE_DIR/../shared/data.
std::string shared_data_dir();

}  // namespace morphfem
