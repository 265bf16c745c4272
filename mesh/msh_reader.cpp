// gmsh model -> Mesh extraction (shared by the geometry builders and .msh import),
// read_msh and write_msh.
#include <gmsh.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "core/errors.h"
#include "mesh/geometry.h"

namespace morphfem {

namespace {

// gmsh element type codes.
constexpr int kGmshTriangle3 = 2;
constexpr int kGmshTetrahedron4 = 4;
constexpr int kGmshTriangle6 = 9;
constexpr int kGmshTetrahedron10 = 11;

// gmsh's 10-node tetrahedron lists its edge mid-nodes as (0,1) (1,2) (2,0) (3,0) (3,2)
// (3,1); VTK as (0,1) (1,2) (0,2) (0,3) (1,3) (2,3). So gmsh nodes 8 and 9 are swapped:
// vtk_node[k] = gmsh_node[kGmshToVtkTet10[k]] (the permutation is its own inverse).
constexpr std::array<int, 10> kGmshToVtkTet10 = {0, 1, 2, 3, 4, 5, 6, 7, 9, 8};
// The 6-node triangle uses (0,1) (1,2) (2,0) in both conventions.

// Swapping vertices 1 and 2 of a VTK tetrahedron (to flip its orientation) also maps
// the mid-nodes: (0,1)<->(0,2), (1,2) stays, (1,3)<->(2,3).
constexpr std::array<int, 10> kTetSwap12 = {0, 2, 1, 3, 6, 5, 4, 7, 9, 8};

// Local faces of a positively oriented VTK tetrahedron, each ordered so that its
// normal (x1 - x0) x (x2 - x0) points away from the opposite vertex, as 6-node
// triangles (vertices, then mid-nodes of (0,1) (1,2) (0,2)). Face k is opposite vertex k.
constexpr int kOutwardTetFaces[4][6] = {{1, 2, 3, 5, 9, 8}, {0, 3, 2, 7, 9, 6}, {0, 1, 3, 4, 8, 7}, {0, 2, 1, 6, 5, 4}};

using FaceKey = std::array<int, 3>;  // sorted vertex node indices

FaceKey face_key(int a, int b, int c) {
  FaceKey key = {a, b, c};
  std::sort(key.begin(), key.end());
  return key;
}

struct GmshTetrahedra {
  int order = 1;
  std::vector<std::size_t> element_tags;
  std::vector<std::size_t> node_tags;  // gmsh node order, nodes_per_cell per element
};

// Elements of one type on one entity (of dimension dim), appended to the outputs.
// (Queried per entity with getElements: gmsh 4.8's getElementsByType misbehaves on
// entities holding several element types.)
void append_entity_elements(int dim, int entity, int element_type, std::vector<std::size_t>& element_tags,
                            std::vector<std::size_t>& node_tags) {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> tags_by_type, nodes_by_type;
  gmsh::model::mesh::getElements(types, tags_by_type, nodes_by_type, dim, entity);
  for (std::size_t t = 0; t < types.size(); ++t) {
    if (types[t] != element_type) continue;
    element_tags.insert(element_tags.end(), tags_by_type[t].begin(), tags_by_type[t].end());
    node_tags.insert(node_tags.end(), nodes_by_type[t].begin(), nodes_by_type[t].end());
  }
}

GmshTetrahedra read_gmsh_tetrahedra(const std::string& source) {
  GmshTetrahedra p1, p2;
  p2.order = 2;
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  for (const auto& [dim, tag] : volumes) {
    append_entity_elements(dim, tag, kGmshTetrahedron4, p1.element_tags, p1.node_tags);
    append_entity_elements(dim, tag, kGmshTetrahedron10, p2.element_tags, p2.node_tags);
  }
  if (p1.element_tags.empty() && p2.element_tags.empty())
    throw InputError(source, "the mesh has no tetrahedra (4- or 10-node)");
  if (!p1.element_tags.empty() && !p2.element_tags.empty())
    throw InputError(source, "the mesh mixes " + std::to_string(p1.element_tags.size()) + " first-order and " +
                                 std::to_string(p2.element_tags.size()) + " second-order tetrahedra; use one order");
  return p1.element_tags.empty() ? p2 : p1;
}

// Node tags used by the tetrahedra, sorted, and their coordinates.
struct CompactNodes {
  std::unordered_map<std::size_t, int> index_of_tag;
  RowMatrixXd X;
};

CompactNodes compact_nodes(const std::vector<std::size_t>& used_tags_with_repeats, const std::string& source) {
  std::vector<std::size_t> used = used_tags_with_repeats;
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  CompactNodes out;
  out.X.setZero(static_cast<Eigen::Index>(used.size()), 3);
  for (std::size_t i = 0; i < used.size(); ++i) out.index_of_tag.emplace(used[i], static_cast<int>(i));

  std::vector<std::size_t> tags;
  std::vector<double> coords, parametric;
  gmsh::model::mesh::getNodes(tags, coords, parametric, -1, -1, true, false);
  std::vector<bool> found(used.size(), false);
  for (std::size_t k = 0; k < tags.size(); ++k) {
    auto it = out.index_of_tag.find(tags[k]);
    if (it == out.index_of_tag.end()) continue;
    for (int c = 0; c < 3; ++c) out.X(it->second, c) = coords[3 * k + c];
    found[it->second] = true;
  }
  if (std::find(found.begin(), found.end(), false) != found.end())
    throw InputError(source, "a tetrahedron references a node that is not defined");
  return out;
}

// Signed volume of the vertex tetrahedron of a cell row [m^3].
double signed_vertex_volume(const RowMatrixXd& X, const RowMatrixXi& cells, int c) {
  const Eigen::RowVector3d x0 = X.row(cells(c, 0));
  const Eigen::RowVector3d e1 = X.row(cells(c, 1)) - x0, e2 = X.row(cells(c, 2)) - x0, e3 = X.row(cells(c, 3)) - x0;
  return e1.dot(e2.cross(e3)) / 6.0;
}

// Cells in VTK order with positive orientation (vertices 1,2 swapped where needed).
RowMatrixXi vtk_cells(const GmshTetrahedra& tets, const CompactNodes& nodes) {
  const int per_cell = tets.order == 1 ? 4 : 10;
  const int n_cells = static_cast<int>(tets.element_tags.size());
  RowMatrixXi cells(n_cells, per_cell);
  for (int c = 0; c < n_cells; ++c)
    for (int k = 0; k < per_cell; ++k) {
      const int gmsh_k = per_cell == 10 ? kGmshToVtkTet10[k] : k;
      cells(c, k) = nodes.index_of_tag.at(tets.node_tags[static_cast<std::size_t>(c) * per_cell + gmsh_k]);
    }
  for (int c = 0; c < n_cells; ++c) {
    if (signed_vertex_volume(nodes.X, cells, c) >= 0.0) continue;
    const Eigen::RowVectorXi original = cells.row(c);
    for (int k = 0; k < per_cell; ++k) cells(c, k) = original(kTetSwap12[k]);
  }
  return cells;
}

struct PhysicalGroup {
  int dim = 0;
  int tag = 0;
  std::string name;
};

// Volume groups first, then surface groups, each in tag order; unnamed groups get
// "volume_TAG" / "surface_TAG".
std::vector<PhysicalGroup> physical_groups(const std::string& source) {
  gmsh::vectorpair dim_tags;
  gmsh::model::getPhysicalGroups(dim_tags);
  std::vector<PhysicalGroup> groups;
  for (int dim : {3, 2})
    for (const auto& [d, tag] : dim_tags) {
      if (d != dim) continue;
      PhysicalGroup g{d, tag, ""};
      gmsh::model::getPhysicalName(d, tag, g.name);
      if (g.name.empty()) g.name = (d == 3 ? "volume_" : "surface_") + std::to_string(tag);
      for (const PhysicalGroup& other : groups)
        if (other.dim == g.dim && other.name == g.name)
          throw InputError(source,
                           "two physical groups of dimension " + std::to_string(dim) + " are named '" + g.name + "'");
      groups.push_back(g);
    }
  if (groups.empty()) throw InputError(source, "the mesh has no physical groups (named volumes and surfaces)");
  if (groups.front().dim != 3) throw InputError(source, "the mesh has no volume (3-D) physical group");
  return groups;
}

// Element tags and node tags of one type over the entities of a physical group.
void group_elements(const PhysicalGroup& group, int element_type, std::vector<std::size_t>& element_tags,
                    std::vector<std::size_t>& node_tags) {
  element_tags.clear();
  node_tags.clear();
  std::vector<int> entities;
  gmsh::model::getEntitiesForPhysicalGroup(group.dim, group.tag, entities);
  for (int entity : entities) append_entity_elements(group.dim, entity, element_type, element_tags, node_tags);
}

std::vector<int> cell_regions(const std::vector<PhysicalGroup>& groups, const GmshTetrahedra& tets,
                              const std::string& source) {
  std::unordered_map<std::size_t, int> cell_of_tag;
  for (std::size_t c = 0; c < tets.element_tags.size(); ++c)
    cell_of_tag.emplace(tets.element_tags[c], static_cast<int>(c));
  const int tet_type = tets.order == 1 ? kGmshTetrahedron4 : kGmshTetrahedron10;
  std::vector<int> region(tets.element_tags.size(), -1);
  for (std::size_t id = 0; id < groups.size(); ++id) {
    if (groups[id].dim != 3) continue;
    std::vector<std::size_t> element_tags, node_tags;
    group_elements(groups[id], tet_type, element_tags, node_tags);
    for (std::size_t tag : element_tags) {
      int& r = region[cell_of_tag.at(tag)];
      if (r >= 0 && r != static_cast<int>(id))
        throw InputError(source, "tetrahedron " + std::to_string(tag) + " is in two volume physical groups, '" +
                                     groups[r].name + "' and '" + groups[id].name + "'");
      r = static_cast<int>(id);
    }
  }
  const auto unassigned = std::count(region.begin(), region.end(), -1);
  if (unassigned > 0)
    throw InputError(source, std::to_string(unassigned) + " tetrahedra belong to no volume physical group");
  return region;
}

// Sorted vertex triple -> (cell * 4 + local face), first (lowest) cell wins.
std::map<FaceKey, int> cell_faces(const RowMatrixXi& cells) {
  std::map<FaceKey, int> faces;
  for (int c = 0; c < cells.rows(); ++c)
    for (int f = 0; f < 4; ++f) {
      const int* local = kOutwardTetFaces[f];
      faces.emplace(face_key(cells(c, local[0]), cells(c, local[1]), cells(c, local[2])), 4 * c + f);
    }
  return faces;
}

struct Faces {
  std::vector<std::array<int, 6>> nodes;
  std::vector<int> region;
};

// Triangles of every surface group, taken from the adjacent cell's outward local face
// (so the opposite vertex lies on the negative side), once per group.
Faces surface_faces(const std::vector<PhysicalGroup>& groups, const RowMatrixXi& cells, int order,
                    const CompactNodes& nodes, const std::string& source) {
  const std::map<FaceKey, int> face_of_key = cell_faces(cells);
  const int tri_type = order == 1 ? kGmshTriangle3 : kGmshTriangle6;
  const int other_tri_type = order == 1 ? kGmshTriangle6 : kGmshTriangle3;
  const int tri_nodes = order == 1 ? 3 : 6;
  Faces out;
  for (std::size_t id = 0; id < groups.size(); ++id) {
    if (groups[id].dim != 2) continue;
    std::vector<std::size_t> element_tags, node_tags;
    group_elements(groups[id], other_tri_type, element_tags, node_tags);
    if (!element_tags.empty())
      throw InputError(source,
                       "surface '" + groups[id].name + "' has triangles of a different order than the tetrahedra");
    group_elements(groups[id], tri_type, element_tags, node_tags);
    for (std::size_t t = 0; t < element_tags.size(); ++t) {
      std::array<int, 3> v{};
      for (int k = 0; k < 3; ++k) {
        auto it = nodes.index_of_tag.find(node_tags[t * tri_nodes + k]);
        if (it == nodes.index_of_tag.end())
          throw InputError(source, "triangle " + std::to_string(element_tags[t]) + " of surface '" + groups[id].name +
                                       "' uses a node of no tetrahedron");
        v[k] = it->second;
      }
      auto face = face_of_key.find(face_key(v[0], v[1], v[2]));
      if (face == face_of_key.end())
        throw InputError(source, "triangle " + std::to_string(element_tags[t]) + " of surface '" + groups[id].name +
                                     "' is not a face of any tetrahedron");
      const int cell = face->second / 4;
      const int* local = kOutwardTetFaces[face->second % 4];
      std::array<int, 6> face_nodes{};
      for (int k = 0; k < tri_nodes; ++k) face_nodes[k] = cells(cell, local[k]);
      out.nodes.push_back(face_nodes);
      out.region.push_back(static_cast<int>(id));
    }
  }
  return out;
}

// Checks the file can be opened and is a .msh of format 4.x.
void check_msh_header(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot open the mesh file (missing or unreadable)");
  std::string first_line;
  double version = 0.0;
  std::getline(in, first_line);
  if (first_line.rfind("$MeshFormat", 0) != 0 || !(in >> version))
    throw InputError(path, "not a gmsh .msh file (no $MeshFormat header)");
  if (version < 4.0 || version >= 5.0) {
    std::ostringstream s;
    s << "gmsh .msh format " << version << " is not supported; save as format 4.1";
    throw InputError(path, s.str());
  }
}

}  // namespace

namespace {
void start_gmsh() {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 2);
  gmsh::option::setNumber("General.NumThreads", 1);
}
}  // namespace

