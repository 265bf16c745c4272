#include "sim/simulation.h"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "actuation/cavity.h"
#include "actuation/voxel_growth.h"
#include "contact/friction.h"
#include "contact/ground.h"
#include "contact/lattice_floor.h"
#include "contact/self_contact.h"
#include "core/errors.h"
#include "core/json.h"
#include "core/plot.h"
#include "core/progress.h"
#include "core/state_file.h"
#include "core/strings.h"
#include "fem/damping.h"
#include "fem/elastic.h"
#include "fem/inertia.h"
#include "fem/loads.h"
#include "fem/material.h"
#include "fem/output.h"
#include "fem/pull_spring.h"
#include "mesh/geometry.h"
#include "mesh/robot.h"

namespace morphfem {

namespace {

template <class Matrix>
void bcast_matrix(Matrix& m, MPI_Datatype type, MPI_Comm comm) {
  long dims[2] = {static_cast<long>(m.rows()), static_cast<long>(m.cols())};
  MPI_Bcast(dims, 2, MPI_LONG, 0, comm);
  m.resize(dims[0], dims[1]);
  MPI_Bcast(m.data(), static_cast<int>(m.size()), type, 0, comm);
}

void bcast_ints(std::vector<int>& v, MPI_Comm comm) {
  long n = static_cast<long>(v.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, comm);
  v.resize(n);
  MPI_Bcast(v.data(), static_cast<int>(n), MPI_INT, 0, comm);
}

void bcast_string(std::string& s, MPI_Comm comm) {
  long n = static_cast<long>(s.size());
  MPI_Bcast(&n, 1, MPI_LONG, 0, comm);
  s.resize(n);
  MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, 0, comm);
}

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

// Thrown by the step callback to stop a run as a kill would (RunOptions::stop_after_steps).
struct StopRun {};

// The directory whose checkpoint a resumed run continues from: the interrupted
// run's partial output, else a finished run's output. Rank 0 only.
std::string checkpoint_to_resume(const Scene& scene) {
  namespace fs = std::filesystem;
  const std::string partial = scene.output_dir + ".partial";
  if (fs::exists(partial + "/checkpoint.h5")) return partial;
  if (fs::exists(scene.output_dir + "/checkpoint.h5")) return scene.output_dir;
  throw InputError("--resume", "no checkpoint in " + partial + "/ (an interrupted run) or " + scene.output_dir +
                                   "/ (a finished one); run without --resume first");
}

// First line where two texts differ (for "the scene differs from the checkpoint's").
std::string first_difference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ga = static_cast<bool>(std::getline(sa, la)), gb = static_cast<bool>(std::getline(sb, lb));
    if (!ga && !gb) return "";
    if (!ga || !gb || la != lb)
      return "line " + std::to_string(line) + ": checkpoint '" + (ga ? la : "") + "', now '" + (gb ? lb : "") + "'";
  }
}

// A resumed run's checkpoint: its directory, its file (`where`, for messages) and its state.
struct ResumePoint {
  std::string dir, where;
  StateRecord state;
};

// Finds and reads the checkpoint on rank 0, sends it to every rank and checks it
// against this run: the rank count, the mesh, the scene (but the keys
// scene_identity drops) and an end time still ahead. Collective.
ResumePoint read_checkpoint_to_resume(const Scene& scene, const Mesh& mesh, const std::string& scene_text, double t_end,
                                      MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  ResumePoint point;
  std::string error;
  if (rank == 0) {
    try {
      point.dir = checkpoint_to_resume(scene);
      point.state = read_state_file(point.dir + "/checkpoint.h5");
    } catch (const InputError& e) {
      error = e.what();
    }
  }
  bcast_string(error, comm);
  if (!error.empty()) throw InputError("", error);
  bcast_string(point.dir, comm);
  broadcast_state(point.state, comm);
  point.where = point.dir + "/checkpoint.h5";
  const StateRecord& saved = point.state;
  const std::string& where = point.where;
  const long ranks = saved.integer("run.ranks", where);
  if (ranks != size)
    throw InputError(where, "written by a run on " + std::to_string(ranks) +
                                " ranks; resume it with the same number (mpirun -n " + std::to_string(ranks) + ")");
  const long nodes = saved.integer("run.nodes", where), cells = saved.integer("run.cells", where);
  if (nodes != mesh.n_nodes() || cells != mesh.n_cells())
    throw InputError(where, "its mesh has " + std::to_string(nodes) + " nodes and " + std::to_string(cells) +
                                " cells, this scene's " + std::to_string(mesh.n_nodes()) + " and " +
                                std::to_string(mesh.n_cells()));
  const std::string diff = first_difference(saved.text("run.scene", where), scene_text);
  if (!diff.empty())
    throw InputError(
        where,
        "the scene differs from the checkpoint's (only solver.end_time and output.checkpoint_s may change): " + diff);
  const double t_saved = saved.number("solver.t", where);
  if (!(t_saved < t_end - 1e-12 * std::max(1.0, t_end)))
    throw InputError(where, "the checkpoint is at t = " + std::to_string(t_saved) +
                                " s; set a later solver.end_time (now " + std::to_string(t_end) + " s) to extend it");
  return point;
}

