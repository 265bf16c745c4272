// Geometry builders (gmsh OpenCASCADE kernel), registered by name in geometry_registry().
//
//  block            lx, ly, lz [m], structured (0/1), distort (0..0.3)
//                   surfaces xmin xmax ymin ymax zmin zmax, volume body; corner at origin
//  thick_cylinder   inner_radius, outer_radius, height (default mesh_size) [m], layers
//                   quarter annulus x, y >= 0 extruded along z;
//                   surfaces inner outer sym_x (x = 0) sym_y (y = 0) zmin zmax, volume body
//  spherical_shell  inner_radius, outer_radius [m]; octant x, y, z >= 0;
//                   surfaces inner outer sym_x sym_y sym_z, volume body
//  cook_membrane    scale (m per drawing unit, default 1e-3), thickness (default mesh_size),
//                   structured; trapezoid (0,0) (48,44) (48,60) (0,44) extruded along z;
//                   surfaces left right top bottom zmin zmax, volume body
//  cantilever       L (x), b (y), h (z) [m], structured; root at x = 0;
//                   surfaces root tip ymin ymax zmin zmax, volume body
// Every builder also takes mesh_size [m] (required) and order (1 or 2, default 1).
#include "mesh/geometry.h"

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>

#include "core/errors.h"
#include "core/strings.h"
#include "mesh/robot.h"
#include "mesh/solid_shapes.h"