ScopedGmshModel::ScopedGmshModel(const std::string& name) {
  initialize_gmsh();
  gmsh::model::add(name);
}

ScopedGmshModel::~ScopedGmshModel() { gmsh::model::remove(); }

namespace {
// gmsh 4.8's boundary recovery (tetgen) can also fail an assert() and abort the process,
// e.g. for the laminate whose 8 mm strip chambers end flush with the 5 mm end seals.
// An abort cannot be caught: while the mesher runs, a SIGABRT handler writes a message
// prepared beforehand (write(2) and _exit(2) are async-signal-safe) and exits with 2,
// the exit code of bad input, instead of a core dump and a backtrace.
std::string mesher_abort_message;
extern "C" void report_mesher_abort(int) {
  const ssize_t written = write(STDERR_FILENO, mesher_abort_message.data(), mesher_abort_message.size());
  (void)written;
  _exit(2);
}
class MesherAbortReport {
 public:
  explicit MesherAbortReport(const std::string& message) {
    mesher_abort_message = "\nmorphfem: " + message + "\n";
    struct sigaction action {};
    action.sa_handler = report_mesher_abort;
    sigemptyset(&action.sa_mask);
    sigaction(SIGABRT, &action, &previous_);
  }
  ~MesherAbortReport() { sigaction(SIGABRT, &previous_, nullptr); }
  MesherAbortReport(const MesherAbortReport&) = delete;
  MesherAbortReport& operator=(const MesherAbortReport&) = delete;

