// Robot geometries (see robot.h): an assembly of axis-aligned boxes, each labelled with
// its volume region, joined by OCC boolean fragments; cavities are the empty boxes the
// pieces enclose. Surfaces are named after meshing from a representative triangle of
// each boundary surface entity: inside a cavity box -> that cavity's wall; outward
// normal -z -> bottom (and a foot if it is the skin's bottom face in a foot band, or in
// the voxel preset an end or side face of the bottom layer there);
// otherwise outer. The same outside surfaces are also split by material for
// friction: the feet, bladder_surface (a bladder's faces) and skin_surface (the rest).
#include "mesh/robot.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "core/errors.h"
#include "mesh/geometry.h"

namespace morphfem {

namespace {

using Vec3 = Eigen::Vector3d;

constexpr double kHuge = std::numeric_limits<double>::max();
constexpr int kBladders = 8;

struct AxisBox {
  Vec3 lo, hi;
  bool contains(const Vec3& p, double tol) const {
    return (p.array() >= lo.array() - tol).all() && (p.array() <= hi.array() + tol).all();
  }
};

AxisBox axis_box(double x0, double x1, double y0, double y1, double z0, double z1) {
  return {Vec3(x0, y0, z0), Vec3(x1, y1, z1)};
}

struct Piece {
  AxisBox box;
  std::string region;
};

struct Cavity {
  AxisBox box;
  std::string surface;  // name of its wall (surface region)
};

struct Assembly {
  std::vector<Piece> pieces;              // solid boxes, touching but not overlapping
  std::vector<Cavity> cavities;           // closed empty boxes enclosed by the pieces
  std::vector<std::string> volume_order;  // volume regions in group order
  double length = 0.0;                    // body length along y
  double foot_length = 0.0;               // feet: y in [0, foot_length] and [length - foot_length, length]
  double foot_z = 0.0;                    // z of the skin's bottom face (the feet plane)
  // z of the top of the layer the feet belong to: > foot_z makes a foot of every
  // outside skin face of that layer in a band (its bottom, end and side faces, as the
  // lattice's foot voxels are whole voxels); = foot_z: the bottom face only.
  double foot_top_z = 0.0;
  double scale = 0.0;           // largest body dimension (for tolerances)
  std::vector<double> sheet_z;  // z of internal planes named fabric_sheet (membranes)
  // Air gaps (chambers bonded along a strip): the outside faces whose centroids lie in
  // a box are also named after it, for self-contact across the gap.
  std::vector<Cavity> gaps;
  double chamber_size = 0.0;  // > 0: mesh size [m] at the bladders' corners (local refinement)
};

// Representative point (centroid of the first triangle) and node box of a meshed surface.
struct SurfaceSample {
  Vec3 point = Vec3::Zero();
  int axis = 2;  // the coordinate axis the (planar, axis-aligned) surface is normal to
  AxisBox nodes;
};

Vec3 node_coordinates(std::size_t tag) {
  std::vector<double> coord, parametric;
  gmsh::model::mesh::getNode(tag, coord, parametric);
  return Vec3(coord[0], coord[1], coord[2]);
}

SurfaceSample sample_surface(int tag) {
  SurfaceSample s;
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> element_tags, node_tags;
  gmsh::model::mesh::getElements(types, element_tags, node_tags, 2, tag);
  if (types.empty() || node_tags[0].size() < 3) throw std::logic_error("robot geometry: an unmeshed surface");
  const Vec3 a = node_coordinates(node_tags[0][0]), b = node_coordinates(node_tags[0][1]),
             c = node_coordinates(node_tags[0][2]);
  s.point = (a + b + c) / 3.0;
  (b - a).cross(c - a).cwiseAbs().maxCoeff(&s.axis);

  const NodeBox box = node_box(2, tag);
  s.nodes = {box.min, box.max};
  return s;
}

bool inside_solid(const Assembly& assembly, const Vec3& p) {
  return std::any_of(assembly.pieces.begin(), assembly.pieces.end(),
                     [&](const Piece& piece) { return piece.box.contains(p, 0.0); });
}

void add_group(int dim, const std::vector<int>& tags, const std::string& name) {
  if (tags.empty()) throw std::logic_error("robot geometry: empty region " + name);
  gmsh::model::setPhysicalName(dim, gmsh::model::addPhysicalGroup(dim, tags), name);
}

// Adds a surface region per gap: copies of the outside faces (bottom, outer) whose
// vertex centroids lie in its box. A face then belongs to both regions, as the feet do.
void name_gap_faces(Mesh& mesh, const std::vector<Cavity>& gaps, double tol) {
  std::vector<int> outside = mesh.faces_of("bottom");
  const std::vector<int> outer = mesh.faces_of("outer");
  outside.insert(outside.end(), outer.begin(), outer.end());
  int next_id = 0;
  for (const Region& r : mesh.regions) next_id = std::max(next_id, r.id + 1);
  std::vector<int> rows, ids;
  for (const Cavity& gap : gaps) {
    const int id = next_id++;
    mesh.regions.push_back(Region{gap.surface, 2, id});
    for (int f : outside) {
      const Vec3 c = (mesh.X.row(mesh.faces(f, 0)) + mesh.X.row(mesh.faces(f, 1)) + mesh.X.row(mesh.faces(f, 2))) / 3.0;
      if (gap.box.contains(c, tol)) {
        rows.push_back(f);
        ids.push_back(id);
      }
    }
  }
  const int n = mesh.n_faces();
  mesh.faces.conservativeResize(n + static_cast<int>(rows.size()), Eigen::NoChange);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    mesh.faces.row(n + static_cast<int>(i)) = mesh.faces.row(rows[i]);
    mesh.face_region.push_back(ids[i]);
  }
}

// Volume fragments by region: the piece containing each fragment's centre of mass
// gives its region.
struct AssemblyVolumes {
  std::map<std::string, std::vector<int>> tags;  // region -> volume tags
  std::map<int, std::string> region_of_volume;
};
AssemblyVolumes assembly_volumes(const Assembly& assembly, double tol) {
  namespace occ = gmsh::model::occ;
  AssemblyVolumes out;
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  for (const auto& [dim, tag] : volumes) {
    double x, y, z;
    occ::getCenterOfMass(dim, tag, x, y, z);
    auto piece = std::find_if(assembly.pieces.begin(), assembly.pieces.end(),
                              [&](const Piece& p) { return p.box.contains(Vec3(x, y, z), tol); });
    if (piece == assembly.pieces.end()) throw std::logic_error("robot geometry: a fragment lies in no piece");
    out.tags[piece->region].push_back(tag);
    out.region_of_volume[tag] = piece->region;
  }
  return out;
}

// An outside boundary surface (no cavity) by material, for friction: "bottom" or
// "outer" by the side the solid is on (probed `probe` along its normal), then a foot
// (foot_a, foot_b), else a bladder's or the skin's surface; end faces (normal along y)
// at y = 0 and y = length also go to end_a and end_b.
void name_outside_surface(const Assembly& assembly, int tag, const SurfaceSample& s, bool bladder, double tol,
                          double probe, std::map<std::string, std::vector<int>>& surface_tags) {
  bool foot = false;
  Vec3 step = Vec3::Zero();
  step(s.axis) = probe;
  const bool solid_below = inside_solid(assembly, s.point - step), solid_above = inside_solid(assembly, s.point + step);
  if (solid_below == solid_above) throw std::logic_error("robot geometry: cannot orient a boundary surface");
  const bool faces_down = s.axis == 2 && solid_above;
  surface_tags[faces_down ? "bottom" : "outer"].push_back(tag);
  const bool in_foot_plane = faces_down && std::abs(s.nodes.hi.z() - assembly.foot_z) <= tol &&
                             std::abs(s.nodes.lo.z() - assembly.foot_z) <= tol;
  // A side or end face of the foot layer: when the body arches it stands on the
  // foot's outer edge, whose friction must then be the foot's, not the skin's.
  const bool foot_layer_side = !bladder && s.axis != 2 && assembly.foot_top_z > assembly.foot_z + tol &&
                               s.nodes.lo.z() >= assembly.foot_z - tol && s.nodes.hi.z() <= assembly.foot_top_z + tol;
  if (in_foot_plane || foot_layer_side) {
    if (s.nodes.hi.y() <= assembly.foot_length + tol) {
      surface_tags["foot_a"].push_back(tag);
      foot = true;
    }
    if (s.nodes.lo.y() >= assembly.length - assembly.foot_length - tol) {
      surface_tags["foot_b"].push_back(tag);
      foot = true;
    }
  }
  if (!foot) surface_tags[bladder ? "bladder_surface" : "skin_surface"].push_back(tag);
  // The end faces (normal along y) at y = 0 and y = length, for slices in plane strain.
  if (s.axis == 1 && s.nodes.hi.y() <= tol) surface_tags["end_a"].push_back(tag);
  if (s.axis == 1 && s.nodes.lo.y() >= assembly.length - tol) surface_tags["end_b"].push_back(tag);
}

// The boundary regions in the order they are declared: cavities, then the outside
// surfaces (no feet without a foot length), then the fabric sheet if any.
std::vector<std::string> surface_order(const Assembly& assembly) {
  std::vector<std::string> order;
  for (const Cavity& c : assembly.cavities) order.push_back(c.surface);
  for (const char* name : {"bottom", "foot_a", "foot_b", "outer", "skin_surface", "bladder_surface", "end_a", "end_b"})
    if (assembly.foot_length > 0 || std::string(name).rfind("foot_", 0) != 0) order.push_back(name);  // no feet
  if (!assembly.sheet_z.empty()) order.push_back("fabric_sheet");
  return order;
}

// Mesh errors name the scene's geometry (or "geometry TYPE"); a geometry gmsh cannot
// mesh names the mesh_size key's location.
Mesh mesh_assembly(const Assembly& assembly, double mesh_size, int order, const ParamSet& params,
                   const std::string& type) {
  const std::string source = geometry_source(params, type);
  ScopedGmshModel model("morphfem_robot");
  namespace occ = gmsh::model::occ;
  gmsh::vectorpair boxes;
  for (const Piece& piece : assembly.pieces) {
    const Vec3 size = piece.box.hi - piece.box.lo;
    boxes.emplace_back(3,
                       occ::addBox(piece.box.lo.x(), piece.box.lo.y(), piece.box.lo.z(), size.x(), size.y(), size.z()));
  }
  gmsh::vectorpair fragments;
  std::vector<gmsh::vectorpair> unused_map;
  occ::fragment({boxes.front()}, gmsh::vectorpair(boxes.begin() + 1, boxes.end()), fragments, unused_map);
  occ::synchronize();
  const double tol = 1e-9 * assembly.scale, probe = 1e-6 * assembly.scale;

  AssemblyVolumes volumes = assembly_volumes(assembly, tol);
  const std::map<int, std::string>& region_of_volume = volumes.region_of_volume;
  std::vector<VolumeSize> refine;
  if (assembly.chamber_size > 0) {
    refine.push_back({{}, assembly.chamber_size});
    for (const auto& [tag, region] : region_of_volume)
      if (region.rfind("bladder_", 0) == 0) refine.back().volumes.push_back(tag);
  }
  generate_tet_mesh(mesh_size, order, params.where("mesh_size"), refine);
  for (const std::string& name : assembly.volume_order) add_group(3, volumes.tags[name], name);

  // Boundary surfaces (one adjacent volume).
  std::map<std::string, std::vector<int>> surface_tags;
  gmsh::vectorpair surfaces;
  gmsh::model::getEntities(surfaces, 2);
  for (const auto& [dim, tag] : surfaces) {
    std::vector<int> up, down;
    gmsh::model::getAdjacencies(dim, tag, up, down);
    if (up.size() == 2 && !assembly.sheet_z.empty()) {  // an interface: a fabric sheet's plane?
      const SurfaceSample s = sample_surface(tag);
      const bool sheet = s.axis == 2 && std::any_of(assembly.sheet_z.begin(), assembly.sheet_z.end(), [&](double z) {
                           return std::abs(s.nodes.lo.z() - z) <= tol && std::abs(s.nodes.hi.z() - z) <= tol;
                         });
      if (sheet) surface_tags["fabric_sheet"].push_back(tag);
    }
    if (up.size() != 1) continue;
    const SurfaceSample s = sample_surface(tag);
    auto cavity = std::find_if(assembly.cavities.begin(), assembly.cavities.end(),
                               [&](const Cavity& c) { return c.box.contains(s.point, tol); });
    if (cavity != assembly.cavities.end()) {
      surface_tags[cavity->surface].push_back(tag);
      continue;
    }
    name_outside_surface(assembly, tag, s, region_of_volume.at(up[0]).rfind("bladder_", 0) == 0, tol, probe,
                         surface_tags);
  }
  for (const std::string& name : surface_order(assembly)) add_group(2, surface_tags[name], name);

  Mesh mesh = mesh_from_current_gmsh_model(source);
  if (!assembly.gaps.empty()) name_gap_faces(mesh, assembly.gaps, tol);
  return mesh;
}

// Reads a length with a default, in (0, inf).
double length_param(const ParamSet& params, const std::string& key, double fallback) {
  return params.number_in(key, 1e-9, kHuge, fallback);
}

void require(bool ok, const ParamSet& params, const std::string& key, const std::string& message) {
  if (!ok) throw InputError(params.where(key), message);
}

// x range of bladder column c = 0..3 (increasing x): columns of width bw evenly spaced
// over [0, width], the outer ones flush with the edges.
std::pair<double, double> column_x(int c, double width, double bw) {
  const double pitch = (width - bw) / 3.0;
  return {c * pitch, c * pitch + bw};
}

// Top bladders 1..4 over columns 0..3, bottom bladders 5..8 over columns 3..0.
int bladder_column(int k) { return k <= 4 ? k - 1 : kBladders - k; }

std::string bladder_name(int k) { return "bladder_" + std::to_string(k); }

// A layer [0, width] x [0, length] x [z0, z1], split at the foot bands' inner ends.
void add_split_layer(Assembly& a, double width, double z0, double z1, const std::string& region) {
  const double f = a.foot_length, l = a.length;
  if (f > 0) a.pieces.push_back({axis_box(0, width, 0, f, z0, z1), region});
  a.pieces.push_back({axis_box(0, width, f, l - f, z0, z1), region});
  if (f > 0) a.pieces.push_back({axis_box(0, width, l - f, l, z0, z1), region});
}

// The core gap z in [z0, z1]: solid bonded strips along x = 0 and x = width (edge wide),
// end seals at y = 0 and y = length (seal wide), and the cavity between them. With
// seal = 0 the gap is open at both ends (a sleeve): core_wall is then the gap's top,
// bottom and side faces only, and its volume must be taken over the x and z axes
// (volume_axes [x, z], exact while the open ends stay in planes y = const).
void add_core(Assembly& a, double width, double edge, double seal, double z0, double z1) {
  const double l = a.length;
  a.pieces.push_back({axis_box(0, edge, 0, l, z0, z1), "skin"});
  a.pieces.push_back({axis_box(width - edge, width, 0, l, z0, z1), "skin"});
  if (seal > 0) {
    a.pieces.push_back({axis_box(edge, width - edge, 0, seal, z0, z1), "skin"});
    a.pieces.push_back({axis_box(edge, width - edge, l - seal, l, z0, z1), "skin"});
  }
  a.cavities.push_back({axis_box(edge, width - edge, seal, l - seal, z0, z1), "core_wall"});
}

struct CommonRobot {
  double mesh_size = 0.0;
  int order = 1;
  double width = 0.0, length = 0.0, core_gap = 0.0, edge = 0.0, seal = 0.0;
  double bladder_thickness = 0.0, bladder_width = 0.0, foot_length = 0.0;
};

CommonRobot common_robot(const ParamSet& params, double width, double length, double core_gap, double edge, double seal,
                         double bladder_thickness, double bladder_width, double foot_length) {
  CommonRobot c;
  c.mesh_size = params.number_in("mesh_size", 1e-12, kHuge);
  c.order = params.integer_in("order", 1, 2, 1);
  c.width = length_param(params, "width", width);
  c.length = length_param(params, "length", length);
  c.core_gap = length_param(params, "core_gap", core_gap);
  c.edge = length_param(params, "edge_width", edge);
  c.seal = params.number_in("end_seal", 0.0, kHuge, seal);  // 0: open ends
  c.bladder_thickness = length_param(params, "bladder_thickness", bladder_thickness);
  c.bladder_width = length_param(params, "bladder_width", bladder_width);
  c.foot_length = params.number_in("foot_length", 0.0, kHuge, foot_length);  // 0: no feet (a slice)
  require(2 * c.edge < c.width, params, "edge_width", "the two bonded edges must leave a core: 2 edge_width < width");
  require(2 * c.seal < c.length, params, "end_seal", "the two end seals must leave a core: 2 end_seal < length");
  require(4 * c.bladder_width <= c.width, params, "bladder_width",
          "four bladder columns must fit: 4 bladder_width <= width");
  require(2 * c.foot_length < c.length, params, "foot_length", "the feet must not meet: 2 foot_length < length");
  return c;
}

std::vector<std::string> volume_order(bool with_fabric) {
  std::vector<std::string> order = {"skin"};
  if (with_fabric) order.push_back("fabric");
  for (int k = 1; k <= kBladders; ++k) order.push_back(bladder_name(k));
  return order;
}

}  // namespace

