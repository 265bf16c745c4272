// Every energy term the scene builders make (sim/terms.h) against finite differences:
// scenes that exercise every entry of term_builders() are built as build_model builds
// them, and each term, alone in an assembler, is checked at random states near the
// start (small displacements: elements stay valid, contact gaps positive) after the
// step's begin_step at the converged start state:
//   gradient  dE/du_j   against (E(u + h e_j) - E(u - h e_j)) / 2h,
//   Hessian   H e_j     against (g(u + h e_j) - g(u - h e_j)) / 2h (with the term's
//                       low-rank part, e.g. a gas cavity's (nRT/V^2) dV dV^T).
// A builder that makes no term in these scenes fails the test: registering a builder
// is what gets its terms checked.
#include <gtest/gtest.h>
#include <petscsys.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "contact/lattice_floor.h"
#include "fem/assembly.h"
#include "fem/energy.h"
#include "fem/inertia.h"
#include "sim/model.h"
#include "sim/scene.h"
#include "sim/terms.h"

namespace morphfem {
namespace {

// Builders deliberately left out of the check, with the reason. Empty: every builder's
// terms are checked.
const std::map<std::string, std::string> kSkippedBuilders = {};

// The step whose begin_step sets the lagged quantities (inertia, damping, friction,
// gas amounts, growing lattice radii) [s].
constexpr double kT0 = 0.0, kT1 = 0.1;

// A block with the body, load and contact sections: elastic with growth, a membrane,
// gravity and a body force, a traction, a pull spring, implicit-Euler inertia with
// Kelvin-Voigt damping, ground contact 0.5 dhat below it with friction, and
// self-contact between its end faces (dhat 30 mm > the 20 mm between them, so that
// every pair is in the barrier). ORDER: 1 or 2.
const char* kBlock = R"(name: term_check_block
geometry: {type: block, lx: 0.02, ly: 0.02, lz: 0.01, mesh_size: 0.01, order: ORDER}
materials:
  body: {model: neo_hookean, mu: 1.0e5, nu: 0.45, density: 1000}
membranes:
  zmax: {model: neo_hookean, thickness: 5.0e-4, mu: 1.0e5}
loads:
  gravity: [1.0, 0.5, -9.81]
  tractions:
    - {surface: xmax, traction: [100, 50, -20]}
  pulls:
    - {surface: xmin, stiffness: 1000, velocity: [-0.1, 0, 0]}
contact:
  ground: {point: [0, 0, -5.0e-4], normal: [0, 0, 1], surfaces: [zmin], dhat: 1.0e-3}
  friction: {eps_v: 1.0e-3, regions: [{surface: zmin, mu: 0.5}]}
  self: {pairs: [[xmin, xmax]], dhat: 0.03}
dynamics: {scheme: implicit_euler, shear_viscosity: 50, bulk_viscosity: 20, initial_velocity: [0.01, 0.005, 0]}
solver: {end_time: 1, initial_step: 0.01}
)";

// An eighth of a spherical shell with the cavity sections on its inner surface: a
// pressure, a gas-filled and a volume-controlled cavity (closed by the symmetry planes).
const char* kShell = R"(name: term_check_shell
geometry: {type: spherical_shell, inner_radius: 0.010, outer_radius: 0.012, mesh_size: 0.004, order: ORDER}
materials:
  body: {model: neo_hookean, mu: 5.0e4, nu: 0.45}
loads:
  cavities:
    - {name: inside, surfaces: [inner], pressure: 2000}
  gas_cavities:
    - {name: gas, surfaces: [inner], symmetry_factor: 8, initial_gauge_pressure: 1000, supply_pressure: 5000,
       conductance: 1.7e-8}
  volume_cavities:
    - {name: held, surfaces: [inner], volume_ratio: [[0, 1], [1, 1.2]], penalty_modulus: 2.0e4}
solver: {end_time: 1, initial_step: 0.01}
)";

// Growth of the whole body g(t) = (1 + t, 1 - t/2, 1) and a body force b(X) [N/m^3]
// varying in space, which the scene files cannot give.
void add_code_sections(Scene& scene) {
  scene.growth.push_back({"body", [](double t) { return Eigen::Vector3d(1.0 + t, 1.0 - 0.5 * t, 1.0); }});
  scene.body_force = [](const Eigen::Vector3d& X, double t) {
    return Eigen::Vector3d(2e4 * X.y(), -1e4 * X.z(), -5e3 * (1.0 + t));
  };
  scene.body_force_degree = 2;
}