 private:
  struct sigaction previous_ {};
};
}  // namespace

void generate_tet_mesh(double mesh_size, int order, const std::string& where, const std::vector<VolumeSize>& refine) {
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0.0);
  gmsh::option::setNumber("Mesh.MeshSizeMax", mesh_size);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.ElementOrder", order);
  gmsh::option::setNumber("Mesh.SecondOrderLinear", 0);  // curved P2 mid-nodes
  gmsh::option::setNumber("Mesh.HighOrderOptimize", 0);
  gmsh::option::setNumber("Mesh.Algorithm3D", 1);  // Delaunay: deterministic, single-threaded
  gmsh::vectorpair points;
  gmsh::model::getEntities(points, 0);
  gmsh::model::mesh::setSize(points, mesh_size);
  for (const VolumeSize& r : refine) {
    gmsh::vectorpair volumes, boundary_points;
    for (int tag : r.volumes) volumes.emplace_back(3, tag);
    gmsh::model::getBoundary(volumes, boundary_points, false, false, true);
    gmsh::vectorpair corner_points;
    for (const auto& p : boundary_points)
      if (p.first == 0) corner_points.push_back(p);
    gmsh::model::mesh::setSize(corner_points, r.size);
  }
  // gmsh 4.8 throws std::string from inside its 3-D mesher for some sizes on thin
  // layers (e.g. "Could not recover boundary mesh: error 2" for the physical laminate
  // with foot pads at 7.5 mm).
  std::ostringstream size_text;
  size_text << mesh_size;
  const std::string size = size_text.str();
  auto refuse = [&](const std::string& what) {
    throw InputError(where, "gmsh could not mesh the geometry at mesh_size " + size + " m (gmsh: " + what +
                                "); a slightly different mesh_size usually meshes");
  };
  // A mesher that threw leaves gmsh's global state broken (the next model in the same
  // process then comes out with unmeshed surfaces): restart gmsh before reporting, with
  // an empty current model for the caller's ScopedGmshModel to remove.
  auto restart = [] {
    gmsh::finalize();
    start_gmsh();
    gmsh::model::add("morphfem_after_mesher_failure");
  };
  try {
    const MesherAbortReport report(where + ": gmsh aborted while meshing the geometry at mesh_size " + size +
                                   " m (an internal assertion, above); a slightly different mesh_size or "
                                   "geometry usually meshes");
    gmsh::model::mesh::generate(3);
  } catch (const std::string& e) {
    restart();
    refuse(e);
  } catch (const std::exception& e) {
    restart();
    refuse(e.what());
  }
}