// Extending a finished run: its output is copied to the partial directory, which
// replaces it when this run ends (the finished results stay until then). Collective.
void reopen_finished_output(const Scene& scene, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::string error;
  if (rank == 0) {
    namespace fs = std::filesystem;
    const std::string partial = scene.output_dir + ".partial";
    std::error_code ec;
    fs::remove_all(partial, ec);
    fs::copy(scene.output_dir, partial, fs::copy_options::recursive, ec);
    if (ec) error = "cannot copy " + scene.output_dir + " to " + partial + ": " + ec.message();
  }
  bcast_string(error, comm);
  if (!error.empty()) throw InputError("--resume", error);
}

}  // namespace

// The lattice voxels of a robot_voxel scene as floor-contact points: the material
// point at each box's centre (interpolated in its region's cells), the box's
// footprint as area, the sphere radius L (s_x + s_y + s_z)/6 with s = base scale x
// the region's growth stretch (actuation.growth), and the region's friction
// coefficient, or a foot's mu(t) for skin voxels over that foot's y range.
std::vector<LatticePoint> lattice_points(const Scene& scene, const Mesh& mesh) {
  const std::string key = scene_key(scene, "", "contact.lattice_floor");
  if (scene.geometry.string("type", "") != "robot_voxel")
    throw InputError(key, "needs geometry.type robot_voxel (the lattice is the voxel study's)");
  const LatticeFloorScene& spec = scene.lattice_floor_spec;
  for (const auto& [region, value] : spec.mu)
    if (!mesh.has_region(region, 3)) throw InputError(key + ".mu", "the mesh has no volume region '" + region + "'");
  const double voxel = spec.voxel_size;
  std::map<std::string, std::function<Eigen::Vector3d(double)>> growth;
  for (const auto& [region, stretch] : scene.growth) growth[region] = stretch;
  std::vector<std::pair<std::pair<double, double>, TimeFunction>> foot_ranges;  // y range [m] -> mu(t)
  for (const auto& [surface, mu] : spec.feet) {
    require_surface(scene, mesh, surface, "", "actuation.feet");
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int a : mesh.nodes_of_surface(surface)) {
      lo = std::min(lo, mesh.X(a, 1));
      hi = std::max(hi, mesh.X(a, 1));
    }
    foot_ranges.push_back({{lo, hi}, mu});
  }
  if (spec.gap_foot_columns && !spec.gap_foot_mu)
    throw InputError(key + ".gap_foot_columns", "needs actuation.feet (foot_a, foot_b) with growth actuation");
  const std::vector<LatticeVoxelBox> boxes = robot_voxel_lattice(scene.geometry, voxel, VoxelActuation{}.min_scale);
  // A skin column holds a bladder if its centre lies in some bladder box's x range.
  const auto under_bladder = [&boxes](double x) {
    for (const LatticeVoxelBox& b : boxes)
      if (b.region != "skin" && x > b.lo.x() && x < b.hi.x()) return true;
    return false;
  };
  std::map<std::string, CellLocator> locators;  // per volume region
  std::vector<LatticePoint> points;
  for (const LatticeVoxelBox& box : boxes) {
    const auto mu = spec.mu.find(box.region);
    if (mu == spec.mu.end())
      throw InputError(key + ".mu", "no friction coefficient for volume region '" + box.region + "'");
    auto locator = locators.find(box.region);
    if (locator == locators.end()) locator = locators.try_emplace(box.region, mesh, mesh.cells_of(box.region)).first;
    LatticePoint p;
    p.owner_cell = locator->second.weights(0.5 * (box.lo + box.hi), p.nodes, p.weights);
    p.area = (box.hi.x() - box.lo.x()) * (box.hi.y() - box.lo.y());
    p.mu = TimeFunction::constant(mu->second);
    const double y = 0.5 * (box.lo.y() + box.hi.y());
    Eigen::Vector3d base = box.base_scale;
    if (box.region == "skin")
      for (const auto& [range, foot_mu] : foot_ranges)
        if (y >= range.first && y <= range.second) {
          p.mu = foot_mu;
          if (spec.gap_foot_columns && !under_bladder(0.5 * (box.lo.x() + box.hi.x()))) {
            p.mu = *spec.gap_foot_mu;
            base.x() *= kVoxelGapFootScaleX;
          }
        }
    const auto g = growth.find(box.region);
    if (g == growth.end())
      p.radius = [r = voxel * base.sum() / 6.0](double) { return r; };
    else
      p.radius = [voxel, base, stretch = g->second](double t) {
        return voxel * base.cwiseProduct(stretch(t)).sum() / 6.0;
      };
    points.push_back(std::move(p));
  }
  return points;
}