// The scene `text` at element order `order` (its ORDER).
Scene scene_of_order(std::string text, int order) {
  text.replace(text.find("ORDER"), 5, std::to_string(order));
  return scene_from_yaml(YAML::Load(text), "term_check.yaml");
}

Scene block_scene(int order) {
  Scene scene = scene_of_order(kBlock, order);
  add_code_sections(scene);
  return scene;
}

// The voxel preset (examples/voxel/roll_flat.yaml) at 2 cm with the lattice's floor
// contact instead of face contact, the floor moved to 0.5 dhat below the lowest sphere
// (set_floor_under_lattice) so that the barrier acts.
Scene voxel_lattice_scene() {
  const std::string path = std::string(MORPHFEM_SOURCE_DIR) + "/examples/voxel/roll_flat.yaml";
  YAML::Node root = YAML::LoadFile(path);
  root["geometry"]["mesh_size"] = 0.02;
  root["contact"] = YAML::Load(
      "{lattice_floor: {point: [0, 0, -0.003], dhat: 5.0e-4, kappa: 6.0e5, mu: {skin: 2.0, bladder_1: 0.5, "
      "bladder_2: 0.5, bladder_3: 0.5, bladder_4: 0.5, bladder_5: 0.5, bladder_6: 0.5, bladder_7: 0.5, "
      "bladder_8: 0.5}}}");
  return scene_from_yaml(root, path);
}

void set_floor_under_lattice(Scene& scene, const Mesh& mesh) {
  LatticeFloorSpec& floor = scene.lattice_floor->floor;
  double lowest = std::numeric_limits<double>::infinity();
  for (const LatticePoint& p : lattice_points(scene, mesh)) {
    double z = 0;
    for (size_t a = 0; a < p.nodes.size(); ++a) z += p.weights[a] * mesh.X(p.nodes[a], 2);
    lowest = std::min(lowest, z - p.radius(kT1));
  }
  floor.point = Eigen::Vector3d(0, 0, lowest - 0.5 * floor.dhat);
  floor.normal = Eigen::Vector3d(0, 0, 1);
}

// A scene's terms, each with the builder that made it: the builders run in the order
// of term_builders() on a model with the materials and partition build_model gives.
struct BuiltScene {
  Scene scene;
  Mesh mesh;
  std::unique_ptr<Model> model;  // build_model's (materials, density, partition)
  std::unique_ptr<Model> probe;  // the builders' terms, one builder at a time
  std::vector<std::pair<std::string, std::shared_ptr<EnergyTerm>>> terms;
};

std::unique_ptr<BuiltScene> build_terms(Scene scene, bool lattice_floor) {
  auto b = std::make_unique<BuiltScene>();
  b->scene = std::move(scene);
  b->mesh = build_scene_mesh(b->scene, PETSC_COMM_WORLD);
  if (lattice_floor) set_floor_under_lattice(b->scene, b->mesh);
  b->model = build_model(b->scene, b->mesh, PETSC_COMM_WORLD);
  b->probe = std::make_unique<Model>(b->scene, b->mesh, PETSC_COMM_WORLD);
  Model& probe = *b->probe;
  probe.materials = b->model->materials;
  probe.density = b->model->density;
  probe.mass_kg = b->model->mass_kg;
  probe.partition = b->model->partition;
  probe.assembler = std::make_unique<Assembler>(b->mesh, probe.partition, PETSC_COMM_WORLD);
  for (const NamedTermBuilder& builder : term_builders()) {
    const size_t before = probe.assembler->terms().size();
    builder.build(b->scene, probe);
    for (size_t k = before; k < probe.assembler->terms().size(); ++k)
      b->terms.emplace_back(builder.name, probe.assembler->terms()[k]);
  }
  return b;
}

// Values of a vector (one rank: every dof).
std::vector<double> values(Vec v) {
  PetscInt n;
  VecGetLocalSize(v, &n);
  const PetscScalar* a;
  VecGetArrayRead(v, &a);
  std::vector<double> out(a, a + n);
  VecRestoreArrayRead(v, &a);
  return out;
}

void set_values(Vec v, const std::vector<double>& x) {
  PetscScalar* a;
  VecGetArray(v, &a);
  std::copy(x.begin(), x.end(), a);
  VecRestoreArray(v, &a);
}

