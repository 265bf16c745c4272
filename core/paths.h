// Where the program finds its resources: the example scenes and schedules
// (examples/), the plot scripts (scripts/) and the public data (voxel-study results,
// tensile curves).
//
// The first of these that exists:
//   1. $MORPHFEM_DATA_DIR (a directory holding examples/ and scripts/, and data/);
//   2. the installed copy beside the program: EXE_DIR/../share/morphfem
//      (`cmake --install build --prefix PREFIX` puts the program in PREFIX/bin and
//      the resources in PREFIX/share/morphfem);
//   3. the source tree the program was built from.
#pragma once
#include <string>

namespace morphfem {

// The directory holding examples/ and scripts/.
std::string resource_dir();
// The public data: RESOURCE_DIR/data if it exists (an installed copy), else
// RESOURCE_DIR/../shared/data (beside the source tree).
std::string shared_data_dir();

}  // namespace morphfem