namespace {

// The robot_voxel body's parameters and its stacking in z (read once, for the mesh
// and for its lattice): bladders [0, hb], bottom layer [hb, z_core], core gap,
// top layer [z_top, z_upper], bladders [z_upper, z_upper + hb]; bladders over y in
// [y0, y1].
struct VoxelLayout {
  CommonRobot c;
  double t = 0, y0 = 0, y1 = 0, hb = 0, z_core = 0, z_top = 0, z_upper = 0;
};

VoxelLayout voxel_layout(const ParamSet& params) {
  params.allow_only({"type", "mesh_size", "order", "width", "length", "layer_thickness", "core_gap", "edge_width",
                     "end_seal", "bladder_thickness", "bladder_width", "bladder_start", "bladder_end", "foot_length"});
  VoxelLayout l;
  l.c = common_robot(params, 0.15, 0.22, 0.002, 0.01, 0.01, 0.02, 0.03, 0.03);
  l.t = length_param(params, "layer_thickness", 0.01);
  l.y0 = params.number_in("bladder_start", 0.0, l.c.length, 0.03);
  l.y1 = params.number_in("bladder_end", 0.0, l.c.length, 0.19);
  require(l.y0 < l.y1, params, "bladder_end", "bladder_end must exceed bladder_start");
  l.hb = l.c.bladder_thickness;
  l.z_core = l.hb + l.t;
  l.z_top = l.z_core + l.c.core_gap;
  l.z_upper = l.z_top + l.t;
  return l;
}

}  // namespace