double max_abs(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

struct CheckSettings {
  int states = 3;        // random states per term
  int sampled_dofs = 0;  // dofs differentiated per state (0: every dof)
  double amplitude = 0;  // |u_j| <= amplitude [m] at the random states
  double length = 0;     // the body's size L (bounding-box diagonal) [m]
  double step = 0;       // difference step h = 1e-7 L [m]
};

// The dofs differentiated: every one, or `count` dofs of nodes of the term's pieces.
std::vector<int> dofs_to_check(const EnergyTerm& term, int n_dofs, int count, std::mt19937& rng) {
  std::vector<int> dofs;
  if (count == 0 || count >= n_dofs) {
    for (int j = 0; j < n_dofs; ++j) dofs.push_back(j);
    return dofs;
  }
  std::set<int> chosen;
  std::vector<int> nodes;
  std::uniform_int_distribution<int> component(0, 2);
  for (int tries = 0; static_cast<int>(chosen.size()) < count && tries < 100 * count; ++tries) {
    if (term.n_pieces() == 0) break;
    term.piece_nodes(std::uniform_int_distribution<int>(0, term.n_pieces() - 1)(rng), nodes);
    const int node = nodes[std::uniform_int_distribution<int>(0, static_cast<int>(nodes.size()) - 1)(rng)];
    chosen.insert(3 * node + component(rng));
  }
  return {chosen.begin(), chosen.end()};
}

// Largest errors of one term's gradient and Hessian against central differences,
// relative to the largest gradient entry and the largest Hessian entry seen.
struct DerivativeErrors {
  double gradient = 0, hessian = 0;
  double gradient_scale = 0, hessian_scale = 0;
};

// The term alone in an assembler: begin_step at u0 = 0, then the derivatives at
// `settings.states` random states u with |u_j| <= amplitude.
DerivativeErrors check_term(const BuiltScene& b, const std::shared_ptr<EnergyTerm>& term, const CheckSettings& s,
                            std::mt19937& rng) {
  Assembler a(b.mesh, b.probe->partition, PETSC_COMM_WORLD);
  a.add_term(term);
  a.setup();
  Vec u0 = a.create_vector(), u = a.create_vector(), g = a.create_vector(), v = a.create_vector(),
      Hv = a.create_vector();
  Mat H = a.create_matrix();
  VecSet(u0, 0.0);
  term->set_exact_hessian(true);  // projected barrier/friction Hessians are not derivatives
  if (term->refresh_pieces(a, u0)) a.setup();
  if (auto inertia = std::dynamic_pointer_cast<InertiaTerm>(term)) {
    const Eigen::Vector3d v0 = b.scene.dynamics->initial_velocity;
    inertia->set_initial_velocity([v0](const Eigen::Vector3d&) { return v0; });
    inertia->initialize(a, u0, kT0);
  }
  term->set_time(kT1);
  term->begin_step(a, u0, kT0, kT1);

  const int n = static_cast<int>(a.n_dofs());
  DerivativeErrors e;
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int state = 0; state < s.states; ++state) {
    std::vector<double> x(n);
    for (double& xj : x) xj = s.amplitude * unit(rng);
    set_values(u, x);
    const double E = a.gradient(u, g);
    EXPECT_TRUE(std::isfinite(E)) << "state " << state << " is outside the term's domain";
    const std::vector<double> grad = values(g);
    a.hessian(u, H);
    std::vector<EnergyTerm::LowRank> low_rank;
    if (term->has_low_rank()) term->low_rank(a, u, low_rank);
    e.gradient_scale = std::max(e.gradient_scale, max_abs(grad));
    for (int j : dofs_to_check(*term, n, s.sampled_dofs, rng)) {
      std::vector<double> xp = x, xm = x;
      xp[j] += s.step;
      xm[j] -= s.step;
      set_values(u, xp);
      const double Ep = a.gradient(u, g);
      const std::vector<double> gp = values(g);
      set_values(u, xm);
      const double Em = a.gradient(u, g);
      const std::vector<double> gm = values(g);
      e.gradient = std::max(e.gradient, std::abs((Ep - Em) / (2 * s.step) - grad[j]));
      // Column j of the Hessian: H e_j + sum_k c_k v_k (v_k)_j.
      VecSet(v, 0.0);
      VecSetValue(v, j, 1.0, INSERT_VALUES);
      VecAssemblyBegin(v);
      VecAssemblyEnd(v);
      MatMult(H, v, Hv);
      for (const auto& [vk, ck] : low_rank) {
        const std::vector<double> vk_values = values(vk);
        VecAXPY(Hv, ck * vk_values[j], vk);
      }
      const std::vector<double> column = values(Hv);
      e.hessian_scale = std::max(e.hessian_scale, max_abs(column));
      for (int i = 0; i < n; ++i) e.hessian = std::max(e.hessian, std::abs((gp[i] - gm[i]) / (2 * s.step) - column[i]));
    }
    for (auto& [vk, ck] : low_rank) VecDestroy(&vk);
  }
  for (Vec* w : {&u0, &u, &g, &v, &Hv}) VecDestroy(w);
  MatDestroy(&H);
  return e;
}