std::string scene_identity(const YAML::Node& doc) {
  YAML::Node copy = YAML::Clone(doc);
  // Neither changes the steps: how far the run goes, how often it checkpoints.
  if (copy["solver"] && copy["solver"].IsMap() && copy["solver"]["end_time"]) copy["solver"].remove("end_time");
  if (copy["output"] && copy["output"].IsMap() && copy["output"]["checkpoint_s"]) copy["output"].remove("checkpoint_s");
  YAML::Emitter out;
  out << copy;
  return out.c_str();
}

double contact_shear_modulus(const Mesh& mesh, const std::vector<std::shared_ptr<const Material>>& materials,
                             const std::vector<std::string>& surfaces) {
  // Cell faces by their sorted vertex triple -> the cell's region.
  std::map<std::array<int, 3>, int> face_region;
  static constexpr int kFace[4][3] = {{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}};
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (const auto& f : kFace) {
      std::array<int, 3> key{mesh.cells(c, f[0]), mesh.cells(c, f[1]), mesh.cells(c, f[2])};
      std::sort(key.begin(), key.end());
      face_region[key] = mesh.cell_region[c];
    }
  std::vector<double> area(mesh.regions.size(), 0.0);
  for (const auto& s : surfaces)
    for (int f : mesh.faces_of(s)) {
      std::array<int, 3> key{mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)};
      const Eigen::Vector3d x0 = mesh.X.row(key[0]), x1 = mesh.X.row(key[1]), x2 = mesh.X.row(key[2]);
      std::sort(key.begin(), key.end());
      const auto it = face_region.find(key);
      if (it != face_region.end()) area[it->second] += 0.5 * (x1 - x0).cross(x2 - x0).norm();
    }
  const auto most = std::max_element(area.begin(), area.end()) - area.begin();
  return area[most] > 0 && materials[most] ? materials[most]->shear_modulus() : 0.0;
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
  if (scene.ground_contact)
    for (const auto& surface : scene.ground.surfaces)
      require_surface(scene, mesh, surface, "", "contact.ground.surfaces");
  if (scene.friction)
    for (const auto& region : scene.friction_spec.regions)
      require_surface(scene, mesh, region.surface, "", "contact.friction.regions");
  if (scene.self_contact)
    for (const auto& [first, second] : scene.self_contact_spec.pairs)
      for (const auto& surface : {first, second}) require_surface(scene, mesh, surface, "", "contact.self.pairs");
  return mesh;
}