Mesh build_robot_voxel(const ParamSet& params) {
  const VoxelLayout l = voxel_layout(params);
  const CommonRobot& c = l.c;
  const double t = l.t, y0 = l.y0, y1 = l.y1, hb = l.hb, z_core = l.z_core, z_top = l.z_top, z_upper = l.z_upper;

  Assembly a;
  a.length = c.length;
  a.foot_length = c.foot_length;
  a.volume_order = volume_order(false);
  a.foot_z = hb;
  a.foot_top_z = hb + t;  // the feet are the bottom layer's foot voxels (ROBOT.md)
  a.scale = std::max({c.width, c.length, z_upper + hb});
  add_split_layer(a, c.width, hb, z_core, "skin");
  add_core(a, c.width, c.edge, c.seal, z_core, z_top);
  a.pieces.push_back({axis_box(0, c.width, 0, c.length, z_top, z_upper), "skin"});
  for (int k = 1; k <= kBladders; ++k) {
    const auto [x0, x1] = column_x(bladder_column(k), c.width, c.bladder_width);
    const double z0 = k <= 4 ? z_upper : 0.0;
    a.pieces.push_back({axis_box(x0, x1, y0, y1, z0, z0 + hb), bladder_name(k)});
  }
  return mesh_assembly(a, c.mesh_size, c.order, params, "robot_voxel");
}

