#include "sim/terms.h"

#include <algorithm>
#include <array>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>

#include "actuation/voxel_growth.h"
#include "core/errors.h"
#include "fem/loads.h"
#include "mesh/robot.h"
#include "sim/cadence.h"

namespace morphfem {

namespace {

// The elastic energy in the scene's formulation, with each grown region's stretch.
void add_elastic(const Scene& scene, Model& m) {
  const auto formulation = elastic_formulations().find(scene.formulation);
  if (formulation == elastic_formulations().end())
    throw InputError(scene_key(scene, "", "solver.formulation"), "unknown formulation '" + scene.formulation + "'");
  m.elastic = formulation->second(m.mesh, m.partition, m.rank, m.materials, scene.quadrature_degree);
  for (const auto& [region, stretch] : scene.growth) {
    if (!m.mesh.has_region(region, 3))
      throw InputError(scene_key(scene, "", "actuation.growth"), "the mesh has no volume region '" + region + "'");
    try {
      m.elastic->set_growth(m.mesh.region(region, 3).id, stretch);
    } catch (const std::invalid_argument& e) {
      throw InputError(scene_key(scene, "", "actuation.growth"), e.what());
    }
  }
  m.assembler->add_term(m.elastic);
}

void add_membranes(const Scene& scene, Model& m) {
  for (const auto& spec : scene.membranes)
    m.assembler->add_term(std::make_shared<MembraneTerm>(m.mesh, m.partition, m.rank, spec));
}

// Gravity is a body force rho g [N/m^3]; rho depends on the cell's region, so one
// term per region keeps the kernel a pure function of X.
void add_gravity(const Scene& scene, Model& m) {
  if (!(scene.gravity.norm() > 0)) return;
  const Mesh& mesh = m.mesh;
  for (size_t id = 0; id < mesh.regions.size(); ++id) {
    if (mesh.regions[id].dim != 3 || m.density[id] <= 0) continue;
    const Eigen::Vector3d body = m.density[id] * scene.gravity;
    std::function<Eigen::Vector3d(double)> stretch;
    if (scene.weightless_inflated)
      for (const auto& [region, g] : scene.growth)
        if (region == mesh.regions[id].name) stretch = g;
    VectorField field = [body](const Eigen::Vector3d&, double) { return body; };
    if (stretch)  // the lattice's inflated bladder voxels: no weight while g_z > 1
      field = [body, stretch](const Eigen::Vector3d&, double t) -> Eigen::Vector3d {
        return stretch(t).z() > 1.0 + 1e-9 ? Eigen::Vector3d::Zero() : body;
      };
    m.assembler->add_term(std::make_shared<BodyForceTerm>(m.mesh, m.partition, m.rank,
                                                          mesh.cells_of(mesh.regions[id].name), field, 2 * mesh.order));
  }
}

void add_body_force(const Scene& scene, Model& m) {
  if (!scene.body_force) return;
  std::vector<int> all_cells(m.mesh.n_cells());
  for (int c = 0; c < m.mesh.n_cells(); ++c) all_cells[c] = c;
  m.assembler->add_term(std::make_shared<BodyForceTerm>(m.mesh, m.partition, m.rank, all_cells, scene.body_force,
                                                        scene.body_force_degree));
}

void add_cavities(const Scene& scene, Model& m) {
  for (const auto& spec : scene.cavities) {
    m.cavities.push_back(std::make_shared<CavityPressureTerm>(m.mesh, m.partition, m.rank, spec));
    m.assembler->add_term(m.cavities.back());
  }
}

// Cavities whose pressure follows from their volume: gas-filled, then volume-controlled.
void add_volume_cavities(const Scene& scene, Model& m) {
  for (std::size_t i = 0; i < scene.gas_cavities.size(); ++i)
    m.volume_driven.push_back(
        std::make_shared<GasCavityTerm>(m.mesh, m.partition, m.rank, clocked_gas_cavity(scene, m, i)));
  for (const auto& spec : scene.volume_cavities)
    m.volume_driven.push_back(std::make_shared<VolumeControlledCavityTerm>(m.mesh, m.partition, m.rank, spec));
  for (const auto& c : m.volume_driven) m.assembler->add_term(c);
}

void add_tractions(const Scene& scene, Model& m) {
  for (const auto& t : scene.tractions) {
    const Eigen::Vector3d traction = t.traction;
    const TimeFunction scale = t.scale;
    m.assembler->add_term(std::make_shared<SurfaceLoadTerm>(
        m.mesh, m.partition, m.rank, m.mesh.faces_of(t.surface),
        [traction, scale](const Eigen::Vector3d&, double time) { return Eigen::Vector3d(scale(time) * traction); }));
  }
}

void add_pulls(const Scene& scene, Model& m) {
  for (const auto& spec : scene.pulls) {
    m.pulls.push_back(std::make_shared<PullSpringTerm>(m.mesh, m.rank, spec));
    m.assembler->add_term(m.pulls.back());
  }
}

// Dynamics: inertia (and viscous damping) only when the scene asks for them.
void add_inertia(const Scene& scene, Model& m) {
  if (!scene.dynamics) return;
  for (const auto& [region, params] : scene.materials)
    if (m.density[m.mesh.region(region, 3).id] <= 0)
      throw InputError(params.where("model"), "dynamics needs 'density' [kg/m^3] for material '" + region + "'");
  m.inertia = std::make_shared<InertiaTerm>(m.mesh, m.partition, m.rank, m.density, m.integrator,
                                            scene.dynamics->inertia.lumped);
  m.assembler->add_term(m.inertia);
}

void add_damping(const Scene& scene, Model& m) {
  if (!scene.dynamics) return;
  const DynamicsSpec& dynamics = *scene.dynamics;
  if (!(dynamics.shear_viscosity > 0 || dynamics.bulk_viscosity > 0)) return;
  std::vector<double> eta(m.mesh.regions.size(), dynamics.shear_viscosity),
      zeta(m.mesh.regions.size(), dynamics.bulk_viscosity);
  m.damping = std::make_shared<DampingTerm>(m.mesh, m.partition, m.rank, eta, zeta, m.integrator);
  m.assembler->add_term(m.damping);
}

// Ground contact only on the declared surfaces.
void add_ground(const Scene& scene, Model& m) {
  if (!scene.ground) return;
  GroundContactSpec spec = *scene.ground;
  // nearly incompressible: E = 2 mu (1 + nu) ~ 3 mu
  spec.young_modulus = 3.0 * contact_shear_modulus(m.mesh, m.materials, spec.surfaces);
  m.ground = std::make_shared<GroundContactTerm>(m.mesh, m.partition, m.rank, spec);
  m.assembler->add_term(m.ground);
}

// Friction on the ground contact (none without it).
void add_friction(const Scene& scene, Model& m) {
  if (!scene.ground || !scene.friction) return;
  m.friction = std::make_shared<FrictionTerm>(m.mesh, m.partition, m.rank, m.ground, clocked_friction(scene, m));
  m.assembler->add_term(m.friction);
}

// Self-contact only between the declared surface pairs.
void add_self_contact(const Scene& scene, Model& m) {
  if (!scene.self_contact) return;
  SelfContactSpec spec = *scene.self_contact;
  std::vector<std::string> surfaces;
  for (const auto& [a, b] : spec.pairs) surfaces.insert(surfaces.end(), {a, b});
  spec.young_modulus = 3.0 * contact_shear_modulus(m.mesh, m.materials, surfaces);  // as for the ground
  m.self_contact = std::make_shared<SelfContactTerm>(m.mesh, m.partition, m.rank, spec);
  m.assembler->add_term(m.self_contact);
}

// The voxel lattice's floor contact (a diagnostic): a sphere per lattice voxel.
void add_lattice_floor(const Scene& scene, Model& m) {
  if (!scene.lattice_floor) return;
  m.assembler->add_term(std::make_shared<LatticeFloorTerm>(m.mesh, m.partition, m.rank, scene.lattice_floor->floor,
                                                           lattice_points(scene, m.mesh)));
}

}  // namespace

const std::vector<NamedTermBuilder>& term_builders() {
  static const std::vector<NamedTermBuilder> table{
      {"elastic", add_elastic},
      {"membranes", add_membranes},
      {"gravity", add_gravity},
      {"body_force", add_body_force},
      {"cavities", add_cavities},
      {"volume_cavities", add_volume_cavities},
      {"tractions", add_tractions},
      {"pulls", add_pulls},
      {"inertia", add_inertia},
      {"damping", add_damping},
      {"ground", add_ground},
      {"friction", add_friction},
      {"self_contact", add_self_contact},
      {"lattice_floor", add_lattice_floor},
  };
  return table;
}

// The lattice voxels of a robot_voxel scene as floor-contact points: the material
// point at each box's centre (interpolated in its region's cells), the box's
// footprint as area, the sphere radius L (s_x + s_y + s_z)/6 with s = base scale x
// the region's growth stretch (actuation.growth), and the region's friction
// coefficient, or a foot's mu(t) for skin voxels over that foot's y range.
std::vector<LatticePoint> lattice_points(const Scene& scene, const Mesh& mesh) {
  const std::string key = scene_key(scene, "", "contact.lattice_floor");
  if (scene.geometry.string("type", "") != "robot_voxel")
    throw InputError(key, "needs geometry.type robot_voxel (the lattice is the voxel study's)");
  if (!scene.lattice_floor) throw InputError(key, "the scene declares no lattice floor");
  const LatticeFloorScene& spec = *scene.lattice_floor;
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

}  // namespace morphfem