void initialize_gmsh() {
  static std::once_flag once;
  std::call_once(once, start_gmsh);
}

Mesh mesh_from_current_gmsh_model(const std::string& source) {
  const GmshTetrahedra tets = read_gmsh_tetrahedra(source);
  const std::vector<PhysicalGroup> groups = physical_groups(source);
  const CompactNodes nodes = compact_nodes(tets.node_tags, source);

  Mesh mesh;
  mesh.order = tets.order;
  mesh.X = nodes.X;
  mesh.cells = vtk_cells(tets, nodes);
  mesh.cell_region = cell_regions(groups, tets, source);
  for (std::size_t id = 0; id < groups.size(); ++id)
    mesh.regions.push_back(Region{groups[id].name, groups[id].dim, static_cast<int>(id)});

  const Faces faces = surface_faces(groups, mesh.cells, mesh.order, nodes, source);
  mesh.faces.resize(static_cast<Eigen::Index>(faces.nodes.size()), mesh.nodes_per_face());
  for (std::size_t f = 0; f < faces.nodes.size(); ++f)
    for (int k = 0; k < mesh.nodes_per_face(); ++k) mesh.faces(f, k) = faces.nodes[f][k];
  mesh.face_region = faces.region;
  validate_mesh(mesh, source);
  return mesh;
}