std::vector<LatticeVoxelBox> robot_voxel_lattice(const ParamSet& params, double voxel, double bladder_min_scale) {
  if (!(voxel > 0) || !(bladder_min_scale > 0))
    throw InputError(params.where("type"), "the lattice needs a voxel size > 0 and a bladder scale > 0");
  const VoxelLayout l = voxel_layout(params);
  const CommonRobot& c = l.c;
  const double y0 = l.y0, y1 = l.y1, hb = l.hb, z_core = l.z_core, z_top = l.z_top, z_upper = l.z_upper;
  // n boxes of equal size over [a, b]: the voxel count, at least one.
  const auto bins = [](double a, double b, double size) {
    const int n = std::max(1, static_cast<int>(std::lround((b - a) / size)));
    std::vector<double> edges(n + 1);
    for (int i = 0; i <= n; ++i) edges[i] = a + (b - a) * i / n;
    return edges;
  };
  std::vector<LatticeVoxelBox> boxes;
  const auto add_block = [&](const std::string& region, double xa, double xb, double ya, double yb, double za,
                             double zb, double z_size) {
    const auto ex = bins(xa, xb, voxel), ey = bins(ya, yb, voxel), ez = bins(za, zb, z_size);
    for (size_t k = 0; k + 1 < ez.size(); ++k)
      for (size_t j = 0; j + 1 < ey.size(); ++j)
        for (size_t i = 0; i + 1 < ex.size(); ++i)
          boxes.push_back({region, Eigen::Vector3d(ex[i], ey[j], ez[k]),
                           Eigen::Vector3d(ex[i + 1], ey[j + 1], ez[k + 1]),
                           Eigen::Vector3d(1.0, 1.0, (ez[k + 1] - ez[k]) / voxel)});
  };
  add_block("skin", 0, c.width, 0, c.length, hb, z_core, voxel);
  add_block("skin", 0, c.width, 0, c.length, z_top, z_upper, voxel);
  for (int k = 1; k <= kBladders; ++k) {
    const auto [x0, x1] = column_x(bladder_column(k), c.width, c.bladder_width);
    const double z0 = k <= 4 ? z_upper : 0.0;
    add_block(bladder_name(k), x0, x1, y0, y1, z0, z0 + hb, bladder_min_scale * voxel);
  }
  return boxes;
}