namespace morphfem {

NodeBox node_box(int dim, int tag) {
  std::vector<std::size_t> tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(tags, coords, parametric, dim, tag, true, false);
  NodeBox box;
  for (std::size_t k = 0; k < tags.size(); ++k) {
    const Eigen::Vector3d x(coords[3 * k], coords[3 * k + 1], coords[3 * k + 2]);
    box.min = box.min.cwiseMin(x);
    box.max = box.max.cwiseMax(x);
  }
  return box;
}

void add_physical_groups(const std::vector<SurfaceRule>& rules) {
  gmsh::vectorpair volumes, surfaces;
  gmsh::model::getEntities(volumes, 3);
  gmsh::model::getEntities(surfaces, 2);
  std::vector<int> volume_tags;
  for (const auto& [dim, tag] : volumes) volume_tags.push_back(tag);
  gmsh::model::setPhysicalName(3, gmsh::model::addPhysicalGroup(3, volume_tags), "body");

  std::vector<std::vector<int>> members(rules.size());
  for (const auto& [dim, tag] : surfaces) {
    const NodeBox box = node_box(dim, tag);
    auto rule = std::find_if(rules.begin(), rules.end(), [&](const SurfaceRule& r) { return r.matches(box); });
    if (rule == rules.end()) throw std::logic_error("geometry: a boundary surface matches no naming rule");
    members[rule - rules.begin()].push_back(tag);
  }
  for (std::size_t r = 0; r < rules.size(); ++r) {
    if (members[r].empty()) throw std::logic_error("geometry: no boundary surface named " + rules[r].name);
    gmsh::model::setPhysicalName(2, gmsh::model::addPhysicalGroup(2, members[r]), rules[r].name);
  }
}

namespace {

constexpr double kHuge = std::numeric_limits<double>::max();

struct CommonParams {
  double mesh_size = 0.0;  // target edge length [m]
  int order = 1;
  std::string where;  // the mesh_size key's location, for mesher errors
};

CommonParams common_params(const ParamSet& params) {
  CommonParams common;
  common.mesh_size = params.number_in("mesh_size", 1e-12, kHuge);
  common.order = params.integer_in("order", 1, 2, 1);
  common.where = params.where("mesh_size");
  return common;
}

double positive_length(const ParamSet& params, const std::string& key) { return params.number_in(key, 1e-12, kHuge); }
double positive_length(const ParamSet& params, const std::string& key, double fallback) {
  return params.number_in(key, 1e-12, kHuge, fallback);
}

// Number of element divisions along a length l: round(l / h), at least 1.
int divisions(double length, double mesh_size) {
  return std::max(1, static_cast<int>(std::lround(length / mesh_size)));
}

// Rules naming the planes x = 0, x = lx, y = 0, y = ly, z = 0, z = lz of a box.
std::vector<SurfaceRule> box_face_rules(const Eigen::Vector3d& lengths, const std::array<std::string, 6>& names) {
  const double tol = 1e-6 * lengths.maxCoeff();
  std::vector<SurfaceRule> rules;
  for (int axis = 0; axis < 3; ++axis) {
    const double l = lengths(axis);
    rules.push_back({names[2 * axis], [=](const NodeBox& b) { return b.max(axis) < tol; }});
    rules.push_back({names[2 * axis + 1], [=](const NodeBox& b) { return b.min(axis) > l - tol; }});
  }
  return rules;
}

// Transfinite (structured) box: n_axis + 1 nodes on every curve along that axis; each
// hexahedral cell is split into tetrahedra.
void make_box_transfinite(const Eigen::Vector3d& lengths, double mesh_size) {
  gmsh::vectorpair curves, surfaces, volumes;
  gmsh::model::getEntities(curves, 1);
  gmsh::model::getEntities(surfaces, 2);
  gmsh::model::getEntities(volumes, 3);
  for (const auto& [dim, tag] : curves) {
    double x0, y0, z0, x1, y1, z1;
    gmsh::model::getBoundingBox(dim, tag, x0, y0, z0, x1, y1, z1);
    const Eigen::Vector3d extent(x1 - x0, y1 - y0, z1 - z0);
    Eigen::Index axis;
    extent.maxCoeff(&axis);
    gmsh::model::mesh::setTransfiniteCurve(tag, divisions(lengths(axis), mesh_size) + 1);
  }
  for (const auto& [dim, tag] : surfaces) gmsh::model::mesh::setTransfiniteSurface(tag);
  for (const auto& [dim, tag] : volumes) gmsh::model::mesh::setTransfiniteVolume(tag);
}

// Axis-aligned box [0, lx] x [0, ly] x [0, lz] with surfaces named (xmin, xmax, ymin,
// ymax, zmin, zmax) = `names` and volume "body".
Mesh box_mesh(const Eigen::Vector3d& lengths, const CommonParams& common, bool structured,
              const std::array<std::string, 6>& names, const std::string& source) {
  ScopedGmshModel model("morphfem_box");
  gmsh::model::occ::addBox(0, 0, 0, lengths(0), lengths(1), lengths(2));
  gmsh::model::occ::synchronize();
  if (structured) make_box_transfinite(lengths, common.mesh_size);
  generate_tet_mesh(common.mesh_size, common.order, common.where);
  add_physical_groups(box_face_rules(lengths, names));
  return mesh_from_current_gmsh_model(source);
}

// Uniform number in [0, 1) from a 32-bit engine (same sequence on every platform).
double unit_random(std::mt19937& engine) { return (static_cast<double>(engine()) + 0.5) / 4294967296.0; }

// A random vector of length <= radius, uniform in the ball (rejection from the cube).
Eigen::Vector3d random_in_ball(std::mt19937& engine, double radius) {
  for (;;) {
    const Eigen::Vector3d v(2 * unit_random(engine) - 1, 2 * unit_random(engine) - 1, 2 * unit_random(engine) - 1);
    if (v.squaredNorm() <= 1.0) return radius * v;
  }
}

double vertex_volume(const RowMatrixXd& X, const RowMatrixXi& cells, int c) {
  const Eigen::RowVector3d x0 = X.row(cells(c, 0));
  const Eigen::RowVector3d e1 = X.row(cells(c, 1)) - x0, e2 = X.row(cells(c, 2)) - x0, e3 = X.row(cells(c, 3)) - x0;
  return e1.dot(e2.cross(e3)) / 6.0;
}

// Mid-node of edge (i, j) of a VTK tetrahedron at index 4 + e.
constexpr int kTetEdges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};

// Places every P2 mid-node at the midpoint of its (straight) edge.
void straighten_mid_nodes(Mesh& mesh) {
  if (mesh.order != 2) return;
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (int e = 0; e < 6; ++e)
      mesh.X.row(mesh.cells(c, 4 + e)) =
          0.5 * (mesh.X.row(mesh.cells(c, kTetEdges[e][0])) + mesh.X.row(mesh.cells(c, kTetEdges[e][1])));
}

// Moves each interior vertex (on no boundary face) by a random vector of length
// <= amplitude [m] (fixed seed). Vertices of cells that would shrink below a quarter
// of their volume get their move halved until none does, so no cell inverts.
void distort_interior_vertices(Mesh& mesh, double amplitude) {
  std::vector<bool> on_boundary(mesh.n_nodes(), false);
  for (int f = 0; f < mesh.n_faces(); ++f)
    for (int k = 0; k < mesh.faces.cols(); ++k) on_boundary[mesh.faces(f, k)] = true;
  std::vector<bool> is_vertex(mesh.n_nodes(), false);
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (int k = 0; k < 4; ++k) is_vertex[mesh.cells(c, k)] = true;

  std::mt19937 engine(20240611u);
  RowMatrixXd move = RowMatrixXd::Zero(mesh.n_nodes(), 3);
  for (int n = 0; n < mesh.n_nodes(); ++n)
    if (is_vertex[n] && !on_boundary[n]) move.row(n) = random_in_ball(engine, amplitude).transpose();

  const RowMatrixXd X0 = mesh.X;
  std::vector<double> volume0(mesh.n_cells());
  for (int c = 0; c < mesh.n_cells(); ++c) volume0[c] = vertex_volume(X0, mesh.cells, c);
  for (int attempt = 0; attempt < 60; ++attempt) {
    mesh.X = X0 + move;
    bool all_good = true;
    for (int c = 0; c < mesh.n_cells(); ++c) {
      if (vertex_volume(mesh.X, mesh.cells, c) >= 0.25 * volume0[c]) continue;
      all_good = false;
      for (int k = 0; k < 4; ++k) move.row(mesh.cells(c, k)) *= 0.5;
    }
    if (all_good) break;
  }
  straighten_mid_nodes(mesh);
}

Mesh build_block(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "lx", "ly", "lz", "structured", "distort"});
  const CommonParams common = common_params(params);
  const Eigen::Vector3d lengths(positive_length(params, "lx"), positive_length(params, "ly"),
                                positive_length(params, "lz"));
  const bool structured = params.integer_in("structured", 0, 1, 0) == 1;
  const double distort = params.number_in("distort", 0.0, 0.3, 0.0);
  Mesh mesh = box_mesh(lengths, common, structured, {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"},
                       geometry_source(params, "block"));
  if (distort > 0.0) {
    distort_interior_vertices(mesh, distort * common.mesh_size);
    validate_mesh(mesh, "geometry block (distorted)");
  }
  return mesh;
}

