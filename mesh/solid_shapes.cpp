// Solid shapes for contact verification (see solid_shapes.h): a refined hemisphere
// (Hertz contact) and a solid cylinder or tube (rolling).
#include "mesh/solid_shapes.h"

#include <gmsh.h>

#include <functional>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "core/errors.h"
#include "mesh/geometry.h"

namespace morphfem {

namespace {

constexpr double kHuge = std::numeric_limits<double>::max();

}  // namespace

Mesh build_hemisphere(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "radius", "contact_size", "refine_radius", "quarter"});
  const double mesh_size = params.number_in("mesh_size", 1e-12, kHuge);
  const int order = params.integer_in("order", 1, 2, 1);
  const double radius = params.number_in("radius", 1e-12, kHuge);
  const double contact_size = params.number_in("contact_size", 1e-12, mesh_size, mesh_size);
  const double refine_radius = params.number_in("refine_radius", 0.0, radius, radius / 4);
  const bool quarter = params.integer_in("quarter", 0, 1, 1) == 1;

  ScopedGmshModel model("morphfem_hemisphere");
  namespace occ = gmsh::model::occ;
  // Lower half-ball (quarter: x, y >= 0) = ball intersected with a box below z = 0.
  const double reach = 1.5 * radius;
  const int box = quarter ? occ::addBox(0, 0, -reach, reach, reach, reach)
                          : occ::addBox(-reach, -reach, -reach, 2 * reach, 2 * reach, reach);
  gmsh::vectorpair half;
  std::vector<gmsh::vectorpair> unused_map;
  occ::intersect({{3, occ::addSphere(0, 0, 0, radius)}}, {{3, box}}, half, unused_map);
  occ::synchronize();

  // Size field: h = contact_size within r <= refine_radius of the pole (0, 0, -R),
  // growing linearly (gradient 1/2) to mesh_size; r [m] the distance from the pole.
  if (contact_size < mesh_size) {
    std::ostringstream distance;
    distance << std::setprecision(17) << "Sqrt(x * x + y * y + (z + " << radius << ") * (z + " << radius << "))";
    const int from_pole = gmsh::model::mesh::field::add("MathEval");
    gmsh::model::mesh::field::setString(from_pole, "F", distance.str());
    const int size = gmsh::model::mesh::field::add("Threshold");
    gmsh::model::mesh::field::setNumber(size, "InField", from_pole);
    gmsh::model::mesh::field::setNumber(size, "SizeMin", contact_size);
    gmsh::model::mesh::field::setNumber(size, "SizeMax", mesh_size);
    gmsh::model::mesh::field::setNumber(size, "DistMin", refine_radius);
    gmsh::model::mesh::field::setNumber(size, "DistMax", refine_radius + 2 * (mesh_size - contact_size));
    gmsh::model::mesh::field::setAsBackgroundMesh(size);
  }
  generate_tet_mesh(mesh_size, order,
                    params.where("mesh_size"));  // a background size field can only refine below mesh_size

  const double tol = 1e-6 * radius;
  std::vector<SurfaceRule> rules;
  if (quarter) {
    rules.push_back({"sym_x", [=](const NodeBox& b) { return b.max.x() < tol; }});
    rules.push_back({"sym_y", [=](const NodeBox& b) { return b.max.y() < tol; }});
  }
  rules.push_back({"flat", [=](const NodeBox& b) { return b.min.z() > -tol; }});
  rules.push_back({"sphere", [](const NodeBox&) { return true; }});
  add_physical_groups(rules);
  return mesh_from_current_gmsh_model(geometry_source(params, "hemisphere"));
}

Mesh build_solid_cylinder(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "radius", "length", "inner_radius"});
  const double mesh_size = params.number_in("mesh_size", 1e-12, kHuge);
  const int order = params.integer_in("order", 1, 2, 1);
  const double radius = params.number_in("radius", 1e-12, kHuge);
  const double length = params.number_in("length", 1e-12, kHuge);
  const double inner_radius = params.number_in("inner_radius", 0.0, radius * (1 - 1e-6), 0.0);

  ScopedGmshModel model("morphfem_solid_cylinder");
  namespace occ = gmsh::model::occ;
  const int outer = occ::addCylinder(0, 0, 0, 0, length, 0, radius);
  if (inner_radius > 0) {
    // The bore sticks out at both ends so the cut leaves no coincident faces.
    gmsh::vectorpair tube;
    std::vector<gmsh::vectorpair> unused_map;
    occ::cut({{3, outer}}, {{3, occ::addCylinder(0, -length, 0, 0, 3 * length, 0, inner_radius)}}, tube, unused_map);
  }
  occ::synchronize();
  generate_tet_mesh(mesh_size, order,
                    params.where("mesh_size"));  // a background size field can only refine below mesh_size

  const double tol = 1e-6 * std::max(radius, length), r_mid = 0.5 * (radius + inner_radius);
  std::vector<SurfaceRule> rules{{"ymin", [=](const NodeBox& b) { return b.max.y() < tol; }},
                                 {"ymax", [=](const NodeBox& b) { return b.min.y() > length - tol; }}};
  if (inner_radius > 0)
    rules.push_back({"inner", [=](const NodeBox& b) { return std::max(b.max.x(), b.max.z()) < r_mid; }});
  rules.push_back({"outer", [](const NodeBox&) { return true; }});
  add_physical_groups(rules);
  return mesh_from_current_gmsh_model(geometry_source(params, "solid_cylinder"));
}

}  // namespace morphfem