// Checks every term of the scene; returns the builders that made at least one term.
std::set<std::string> check_scene(const std::string& label, const BuiltScene& b, const CheckSettings& s) {
  // Central differences err by truncation, (h/l)^2 / 6 relative, with l the shortest
  // length an energy varies on: an element (millimetres), the gap to a barrier
  // (>= 0.2 mm here) or friction's smoothing length eps_v dt (0.1 mm); h = 1e-7 L, L
  // the body's size (centimetres to decimetres), keeps it below 1e-7. And by rounding,
  // eps |E| / (h |g|) ~ 1e-16 l_E / h with l_E = |E| / |g|: below 1e-8 but for a gas
  // cavity, whose nRT log V is large against its gradient (4e-7). Measured errors are
  // 1e-12 to 4e-7 of the scales; 1e-5 leaves a wide margin, while a wrong sign or
  // factor in a derivative errs by O(1).
  const double tolerance = 1e-5;
  std::mt19937 rng(20240917);
  std::set<std::string> builders;
  for (const auto& [builder, term] : b.terms) {
    SCOPED_TRACE(label + ": " + builder + " term '" + term->name() + "'");
    builders.insert(builder);
    const DerivativeErrors e = check_term(b, term, s, rng);
    // A term with no gradient at these states would check nothing.
    EXPECT_GT(e.gradient_scale, 0.0);
    EXPECT_LE(e.gradient, tolerance * e.gradient_scale);
    // Loads linear in u (gravity, body force, traction) have no Hessian: theirs is
    // compared with |g| / L, the size a Hessian of that gradient would have.
    EXPECT_LE(e.hessian, tolerance * std::max(e.hessian_scale, e.gradient_scale / s.length));
  }
  return builders;
}

// The largest |u_j| that keeps every element valid and every contact gap positive:
// 2 % of the shortest cell edge, and a fifth of a contact gap (0.5 dhat at the start).
double state_amplitude(const Mesh& mesh, double gap) {
  double shortest = std::numeric_limits<double>::infinity();
  for (int c = 0; c < mesh.n_cells(); ++c)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        shortest = std::min(shortest, (mesh.X.row(mesh.cells(c, i)) - mesh.X.row(mesh.cells(c, j))).norm());
  return std::min(0.02 * shortest, 0.2 * gap);
}

// Settings for a mesh: the amplitude of state_amplitude and h = 1e-7 L.
CheckSettings settings(const Mesh& mesh, double gap, int states, int sampled_dofs) {
  CheckSettings s;
  s.states = states;
  s.sampled_dofs = sampled_dofs;
  s.amplitude = state_amplitude(mesh, gap);
  s.length = (mesh.X.colwise().maxCoeff() - mesh.X.colwise().minCoeff()).norm();
  s.step = 1e-7 * s.length;
  return s;
}

TEST(TermDerivatives, EveryBuilderTermMatchesFiniteDifferences) {
  int size = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &size);
  if (size > 1) GTEST_SKIP() << "one rank: the differences perturb every dof in place";
  std::set<std::string> covered;
  const auto check = [&covered](const std::string& label, const BuiltScene& b, const CheckSettings& s) {
    const std::set<std::string> builders = check_scene(label, b, s);
    covered.insert(builders.begin(), builders.end());
  };
  for (int order : {1, 2}) {
    const auto b = build_terms(block_scene(order), false);
    // The ground gap at the start is 0.5 dhat = 0.5 mm.
    check("block P" + std::to_string(order), *b, settings(b->mesh, 0.5e-3, order == 1 ? 3 : 2, 0));
  }
  const auto shell = build_terms(scene_of_order(kShell, 1), false);
  check("shell P1", *shell, settings(shell->mesh, std::numeric_limits<double>::infinity(), 3, 0));
  // Thousands of dofs: those of a few random pieces of each term.
  const auto voxel = build_terms(voxel_lattice_scene(), true);
  check("voxel lattice", *voxel, settings(voxel->mesh, 0.5 * voxel->scene.lattice_floor->floor.dhat, 2, 24));
  for (const NamedTermBuilder& builder : term_builders())
    EXPECT_TRUE(covered.count(builder.name) || kSkippedBuilders.count(builder.name))
        << "builder '" << builder.name << "' made no term in the scenes of this test: add its section to one";
}

}  // namespace
}  // namespace morphfem
