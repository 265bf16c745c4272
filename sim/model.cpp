#include "sim/model.h"

#include <algorithm>

#include "core/errors.h"
#include "core/strings.h"
#include "mesh/geometry.h"
#include "sim/broadcast.h"
#include "sim/cadence.h"
#include "sim/terms.h"

namespace morphfem {

namespace {

// Rank 0 builds (gmsh is not run in parallel); everyone receives the same mesh.
// An InputError on rank 0 is re-thrown on every rank.
Mesh build_on_root(const Scene& scene, MPI_Comm comm) {
  int rank;
  MPI_Comm_rank(comm, &rank);
  Mesh mesh;
  std::string error, where;
  if (rank == 0) {
    try {
      mesh = scene.mesh_file.empty() ? build_geometry(scene.geometry) : read_msh(scene.mesh_file);
    } catch (const InputError& e) {
      error = e.what();
      where = e.where();
    }
  }
  bcast_string(error, comm);
  if (!error.empty()) {
    bcast_string(where, comm);
    // e.what() already includes `where`; keep the message as it is.
    throw InputError("", error);
  }
  MPI_Bcast(&mesh.order, 1, MPI_INT, 0, comm);
  bcast_matrix(mesh.X, MPI_DOUBLE, comm);
  bcast_matrix(mesh.cells, MPI_INT, comm);
  bcast_matrix(mesh.faces, MPI_INT, comm);
  bcast_ints(mesh.cell_region, comm);
  bcast_ints(mesh.face_region, comm);
  long n_regions = static_cast<long>(mesh.regions.size());
  MPI_Bcast(&n_regions, 1, MPI_LONG, 0, comm);
  mesh.regions.resize(n_regions);
  for (auto& region : mesh.regions) {
    bcast_string(region.name, comm);
    MPI_Bcast(&region.dim, 1, MPI_INT, 0, comm);
    MPI_Bcast(&region.id, 1, MPI_INT, 0, comm);
  }
  return mesh;
}

// Each volume region's material and density, and the body's mass.
void read_materials(Model& model) {
  const Scene& scene = model.scene;
  const Mesh& mesh = model.mesh;
  model.materials.assign(mesh.regions.size(), nullptr);
  model.density.assign(mesh.regions.size(), 0.0);
  for (const auto& [region, params] : scene.materials) {
    const int id = mesh.region(region, 3).id;
    model.materials[id] = make_material(params.without("density"));
    model.density[id] = params.number_in("density", 0.0, 1e5, 0.0);
    if (scene.gravity.norm() > 0 && model.density[id] <= 0)
      throw InputError(params.where("model"), "gravity is on but material '" + region + "' has no 'density' [kg/m^3]");
  }
  for (int c = 0; c < mesh.n_cells(); ++c) model.mass_kg += model.density[mesh.cell_region[c]] * mesh.cell_volume(c);
}

// The scene's boundary displacements: a field of (X, t), or a displacement reached
// linearly at the end time.
std::vector<DirichletCondition> boundary_conditions(const Scene& scene, const Mesh& mesh) {
  std::vector<DirichletCondition> bcs;
  const double t_end = scene.solver.t_end;
  for (const auto& b : scene.boundary) {
    DirichletCondition bc;
    bc.name = b.surface;
    bc.nodes = mesh.nodes_of_surface(b.surface);
    bc.components = b.components;
    const Eigen::Vector3d d = b.displacement;
    if (b.field)
      bc.value = b.field;
    else
      bc.value = [d, t_end](const Eigen::Vector3d&, double t) { return Eigen::Vector3d(d * std::min(1.0, t / t_end)); };
    bcs.push_back(bc);
  }
  return bcs;
}

// A dynamic scene's time integrator starts at the scene's initial velocity.
void start_inertia(Model& model) {
  if (!model.inertia) return;
  const Eigen::Vector3d v0 = model.scene.dynamics->initial_velocity;  // inertia only with dynamics
  model.integrator->set_initial_velocity([v0](const Eigen::Vector3d&) { return v0; });
  model.inertia->initialize(*model.assembler, model.solver->solution(), 0.0);
}

}  // namespace

Model::Model(const Scene& scene, Mesh& mesh, MPI_Comm comm) : scene(scene), mesh(mesh), comm(comm) {
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (scene.dynamics) integrator = std::make_shared<TimeIntegrator>(scene.dynamics->inertia);
}

std::string scene_key(const Scene& scene, const std::string& where, const std::string& key) {
  if (!where.empty()) return where;
  return (scene.source.empty() ? scene.name : scene.source) + ": " + key;
}

void require_surface(const Scene& scene, const Mesh& mesh, const std::string& name, const std::string& where,
                     const std::string& key) {
  if (!mesh.has_region(name, 2)) {
    throw InputError(scene_key(scene, where, key), "the mesh has no surface region '" + name +
                                                       "' (it has: " + join(mesh.region_names(2), ", ") + ")");
  }
}

Mesh build_scene_mesh(const Scene& scene, MPI_Comm comm) {
  Mesh mesh = build_on_root(scene, comm);
  const std::string src = scene.source.empty() ? scene.name : scene.source;
  for (const auto& [region, params] : scene.materials)
    if (!mesh.has_region(region, 3))
      throw InputError(params.where("model"), "the mesh has no volume region '" + region +
                                                  "' (it has: " + join(mesh.region_names(3), ", ") + ")");
  for (const auto& name : mesh.region_names(3))
    if (!scene.materials.count(name))
      throw InputError(src + ": materials", "no material for volume region '" + name + "'");
  for (const auto& b : scene.boundary) require_surface(scene, mesh, b.surface, b.where, "boundary");
  for (const auto& m : scene.membranes) require_surface(scene, mesh, m.surface, m.where, "membranes");
  for (const auto& c : scene.cavities)
    for (const auto& s : c.surfaces) require_surface(scene, mesh, s, "", "loads.cavities." + c.name);
  for (const auto& t : scene.tractions) require_surface(scene, mesh, t.surface, t.where, "loads.tractions");
  for (const auto& p : scene.pulls) require_surface(scene, mesh, p.surface, p.where, "loads.pulls");
  for (const auto& c : scene.gas_cavities)
    for (const auto& s : c.wall.surfaces) require_surface(scene, mesh, s, "", "loads.gas_cavities." + c.wall.name);
  for (const auto& c : scene.volume_cavities)
    for (const auto& s : c.wall.surfaces) require_surface(scene, mesh, s, "", "loads.volume_cavities." + c.wall.name);
  if (scene.ground)
    for (const auto& surface : scene.ground->surfaces)
      require_surface(scene, mesh, surface, "", "contact.ground.surfaces");
  if (scene.friction)
    for (const auto& region : scene.friction->regions)
      require_surface(scene, mesh, region.surface, "", "contact.friction.regions");
  if (scene.self_contact)
    for (const auto& [first, second] : scene.self_contact->pairs)
      for (const auto& surface : {first, second}) require_surface(scene, mesh, surface, "", "contact.self.pairs");
  return mesh;
}

std::unique_ptr<Model> build_model(const Scene& scene, Mesh& mesh, MPI_Comm comm) {
  auto model = std::make_unique<Model>(scene, mesh, comm);
  read_materials(*model);
  model->partition = partition_mesh(mesh, model->size);
  model->assembler = std::make_unique<Assembler>(mesh, model->partition, comm);
  model->schedule_clock = make_schedule_clock(scene);
  for (const NamedTermBuilder& builder : term_builders()) builder.build(scene, *model);
  watch_valves(*model);
  model->solver =
      std::make_unique<IncrementalSolver>(*model->assembler, boundary_conditions(scene, mesh), scene.solver);
  start_inertia(*model);
  return model;
}

}  // namespace morphfem