SimulationResult run_scene(const Scene& scene, MPI_Comm comm, const RunOptions& options) {
  int rank, size;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  auto start = std::chrono::steady_clock::now();

  // ---- Everything that can be wrong with the input is checked before any output.
  SimulationResult result;
  result.mesh = build_scene_mesh(scene, comm);
  Mesh& mesh = result.mesh;
  std::vector<std::shared_ptr<const Material>> materials(mesh.regions.size());
  std::vector<double> density(mesh.regions.size(), 0.0);
  for (const auto& [region, params] : scene.materials) {
    const int id = mesh.region(region, 3).id;
    materials[id] = make_material(params.without("density"));
    density[id] = params.number_in("density", 0.0, 1e5, 0.0);
    if (scene.gravity.norm() > 0 && density[id] <= 0)
      throw InputError(params.where("model"), "gravity is on but material '" + region + "' has no 'density' [kg/m^3]");
  }
  for (int c = 0; c < mesh.n_cells(); ++c) result.mass_kg += density[mesh.cell_region[c]] * mesh.cell_volume(c);
  Partition partition = partition_mesh(mesh, size);

  Assembler assembler(mesh, partition, comm);
  const auto formulation = elastic_formulations().find(scene.formulation);
  if (formulation == elastic_formulations().end())
    throw InputError(scene_key(scene, "", "solver.formulation"), "unknown formulation '" + scene.formulation + "'");
  auto elastic = formulation->second(mesh, partition, rank, materials, scene.quadrature_degree);
  for (const auto& [region, stretch] : scene.growth) {
    if (!mesh.has_region(region, 3))
      throw InputError(scene_key(scene, "", "actuation.growth"), "the mesh has no volume region '" + region + "'");
    try {
      elastic->set_growth(mesh.region(region, 3).id, stretch);
    } catch (const std::invalid_argument& e) {
      throw InputError(scene_key(scene, "", "actuation.growth"), e.what());
    }
  }
  assembler.add_term(elastic);
  for (const auto& spec : scene.membranes)
    assembler.add_term(std::make_shared<MembraneTerm>(mesh, partition, rank, spec));
  if (scene.gravity.norm() > 0) {
    // Gravity is a body force rho g [N/m^3]; rho depends on the cell's region, so
    // one term per region keeps the kernel a pure function of X.
    for (size_t id = 0; id < mesh.regions.size(); ++id) {
      if (mesh.regions[id].dim != 3 || density[id] <= 0) continue;
      const Eigen::Vector3d body = density[id] * scene.gravity;
      std::function<Eigen::Vector3d(double)> stretch;
      if (scene.weightless_inflated)
        for (const auto& [region, g] : scene.growth)
          if (region == mesh.regions[id].name) stretch = g;
      VectorField field = [body](const Eigen::Vector3d&, double) { return body; };
      if (stretch)  // the lattice's inflated bladder voxels: no weight while g_z > 1
        field = [body, stretch](const Eigen::Vector3d&, double t) -> Eigen::Vector3d {
          return stretch(t).z() > 1.0 + 1e-9 ? Eigen::Vector3d::Zero() : body;
        };
      assembler.add_term(std::make_shared<BodyForceTerm>(mesh, partition, rank, mesh.cells_of(mesh.regions[id].name),
                                                         field, 2 * mesh.order));
    }
  }
  if (scene.body_force) {
    std::vector<int> all_cells(mesh.n_cells());
    for (int c = 0; c < mesh.n_cells(); ++c) all_cells[c] = c;
    assembler.add_term(
        std::make_shared<BodyForceTerm>(mesh, partition, rank, all_cells, scene.body_force, scene.body_force_degree));
  }
  std::vector<std::shared_ptr<CavityPressureTerm>> cavities;
  for (const auto& spec : scene.cavities) {
    cavities.push_back(std::make_shared<CavityPressureTerm>(mesh, partition, rank, spec));
    assembler.add_term(cavities.back());
  }
  // Cavities whose pressure follows from their volume: gas-filled, then volume-controlled.
  std::vector<std::shared_ptr<CavityVolumeTerm>> volume_driven;
  for (const auto& spec : scene.gas_cavities)
    volume_driven.push_back(std::make_shared<GasCavityTerm>(mesh, partition, rank, spec));
  for (const auto& spec : scene.volume_cavities)
    volume_driven.push_back(std::make_shared<VolumeControlledCavityTerm>(mesh, partition, rank, spec));
  for (const auto& c : volume_driven) assembler.add_term(c);
  for (const auto& t : scene.tractions) {
    const Eigen::Vector3d traction = t.traction;
    const TimeFunction scale = t.scale;
    assembler.add_term(std::make_shared<SurfaceLoadTerm>(
        mesh, partition, rank, mesh.faces_of(t.surface),
        [traction, scale](const Eigen::Vector3d&, double time) { return Eigen::Vector3d(scale(time) * traction); }));
  }
  std::vector<std::shared_ptr<PullSpringTerm>> pulls;  // test-machine pull springs, only if declared
  for (const auto& spec : scene.pulls) {
    pulls.push_back(std::make_shared<PullSpringTerm>(mesh, rank, spec));
    assembler.add_term(pulls.back());
  }
  // Dynamics: inertia (and viscous damping) only when the scene asks for them.
  std::shared_ptr<InertiaTerm> inertia;
  std::shared_ptr<DampingTerm> damping;
  if (scene.dynamic) {
    for (const auto& [region, params] : scene.materials)
      if (density[mesh.region(region, 3).id] <= 0)
        throw InputError(params.where("model"), "dynamics needs 'density' [kg/m^3] for material '" + region + "'");
    inertia = std::make_shared<InertiaTerm>(mesh, partition, rank, density, scene.inertia);
    assembler.add_term(inertia);
    if (scene.shear_viscosity > 0 || scene.bulk_viscosity > 0) {
      std::vector<double> eta(mesh.regions.size(), scene.shear_viscosity),
          zeta(mesh.regions.size(), scene.bulk_viscosity);
      damping = std::make_shared<DampingTerm>(mesh, partition, rank, eta, zeta, scene.inertia.scheme);
      assembler.add_term(damping);
    }
  }
  // Ground contact and friction only on the declared surfaces.
  std::shared_ptr<GroundContactTerm> ground;
  std::shared_ptr<FrictionTerm> friction;
  if (scene.ground_contact) {
    GroundContactSpec spec = scene.ground;
    // nearly incompressible: E = 2 mu (1 + nu) ~ 3 mu
    spec.young_modulus = 3.0 * contact_shear_modulus(mesh, materials, spec.surfaces);
    ground = std::make_shared<GroundContactTerm>(mesh, partition, rank, spec);
    assembler.add_term(ground);
    if (scene.friction) {
      friction = std::make_shared<FrictionTerm>(mesh, partition, rank, ground, scene.friction_spec);
      assembler.add_term(friction);
    }
  }
  // Self-contact only between the declared surface pairs.
  std::shared_ptr<SelfContactTerm> self_contact;
  if (scene.self_contact) {
    SelfContactSpec spec = scene.self_contact_spec;
    std::vector<std::string> surfaces;
    for (const auto& [a, b] : spec.pairs) surfaces.insert(surfaces.end(), {a, b});
    spec.young_modulus = 3.0 * contact_shear_modulus(mesh, materials, surfaces);  // as for the ground
    self_contact = std::make_shared<SelfContactTerm>(mesh, partition, rank, spec);
    assembler.add_term(self_contact);
  }
  // The voxel lattice's floor contact (a diagnostic): a sphere per lattice voxel.
  if (scene.lattice_floor)
    assembler.add_term(std::make_shared<LatticeFloorTerm>(mesh, partition, rank, scene.lattice_floor_spec.floor,
                                                          lattice_points(scene, mesh)));
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
  SolverOptions solver_options = scene.solver;
  QuasiStaticSolver solver(assembler, bcs, solver_options);
  if (inertia) {
    const Eigen::Vector3d v0 = scene.initial_velocity;
    inertia->set_initial_velocity([v0](const Eigen::Vector3d&) { return v0; });
    inertia->initialize(assembler, solver.solution(), 0.0);
  }
  result.dofs = assembler.n_dofs();
  for (const auto& c : cavities) result.cavity_names.push_back(c->spec().name);
  for (const auto& c : volume_driven) result.cavity_names.push_back(c->wall().name);

  // ---- Output (rank 0 writes; every rank takes part in the gathers).
  const bool write = options.write_output && !scene.output_dir.empty();
  if (options.resume && !write)
    throw InputError(scene_key(scene, "", "output.directory"), "--resume needs the scene's output directory");
  // Resuming: the checkpoint, checked against this run, and the solver's state from it.
  ResumePoint checkpoint;
  double wall_before = 0.0;  // wall time of the earlier parts of a resumed run [s]
  if (options.resume) {
    checkpoint = read_checkpoint_to_resume(scene, mesh, options.scene_text, t_end, comm);
    result.stats = solver.load_state(checkpoint.state, checkpoint.where);
    result.resumed_at = checkpoint.state.number("solver.t", checkpoint.where);
    wall_before = checkpoint.state.number("run.wall_s", checkpoint.where);
    if (checkpoint.dir == scene.output_dir) reopen_finished_output(scene, comm);
  }
  std::string tmp_dir;
  std::unique_ptr<ResultWriter> writer;
  if (write && rank == 0) {
    if (options.resume) {
      tmp_dir = scene.output_dir + ".partial";
      writer = std::make_unique<ResultWriter>(tmp_dir, scene.name, mesh, result.resumed_at);
    } else {
      tmp_dir = temporary_output_dir(scene.output_dir);
      writer = std::make_unique<ResultWriter>(tmp_dir, scene.name, mesh);
    }
    if (!options.scene_file.empty()) write_file_atomic(tmp_dir + "/scene.yaml", options.scene_file);
  }
  std::vector<std::string> cavity_columns{"time"};
  for (const auto& c : cavities) {
    cavity_columns.push_back(c->spec().name + "_pressure_Pa");
    cavity_columns.push_back(c->spec().name + "_volume_m3");
  }
  for (const auto& c : volume_driven) {
    cavity_columns.push_back(c->wall().name + "_pressure_Pa");
    cavity_columns.push_back(c->wall().name + "_volume_m3");
    cavity_columns.push_back(c->wall().name + "_" + c->state_column());
  }
  std::vector<std::string> pull_columns{"time"};
  for (const auto& p : pulls) {
    pull_columns.push_back(p->spec().surface + "_force_N");
    pull_columns.push_back(p->spec().surface + "_crosshead_m");
    pull_columns.push_back(p->spec().surface + "_mean_position_m");
  }
  std::vector<double> pull_force(pulls.size(), 0.0);  // last recorded [N]
  std::vector<std::string> energy_columns{"time"};
  for (const auto& term : assembler.terms()) energy_columns.push_back(term->name() + "_J");
  if (inertia) energy_columns.push_back("kinetic_J");
  if (friction) energy_columns.push_back("friction_dissipated_J");
  if (damping) energy_columns.push_back("damping_dissipated_J");
  double friction_dissipated = 0.0;

  // Gait: mean node position (the voxel study's "mean vertex") along the heading.
  const double body_length =
      scene.gait.body_length > 0 ? scene.gait.body_length : mesh.X.col(1).maxCoeff() - mesh.X.col(1).minCoeff();
  const Eigen::Vector3d mean_X = mesh.X.colwise().mean();
  double heading_at_start = std::numeric_limits<double>::quiet_NaN();
  auto record = [&](double t, bool force_write, int step) {
    result.u = assembler.gather_all(solver.solution());
    for (size_t i = 0; i < pulls.size(); ++i) pull_force[i] = pulls[i]->force(result.u, t);
    if (scene.gait.enabled) {
      const Eigen::Vector3d centroid = mean_X + Eigen::Vector3d(result.u.colwise().mean());
      result.trajectory.push_back({t, centroid.x(), centroid.y(), centroid.z()});
      const double along = centroid.dot(scene.gait.heading), eps = 1e-9 * std::max(1.0, t_end);
      if (std::abs(t - scene.gait.start) <= eps) heading_at_start = along;
      if (std::abs(t - scene.gait.end) <= eps && std::isfinite(heading_at_start)) {
        result.gait_displacement_m = along - heading_at_start;
        result.speed_bl_per_s = result.gait_displacement_m / body_length / scene.gait.nominal_s;
        result.gait_complete = true;
      }
    }
    result.cavity_pressure.clear();
    result.cavity_volume.clear();
    for (const auto& c : cavities) {
      result.cavity_pressure.push_back(c->pressure());
      result.cavity_volume.push_back(c->volume(assembler, solver.solution()));
    }
    for (const auto& c : volume_driven) {
      result.cavity_pressure.push_back(c->pressure());
      result.cavity_volume.push_back(c->cavity_volume());
    }
    // Cell measures: each rank fills its own cells, a reduction gathers them.
    std::vector<double> J(mesh.n_cells(), 0.0), vm(mesh.n_cells(), 0.0), Jg(mesh.n_cells()), vmg(mesh.n_cells());
    double local_min_J = std::numeric_limits<double>::infinity();
    const auto measures = elastic->measures_all(result.u);
    for (int k = 0; k < elastic->n_pieces(); ++k) {
      J[elastic->cell_of_piece(k)] = measures[k].J_mean;
      vm[elastic->cell_of_piece(k)] = measures[k].von_mises;
      local_min_J = std::min(local_min_J, measures[k].J_min);
    }
    MPI_Allreduce(&local_min_J, &result.min_J, 1, MPI_DOUBLE, MPI_MIN, comm);
    const bool output_now = force_write || (step % scene.output_every == 0);
    if (write && output_now) {
      MPI_Reduce(J.data(), Jg.data(), mesh.n_cells(), MPI_DOUBLE, MPI_SUM, 0, comm);
      MPI_Reduce(vm.data(), vmg.data(), mesh.n_cells(), MPI_DOUBLE, MPI_SUM, 0, comm);
    }
    std::vector<double> energies = assembler.term_energies(solver.solution());
    if (inertia) energies.push_back(inertia->kinetic_energy(assembler));
    if (friction) {
      if (step > 0) friction_dissipated += friction->dissipated(assembler, solver.solution());
      energies.push_back(friction_dissipated);
    }
    if (damping) energies.push_back(damping->total_dissipated());
    std::vector<Field> contact_fields;
    if (ground && write && output_now) {
      auto c = ground->nodal_contact(assembler, solver.solution());
      contact_fields.push_back(
          Field{"contact_force_N", 3, std::vector<double>(c.force.data(), c.force.data() + c.force.size())});
      for (double& g : c.gap)
        if (!std::isfinite(g)) g = -1.0;  // -1: node not on a contact surface (gaps are always > 0)
      contact_fields.push_back(Field{"contact_gap_m", 1, c.gap});
      contact_fields.push_back(Field{"contact_status", 1, std::vector<double>(c.status.begin(), c.status.end())});
      if (friction) {
        auto f = friction->nodal_friction(assembler, solver.solution());
        contact_fields.push_back(
            Field{"friction_force_N", 3, std::vector<double>(f.force.data(), f.force.data() + f.force.size())});
        contact_fields.push_back(Field{"friction_status", 1, std::vector<double>(f.status.begin(), f.status.end())});
      }
    }
    if (self_contact && write && output_now) {
      auto c = self_contact->nodal_contact(assembler, solver.solution());
      contact_fields.push_back(
          Field{"self_contact_force_N", 3, std::vector<double>(c.force.data(), c.force.data() + c.force.size())});
      for (double& g : c.gap)
        if (!std::isfinite(g)) g = -1.0;  // -1: node in no candidate pair
      contact_fields.push_back(Field{"self_contact_gap_m", 1, c.gap});
    }
    if (writer && output_now) {
      Field disp{"displacement", 3, std::vector<double>(result.u.data(), result.u.data() + result.u.size())};
      std::vector<Field> nodal{disp};
      nodal.insert(nodal.end(), contact_fields.begin(), contact_fields.end());
      writer->write_step(t, nodal, {Field{"J", 1, Jg}, Field{"von_mises_Pa", 1, vmg}});
      std::vector<double> row{t};
      for (size_t i = 0; i < cavities.size(); ++i) {
        row.push_back(result.cavity_pressure[i]);
        row.push_back(result.cavity_volume[i]);
      }
      for (size_t i = 0; i < volume_driven.size(); ++i) {
        row.push_back(result.cavity_pressure[cavities.size() + i]);
        row.push_back(result.cavity_volume[cavities.size() + i]);
        row.push_back(volume_driven[i]->state_value());
      }
      if (cavity_columns.size() > 1) writer->append_row("cavities", cavity_columns, row);
      if (!pulls.empty()) {
        std::vector<double> prow{t};
        for (size_t i = 0; i < pulls.size(); ++i) {
          prow.push_back(pull_force[i]);
          prow.push_back(pulls[i]->crosshead(t));
          prow.push_back(pulls[i]->mean_position(result.u));
        }
        writer->append_row("pulls", pull_columns, prow);
      }
      std::vector<double> erow{t};
      erow.insert(erow.end(), energies.begin(), energies.end());
      writer->append_row("energy", energy_columns, erow);
    }
    if (options.on_step) options.on_step(t, mesh, result.u, result);
  };

  // Checkpoints: the solver and its terms (QuasiStaticSolver::save_state) and what
  // this loop accumulates. Collective; rank 0 writes.
  int last_written = 0;
  const auto save_checkpoint = [&](const std::string& dir) {
    StateRecord state;
    solver.save_state(state);
    if (rank != 0) return;
    state.integers["run.ranks"] = size;
    state.integers["run.nodes"] = mesh.n_nodes();
    state.integers["run.cells"] = mesh.n_cells();
    state.integers["run.last_written"] = last_written;
    state.texts["run.scene"] = options.scene_text;
    state.set_number("run.wall_s",
                     wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    state.set_number("run.friction_dissipated", friction_dissipated);
    state.set_number("run.heading_at_start", heading_at_start);
    state.integers["run.gait_complete"] = result.gait_complete;
    state.set_number("run.gait_displacement_m", result.gait_displacement_m);
    state.set_number("run.speed_bl_per_s", result.speed_bl_per_s);
    std::vector<double> path;
    for (const auto& p : result.trajectory) path.insert(path.end(), p.begin(), p.end());
    state.arrays["run.trajectory"] = path;
    write_state_file(dir + "/checkpoint.h5", state);
  };
  if (options.resume) {
    const StateRecord& saved = checkpoint.state;
    const std::string& where = checkpoint.where;
    last_written = static_cast<int>(saved.integer("run.last_written", where));
    friction_dissipated = saved.number("run.friction_dissipated", where);
    heading_at_start = saved.number("run.heading_at_start", where);
    result.gait_complete = saved.integer("run.gait_complete", where) != 0;
    result.gait_displacement_m = saved.number("run.gait_displacement_m", where);
    result.speed_bl_per_s = saved.number("run.speed_bl_per_s", where);
    const auto& path = saved.array("run.trajectory", where);
    for (size_t i = 0; i + 3 < path.size(); i += 4)
      result.trajectory.push_back({path[i], path[i + 1], path[i + 2], path[i + 3]});
  }

  Progress progress(scene.name, t_end, options.progress);
  if (options.resume) {
    progress.set_resumed_from(result.resumed_at);
  } else {
    record(0.0, true, 0);
  }
  auto last_checkpoint = std::chrono::steady_clock::now();
  int steps_here = 0;
  try {
    result.stats = solver.run([&](const StepReport& r) {
      const bool last = r.t >= t_end - 1e-12 * t_end;
      record(r.t, last, r.step);
      if (last || r.step % scene.output_every == 0) last_written = r.step;
      progress.update(r.t, "step " + std::to_string(r.step) + " newton " + std::to_string(r.newton_its));
      ++steps_here;
      const bool stop = options.stop_after_steps > 0 && steps_here == options.stop_after_steps;
      // Rank 0's clock decides, so every rank takes part in the same checkpoints.
      int due = write && !last && scene.checkpoint_s > 0 &&
                std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint).count() >=
                    scene.checkpoint_s;
      MPI_Bcast(&due, 1, MPI_INT, 0, comm);
      if (write && (due || stop)) {
        save_checkpoint(tmp_dir);
        last_checkpoint = std::chrono::steady_clock::now();
      }
      if (stop) throw StopRun{};
    });
  } catch (const StopRun&) {
    progress.finish("stopped");
    result.stopped = true;
    result.stats = RunStats{};
    result.stats.failure = "stopped after " + std::to_string(steps_here) + " steps (checkpoint in " + tmp_dir + ")";
    result.stats.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (writer) writer->close();
    return result;
  }
  if (!result.stats.completed && last_written != result.stats.steps) record(solver.time(), true, result.stats.steps);
  progress.finish(result.stats.completed ? "done" : "FAILED");
  if (write) save_checkpoint(tmp_dir);  // the final state: a later run may extend it (--resume)
  result.stats.wall_s = wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Candidate pairs of the last self-contact search, over every rank.
  long self_candidates[2] = {0, 0};
  if (self_contact) {
    self_candidates[0] = self_contact->n_pairs();
    self_candidates[1] = self_contact->n_edge_pairs();
    MPI_Allreduce(MPI_IN_PLACE, self_candidates, 2, MPI_LONG, MPI_SUM, comm);
  }
  if (write) {
    if (rank == 0) {
      writer->close();
      Json summary;
      summary.add("scene", scene.name)
          .add("status", result.stats.completed ? "completed" : "failed")
          .add("failure", result.stats.failure)
          .add("end_time_reached", solver.time())
          .add("ranks", size)
          .add("order", mesh.order)
          .add("nodes", mesh.n_nodes())
          .add("cells", mesh.n_cells())
          .add("dofs", result.dofs)
          .add("steps", result.stats.steps)
          .add("newton_its", result.stats.newton_its)
          .add("linear_its", result.stats.linear_its)
          .add("step_cuts", result.stats.step_cuts)
          .add("step_cuts_by_cause",
               [&] {
                 Json causes;
                 for (const auto& [cause, n] : result.stats.cuts_by_cause) causes.add(cause, n);
                 return causes;
               }())
          .add("wall_s", result.stats.wall_s)
          .add("resumed_at_s", result.resumed_at)
          .add("min_J", result.min_J)
          .add("mass_kg", result.mass_kg)
          .add("max_displacement_m", result.u.rowwise().norm().maxCoeff())
          .add("pattern_rebuilds", solver.pattern_rebuilds())
          .add("exact_hessian_its", result.stats.exact_hessian_its)  // adaptive Hessian projection
          .add("projection_fallbacks", result.stats.projection_fallbacks);
      if (self_contact)  // candidate searches, and rigid moves of the trust region instead of one
        summary.add("self_contact", Json()
                                        .add("refreshes", self_contact->n_refreshes())
                                        .add("rigid_reanchors", self_contact->n_reanchors())
                                        .add("point_triangle_candidates", self_candidates[0])
                                        .add("edge_edge_candidates", self_candidates[1]));
      std::vector<Json> cavs;
      for (size_t i = 0; i < result.cavity_names.size(); ++i) {
        Json c;
        c.add("name", result.cavity_names[i])
            .add("pressure_Pa", result.cavity_pressure[i])
            .add("volume_m3", result.cavity_volume[i]);
        cavs.push_back(c);
      }
      summary.add("cavities", cavs);
      if (!pulls.empty()) {
        std::vector<Json> pull_summary;
        for (size_t i = 0; i < pulls.size(); ++i) {
          Json p;
          p.add("surface", pulls[i]->spec().surface)
              .add("stiffness_N_per_m", pulls[i]->spec().stiffness)
              .add("force_N", pull_force[i])
              .add("crosshead_m", pulls[i]->crosshead(solver.time()));
          pull_summary.push_back(p);
        }
        summary.add("pulls", pull_summary);
      }
      if (scene.gait.enabled) {
        summary.add("gait_complete", result.gait_complete)
            .add("displacement_m", result.gait_displacement_m)
            .add("speed_bl_per_s", result.speed_bl_per_s)
            .add("gait_time_s", scene.gait.nominal_s)
            .add("simulated_gait_s", scene.gait.end - scene.gait.start)
            .add("gait_start_s", scene.gait.start)
            .add("body_length_m", body_length)
            .add("heading",
                 std::vector<double>{scene.gait.heading.x(), scene.gait.heading.y(), scene.gait.heading.z()});
        std::string csv = "time_s,centroid_x_m,centroid_y_m,centroid_z_m\n";
        char line[160];
        for (const auto& p : result.trajectory) {
          std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g\n", p[0], p[1], p[2], p[3]);
          csv += line;
        }
        write_file_atomic(tmp_dir + "/trajectory.csv", csv);
      }
      if (!scene.calibrations.empty()) {  // which calibration (and its checksum) produced which value
        std::vector<Json> used;
        for (const auto& c : scene.calibrations) {
          Json j;
          j.add("key", c.key)
              .add("file", c.file)
              .add("sha256", c.sha256)
              .add("kind", c.kind)
              .add("parameter", c.parameter)
              .add("value", c.value)
              .add("std_error", c.std_error);
          used.push_back(j);
        }
        summary.add("calibrations", used);
      }
      write_file_atomic(tmp_dir + "/summary.json", summary.str(true) + "\n");
      commit_output_dir(tmp_dir, scene.output_dir);
      result.output_dir = scene.output_dir;
      // trajectory.png beside trajectory.csv
      if (scene.gait.enabled) run_plot_script("plot_trajectory.py", {result.output_dir}, "the trajectory");
    }
    bcast_string(result.output_dir, comm);
  }
  return result;
}

}  // namespace morphfem