Mesh build_robot_physical(const ParamSet& params) {
  // (clang-format would put these 20 keys one per line)
  // clang-format off
  params.allow_only({"type", "mesh_size", "order", "width", "length", "skin_thickness", "fabric_thickness", "core_gap",
                     "edge_width", "end_seal", "bladder_thickness", "bladder_wall", "bladder_width", "foot_length",
                     "bladder_end_walls", "foot_pad", "fabric", "bladder_bond_width", "bladder_gap",
                     "bladder_mesh_size"});
  // clang-format on
  const CommonRobot c = common_robot(params, 0.10, 0.15, 0.001, 0.005, 0.005, 0.003, 0.02, 0.02);
  // 0: chambers open at both ends (no end walls), e.g. for a plane-strain slice in which
  // the chambers run through the whole slice (foot_length 0) as open sleeves.
  const bool end_walls = params.integer_in("bladder_end_walls", 0, 1, 1) == 1;
  const double t = length_param(params, "skin_thickness", 0.003);
  // The fabric: a solid layer (volume `fabric`, fabric_thickness thick) or a sheet
  // without thickness in the mesh (surface `fabric_sheet`, an interface inside the skin
  // layer, for a membrane term: no thin tetrahedra).
  const std::string fabric = params.string("fabric", "solid");
  require(fabric == "solid" || fabric == "membrane", params, "fabric", "must be 'solid' or 'membrane'");
  const bool sheet = fabric == "membrane";
  const double tf = sheet ? 0.0 : length_param(params, "fabric_thickness", 0.0005);
  const double w = length_param(params, "bladder_wall", 0.0008);
  require(tf < t, params, "fabric_thickness", "the fabric must be thinner than the skin layer");
  require(2 * w < std::min(c.bladder_thickness, c.bladder_width), params, "bladder_wall",
          "the bladder walls must leave a chamber: 2 bladder_wall < bladder_thickness and bladder_width");
  if (end_walls)
    require(2 * w < c.length - 2 * c.foot_length, params, "bladder_wall",
            "the bladder walls must leave a chamber along the axis");
  // Foot pads: solid blocks (volume region `foot`) under the skin in the two foot bands,
  // pad thick, standing in for the foot balloons in their laminae; their bottom faces are
  // the feet. A pad thicker than the lower bladders lifts the body so that the robot
  // stands on its feet. 0: no pads (the feet are the skin's bottom faces).
  const double pad = params.number_in("foot_pad", 0.0, kHuge, 0.0);
  require(pad == 0.0 || c.foot_length > 0, params, "foot_pad", "foot pads need feet: foot_length > 0");
  // Chambers bonded to the skin over their full width (default), or only along a
  // central strip bladder_bond_width wide: the chamber then stands bladder_gap off the
  // skin on a DS30 strip, so its floor, free on either side of the strip, unfolds
  // with its roof as a flattened tube does (an air gap in the mesh, not a
  // zero-thickness unbonded interface; the gap's faces are outside faces).
  const double bond = params.number_in("bladder_bond_width", 1e-9, c.bladder_width, c.bladder_width);
  const bool strip = bond < c.bladder_width;
  const double gap = strip ? length_param(params, "bladder_gap", w) : 0.0;
  require(strip || !params.has("bladder_gap"), params, "bladder_gap",
          "a gap needs a chamber bonded along a strip: bladder_bond_width < bladder_width");

  Assembly a;
  a.length = c.length;
  a.foot_length = c.foot_length;
  a.volume_order = volume_order(!sheet);
  // Local refinement of the chambers: their walls bend, the skin around them mostly
  // stretches, so a finer mesh there resolves the bulge at a fraction of the dofs.
  a.chamber_size = params.number_in("bladder_mesh_size", 1e-9, c.mesh_size, c.mesh_size);
  if (a.chamber_size >= c.mesh_size) a.chamber_size = 0.0;
  if (pad > 0) a.volume_order.push_back("foot");
  const double hb = c.bladder_thickness, ds = 0.5 * (t - tf);
  const double base = std::max(0.0, pad - hb - gap);  // lift of the body over the ground plane z = 0
  const double z_skin = base + hb + gap, z_core = z_skin + t, z_top = z_core + c.core_gap, z_upper = z_top + t;
  a.foot_z = z_skin - pad;
  a.scale = std::max({c.width, c.length, z_upper + gap + hb});
  if (pad > 0) {
    a.pieces.push_back({axis_box(0, c.width, 0, c.foot_length, a.foot_z, z_skin), "foot"});
    a.pieces.push_back({axis_box(0, c.width, c.length - c.foot_length, c.length, a.foot_z, z_skin), "foot"});
  }
  // Each skin layer: DS10 | fabric | DS10 (the fabric a sheet at mid-thickness: DS10 |
  // DS10); the lowest sheet is split at the feet.
  add_split_layer(a, c.width, z_skin, z_skin + ds, "skin");
  if (!sheet) a.pieces.push_back({axis_box(0, c.width, 0, c.length, z_skin + ds, z_skin + ds + tf), "fabric"});
  a.pieces.push_back({axis_box(0, c.width, 0, c.length, z_skin + ds + tf, z_core), "skin"});
  add_core(a, c.width, c.edge, c.seal, z_core, z_top);
  a.pieces.push_back({axis_box(0, c.width, 0, c.length, z_top, z_top + ds), "skin"});
  if (!sheet) a.pieces.push_back({axis_box(0, c.width, 0, c.length, z_top + ds, z_top + ds + tf), "fabric"});
  a.pieces.push_back({axis_box(0, c.width, 0, c.length, z_top + ds + tf, z_upper), "skin"});
  if (sheet) a.sheet_z = {z_skin + ds, z_top + ds};
  // Bladders: closed DS30 chambers (floor, roof, two side walls, two end walls), or
  // without end walls open sleeves along y.
  const double y0 = c.foot_length, y1 = c.length - c.foot_length, we = end_walls ? w : 0.0;
  for (int k = 1; k <= kBladders; ++k) {
    const auto [x0, x1] = column_x(bladder_column(k), c.width, c.bladder_width);
    const double z0 = k <= 4 ? z_upper + gap : base, z1 = z0 + hb;
    const std::string name = bladder_name(k);
    if (strip) {  // the bond strip between the chamber and the skin
      const double xm = 0.5 * (x0 + x1), zb = k <= 4 ? z_upper : z1;
      a.pieces.push_back({axis_box(xm - 0.5 * bond, xm + 0.5 * bond, y0, y1, zb, zb + gap), name});
      // The gap's faces: the floor's underside, the strip's sides and the skin under the
      // chamber (a quarter chamber width either side: skin triangles straddle its edges).
      const double margin = 0.25 * c.bladder_width;
      a.gaps.push_back({axis_box(x0 - margin, x1 + margin, y0, y1, zb, zb + gap), name + "_gap"});
    }
    a.pieces.push_back({axis_box(x0, x1, y0, y1, z0, z0 + w), name});
    a.pieces.push_back({axis_box(x0, x1, y0, y1, z1 - w, z1), name});
    a.pieces.push_back({axis_box(x0, x0 + w, y0, y1, z0 + w, z1 - w), name});
    a.pieces.push_back({axis_box(x1 - w, x1, y0, y1, z0 + w, z1 - w), name});
    if (end_walls) {
      a.pieces.push_back({axis_box(x0 + w, x1 - w, y0, y0 + w, z0 + w, z1 - w), name});
      a.pieces.push_back({axis_box(x0 + w, x1 - w, y1 - w, y1, z0 + w, z1 - w), name});
    }
    a.cavities.push_back({axis_box(x0 + w, x1 - w, y0 + we, y1 - we, z0 + w, z1 - w), name + "_wall"});
  }
  return mesh_assembly(a, c.mesh_size, c.order, params, "robot_physical");
}

}  // namespace morphfem