Mesh build_cantilever(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "L", "b", "h", "structured"});
  const CommonParams common = common_params(params);
  const Eigen::Vector3d lengths(positive_length(params, "L"), positive_length(params, "b"),
                                positive_length(params, "h"));
  const bool structured = params.integer_in("structured", 0, 1, 0) == 1;
  return box_mesh(lengths, common, structured, {"root", "tip", "ymin", "ymax", "zmin", "zmax"},
                  geometry_source(params, "cantilever"));
}

// Extrudes planar surface `surface` (in z = 0) by `height` along z: `layers` structured
// layers of split prisms if layers > 0, else a plain volume meshed unstructured.
void extrude_along_z(int surface, double height, int layers) {
  gmsh::vectorpair extruded;
  std::vector<int> num_elements;
  if (layers > 0) num_elements.push_back(layers);
  gmsh::model::occ::extrude({{2, surface}}, 0, 0, height, extruded, num_elements);
}

Mesh build_thick_cylinder(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "inner_radius", "outer_radius", "height", "layers"});
  const CommonParams common = common_params(params);
  const double r_in = positive_length(params, "inner_radius");
  const double r_out = params.number_in("outer_radius", r_in * (1 + 1e-9), kHuge);
  const double height = positive_length(params, "height", common.mesh_size);
  const int layers = params.integer_in("layers", 1, 100000, 0);

  ScopedGmshModel model("morphfem_thick_cylinder");
  namespace occ = gmsh::model::occ;
  const int centre = occ::addPoint(0, 0, 0);
  const int p_in_x = occ::addPoint(r_in, 0, 0), p_out_x = occ::addPoint(r_out, 0, 0);
  const int p_out_y = occ::addPoint(0, r_out, 0), p_in_y = occ::addPoint(0, r_in, 0);
  const int loop = occ::addCurveLoop({occ::addLine(p_in_x, p_out_x), occ::addCircleArc(p_out_x, centre, p_out_y),
                                      occ::addLine(p_out_y, p_in_y), occ::addCircleArc(p_in_y, centre, p_in_x)});
  const int annulus = occ::addPlaneSurface({loop});
  occ::remove({{0, centre}});
  extrude_along_z(annulus, height, layers);
  occ::synchronize();
  generate_tet_mesh(common.mesh_size, common.order, common.where);

  const double tol = 1e-6 * r_out, r_mid = 0.5 * (r_in + r_out);
  add_physical_groups({{"zmin", [=](const NodeBox& b) { return b.max.z() < tol; }},
                       {"zmax", [=](const NodeBox& b) { return b.min.z() > height - tol; }},
                       {"sym_x", [=](const NodeBox& b) { return b.max.x() < tol; }},
                       {"sym_y", [=](const NodeBox& b) { return b.max.y() < tol; }},
                       {"inner", [=](const NodeBox& b) { return std::max(b.max.x(), b.max.y()) < r_mid; }},
                       {"outer", [=](const NodeBox& b) { return true; }}});
  return mesh_from_current_gmsh_model(geometry_source(params, "thick_cylinder"));
}

