// A quarter tube (geometry thick_cylinder) held on its symmetry planes and between
// its end planes: a plane-strain chamber wall whose inner surface a scene inflates.
#pragma once
#include <string>

namespace morphfem {

// The scene's geometry, material and boundary keys; `geometry` holds the
// thick_cylinder's sizes ("inner_radius: 0.005, outer_radius: 0.01, ..."),
// `material` the body's law ("{model: dragon_skin_30}").
inline std::string quarter_tube(const std::string& geometry, const std::string& material) {
  return "geometry: {type: thick_cylinder, " + geometry + "}\nmaterials:\n  body: " + material + R"(
boundary:
  - {surface: sym_x, fix: [x]}
  - {surface: sym_y, fix: [y]}
  - {surface: zmin, fix: [z]}
  - {surface: zmax, fix: [z]}
)";
}

}  // namespace morphfem