Mesh read_msh(const std::string& path) {
  check_msh_header(path);
  ScopedGmshModel model("morphfem_read_msh");
  gmsh::merge(path);
  return mesh_from_current_gmsh_model(path);
}

namespace {

// Node tags 1..n; element tags numbered consecutively over all regions from 1.
void add_region_entities(const Mesh& mesh) {
  const int tet_type = mesh.order == 1 ? kGmshTetrahedron4 : kGmshTetrahedron10;
  const int tri_type = mesh.order == 1 ? kGmshTriangle3 : kGmshTriangle6;
  std::size_t next_element = 1;
  bool nodes_added = false;
  for (const Region& region : mesh.regions) {
    const int entity = gmsh::model::addDiscreteEntity(region.dim);
    if (!nodes_added && region.dim == 3) {
      // All nodes are classified on the first volume entity.
      std::vector<std::size_t> tags(mesh.n_nodes());
      std::iota(tags.begin(), tags.end(), std::size_t{1});
      std::vector<double> coords(mesh.X.data(), mesh.X.data() + mesh.X.size());
      gmsh::model::mesh::addNodes(3, entity, tags, coords);
      nodes_added = true;
    }
    std::vector<std::size_t> element_tags, node_tags;
    if (region.dim == 3) {
      for (int c = 0; c < mesh.n_cells(); ++c) {
        if (mesh.cell_region[c] != region.id) continue;
        element_tags.push_back(next_element++);
        for (int k = 0; k < mesh.nodes_per_cell(); ++k)
          node_tags.push_back(mesh.cells(c, mesh.order == 2 ? kGmshToVtkTet10[k] : k) + 1);
      }
    } else {
      for (int f = 0; f < mesh.n_faces(); ++f) {
        if (mesh.face_region[f] != region.id) continue;
        element_tags.push_back(next_element++);
        for (int k = 0; k < mesh.nodes_per_face(); ++k) node_tags.push_back(mesh.faces(f, k) + 1);
      }
    }
    if (!element_tags.empty())
      gmsh::model::mesh::addElementsByType(entity, region.dim == 3 ? tet_type : tri_type, element_tags, node_tags);
    const int group = gmsh::model::addPhysicalGroup(region.dim, {entity});
    gmsh::model::setPhysicalName(region.dim, group, region.name);
  }
}

}  // namespace

void write_msh(const Mesh& mesh, const std::string& path) {
  validate_mesh(mesh, path);
  ScopedGmshModel model("morphfem_write_msh");
  add_region_entities(mesh);
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::option::setNumber("Mesh.Binary", 0);
  gmsh::option::setNumber("Mesh.SaveAll", 0);
  gmsh::write(path);
  if (!std::ifstream(path)) throw InputError(path, "could not write the mesh file");
}

}  // namespace morphfem
