// Geometry built in code with the gmsh C++ API, and import of user .msh files.
// Every builder returns a Mesh with named regions (physical groups). Builders are
// registered by name in one place (geometry.cpp) and read their parameters from
// a ParamSet, so scenes pick a geometry with `geometry: {type: NAME, ...}`.
#pragma once
#include <Eigen/Dense>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "core/params.h"
#include "mesh/mesh.h"

namespace morphfem {

// Common parameters of every builder:
//   mesh_size [m]   target element edge length (required)
//   order           1 (P1, 4-node tets) or 2 (P2, 10-node tets; curved mid-nodes
//                   on curved surfaces), default 1
using GeometryBuilder = std::function<Mesh(const ParamSet&)>;

// name -> builder; names: block, thick_cylinder, spherical_shell, cook_membrane,
// cantilever (see geometry.cpp for each one's parameters and region names).
const std::map<std::string, GeometryBuilder>& geometry_registry();

// Builds geometry `params.string("type")`; throws InputError for an unknown type
// or bad parameter.
Mesh build_geometry(const ParamSet& params);

// What a builder's mesh errors name: the scene's geometry section (its file and
// line) or, for a ParamSet made in code, "geometry TYPE".
std::string geometry_source(const ParamSet& params, const std::string& type);

// Reads a gmsh .msh (format 4.x) file: 4- or 10-node tetrahedra, physical groups
// of dimension 3 (materials) and 2 (surfaces) give the named regions; elements of
// other types are ignored except that mixing P1 and P2 tetrahedra is an error.
// Throws InputError naming the file and what is wrong.
Mesh read_msh(const std::string& path);

// Writes `mesh` as a gmsh .msh 4.1 file: one discrete entity and one named physical
// group per region, P2 nodes in gmsh order. Reading it back gives the same nodes,
// faces and regions (cells are grouped by volume region, so with one volume region the
// same Mesh). Throws InputError naming the file if it cannot be written.
void write_msh(const Mesh& mesh, const std::string& path);

// Lower level, shared by the builders and read_msh.
// Initializes the gmsh API once per process (quiet, single-threaded); cheap to repeat.
void initialize_gmsh();
// Tight axis-aligned bounding box of the mesh nodes of one gmsh entity (dim, tag),
// unlike gmsh's CAD boxes.
struct NodeBox {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d max = Eigen::Vector3d::Constant(-std::numeric_limits<double>::max());
};
NodeBox node_box(int dim, int tag);
// A named surface and the test its entities' node boxes pass.
struct SurfaceRule {
  std::string name;
  std::function<bool(const NodeBox&)> matches;
};
// Physical groups of the meshed current model: every volume as "body", each surface
// entity under the name of the first rule it matches (std::logic_error if it matches
// none, or a rule names no entity).
void add_physical_groups(const std::vector<SurfaceRule>& rules);

// Meshes the synchronized current model in 3-D: target size mesh_size [m] at every
// CAD point (a background size field can only refine below it), element order 1 or 2
// with curved mid-nodes, deterministic single-threaded Delaunay. A geometry gmsh cannot
// mesh throws InputError(where, ...) with gmsh's reason; builders pass the location of
// their mesh_size key (ParamSet::where: scene file, line, key). `refine` lists volumes (gmsh
// tags) and a smaller size [m] for every CAD point on their boundaries (local
// refinement: sizes are interpolated from the points along curves and surfaces).
struct VolumeSize {
  std::vector<int> volumes;
  double size = 0.0;
};
void generate_tet_mesh(double mesh_size, int order, const std::string& where,
                       const std::vector<VolumeSize>& refine = {});
// A fresh gmsh model for one build or file operation, removed when the scope ends
// (also on errors).
class ScopedGmshModel {
 public:
  explicit ScopedGmshModel(const std::string& name);
  ~ScopedGmshModel();
  ScopedGmshModel(const ScopedGmshModel&) = delete;
  ScopedGmshModel& operator=(const ScopedGmshModel&) = delete;
};
// Extracts the Mesh of the current gmsh model: its 4- or 10-node tetrahedra (all of
// them must lie in a volume physical group), the triangles of every surface
// physical group (stored once per group, oriented outward from their tetrahedron),
// and the regions. Throws InputError naming `source` if the model is unusable.
Mesh mesh_from_current_gmsh_model(const std::string& source);

}  // namespace morphfem