Mesh build_spherical_shell(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "inner_radius", "outer_radius"});
  const CommonParams common = common_params(params);
  const double r_in = positive_length(params, "inner_radius");
  const double r_out = params.number_in("outer_radius", r_in * (1 + 1e-9), kHuge);

  ScopedGmshModel model("morphfem_spherical_shell");
  namespace occ = gmsh::model::occ;
  // Octant x, y, z >= 0 of (ball r_out minus ball r_in).
  gmsh::vectorpair shell, octant;
  std::vector<gmsh::vectorpair> unused_map;
  occ::cut({{3, occ::addSphere(0, 0, 0, r_out)}}, {{3, occ::addSphere(0, 0, 0, r_in)}}, shell, unused_map);
  const double box = 1.5 * r_out;
  occ::intersect(shell, {{3, occ::addBox(0, 0, 0, box, box, box)}}, octant, unused_map);
  occ::synchronize();
  generate_tet_mesh(common.mesh_size, common.order, common.where);

  const double tol = 1e-6 * r_out, r_mid = 0.5 * (r_in + r_out);
  add_physical_groups({{"sym_x", [=](const NodeBox& b) { return b.max.x() < tol; }},
                       {"sym_y", [=](const NodeBox& b) { return b.max.y() < tol; }},
                       {"sym_z", [=](const NodeBox& b) { return b.max.z() < tol; }},
                       {"inner", [=](const NodeBox& b) { return b.max.maxCoeff() < r_mid; }},
                       {"outer", [=](const NodeBox& b) { return true; }}});
  return mesh_from_current_gmsh_model(geometry_source(params, "spherical_shell"));
}

Mesh build_cook_membrane(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "scale", "thickness", "structured"});
  const CommonParams common = common_params(params);
  const double scale = positive_length(params, "scale", 1e-3);  // m per drawing unit (mm)
  const double thickness = positive_length(params, "thickness", common.mesh_size);
  const bool structured = params.integer_in("structured", 0, 1, 0) == 1;

  ScopedGmshModel model("morphfem_cook_membrane");
  namespace occ = gmsh::model::occ;
  const int a = occ::addPoint(0, 0, 0), b = occ::addPoint(48 * scale, 44 * scale, 0);
  const int c = occ::addPoint(48 * scale, 60 * scale, 0), d = occ::addPoint(0, 44 * scale, 0);
  const std::vector<int> edges = {occ::addLine(a, b), occ::addLine(b, c), occ::addLine(c, d), occ::addLine(d, a)};
  const int trapezoid = occ::addPlaneSurface({occ::addCurveLoop(edges)});
  extrude_along_z(trapezoid, thickness, structured ? divisions(thickness, common.mesh_size) : 0);
  occ::synchronize();
  if (structured) {
    // n divisions on every side of the source trapezoid, n = round(48 mm * scale / mesh_size);
    // the extruded layers copy its mesh.
    const int n = divisions(48 * scale, common.mesh_size);
    for (int edge : edges) gmsh::model::mesh::setTransfiniteCurve(edge, n + 1);
    gmsh::model::mesh::setTransfiniteSurface(trapezoid);
  }
  generate_tet_mesh(common.mesh_size, common.order, common.where);

  const double tol = 1e-6 * 60 * scale;
  add_physical_groups({{"zmin", [=](const NodeBox& bx) { return bx.max.z() < tol; }},
                       {"zmax", [=](const NodeBox& bx) { return bx.min.z() > thickness - tol; }},
                       {"left", [=](const NodeBox& bx) { return bx.max.x() < tol; }},
                       {"right", [=](const NodeBox& bx) { return bx.min.x() > 48 * scale - tol; }},
                       {"bottom", [=](const NodeBox& bx) { return bx.min.y() < tol; }},
                       {"top", [=](const NodeBox& bx) { return bx.max.y() > 60 * scale - tol; }}});
  return mesh_from_current_gmsh_model(geometry_source(params, "cook_membrane"));
}

}  // namespace

const std::map<std::string, GeometryBuilder>& geometry_registry() {
  static const std::map<std::string, GeometryBuilder> registry = {
      {"block", build_block},
      {"thick_cylinder", build_thick_cylinder},
      {"spherical_shell", build_spherical_shell},
      {"cook_membrane", build_cook_membrane},
      {"cantilever", build_cantilever},
      {"robot_voxel", build_robot_voxel},
      {"robot_physical", build_robot_physical},
      {"hemisphere", build_hemisphere},
      {"solid_cylinder", build_solid_cylinder},
  };
  return registry;
}

std::string geometry_source(const ParamSet& params, const std::string& type) {
  return params.context().empty() ? "geometry " + type : params.context();
}

Mesh build_geometry(const ParamSet& params) {
  const std::string type = params.string("type");
  const auto& registry = geometry_registry();
  auto it = registry.find(type);
  if (it == registry.end()) {
    throw InputError(params.where("type"),
                     "unknown geometry type '" + type + "' (known: " + join_keys(registry, ", ") + ")");
  }
  return it->second(params);
}

}  // namespace morphfem
