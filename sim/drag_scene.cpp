// Simulated pull test (drag_scene.h).
#include "sim/drag_scene.h"

#include <cmath>

#include "core/errors.h"
#include "fem/pull_spring.h"
#include "sim/simulation.h"

namespace morphfem {

Scene drag_scene(const DragParameters& p) {
  const std::string where = "drag test";
  if (!(p.mu_static > 0 && p.mu_kinetic > 0 && p.mu_kinetic <= p.mu_static))
    throw InputError(where, "need mu_static >= mu_kinetic > 0");
  if (!(p.stiffness > 0 && p.weight_N > 0 && p.speed > 0 && p.model_speed_factor > 0 && p.travel > 0 && p.dt > 0 &&
        p.settle >= 0))
    throw InputError(where, "stiffness, weight, speed, travel and dt must be > 0");
  const double g = 9.81;
  const double volume = p.block_length * p.block_width * p.block_height;
  Scene s;
  s.name = "drag_test";
  s.geometry = ParamSet("drag test geometry");
  s.geometry.set_string("type", "block");
  s.geometry.set("lx", p.block_length);
  s.geometry.set("ly", p.block_width);
  s.geometry.set("lz", p.block_height);
  s.geometry.set("mesh_size", std::max(p.block_height, 0.5 * std::min(p.block_length, p.block_width)));
  s.geometry.set("order", 1);
  ParamSet material("drag test material");
  material.set_string("model", "neo_hookean");
  material.set("mu", p.shear_modulus);
  material.set("nu", 0.45);
  material.set("density", p.weight_N / (g * volume));  // rho g V = W
  s.materials["body"] = material;
  s.gravity = Eigen::Vector3d(0, 0, -g);
  s.dynamics.emplace().inertia.scheme = TimeScheme::implicit_euler;
  GroundContactSpec& ground = s.ground.emplace();
  ground.surfaces = {"zmin"};
  const double dhat = 1e-5;
  ground.dhat = dhat;
  // Start at the resting barrier gap under the weight: d ~ dhat (1 - sqrt(p / (3 kappa))),
  // kappa = E ~ 3 mu, contact pressure W / A.
  const double pressure = p.weight_N / (p.block_length * p.block_width);
  const double resting = 1.0 - std::sqrt(pressure / (3.0 * 3.0 * p.shear_modulus));
  ground.point = Eigen::Vector3d(0, 0, -resting * dhat);
  FrictionSpec& friction = s.friction.emplace();
  friction.eps_v = p.eps_v;
  friction.regions.push_back({"zmin", TimeFunction::constant(p.mu_static), TimeFunction::constant(p.mu_kinetic)});
  PullSpringSpec pull;
  pull.surface = "xmax";
  pull.stiffness = p.stiffness;
  const double model_speed = p.speed * p.model_speed_factor;
  pull.velocity = Eigen::Vector3d(model_speed, 0, 0);
  pull.start = p.settle;
  pull.where = where;
  s.pulls.push_back(pull);
  s.solver.t_end = p.settle + p.travel / model_speed;
  s.solver.dt_initial = s.solver.dt_max = p.dt;
  if (p.settle > 0) s.solver.output_times = {p.settle};  // a step lands on the pull's start
  return s;
}

DragCurve run_pull_scene(const Scene& scene, MPI_Comm comm, RunOptions options, double time_scale) {
  if (scene.pulls.empty()) throw InputError(scene.source, "the scene has no loads.pulls (a test machine to record)");
  DragCurve curve;
  const double start = scene.pulls.front().start;
  std::unique_ptr<PullSpringTerm> spring;  // on the solved mesh (the partitioner renumbers nodes)
  auto chained = options.on_step;
  options.on_step = [&](double t, const Mesh& mesh, const RowMatrixXd& u, const SimulationResult& r) {
    if (chained) chained(t, mesh, u, r);
    if (!spring) spring = std::make_unique<PullSpringTerm>(mesh, 1, scene.pulls.front());
    if (t < start - 1e-12) return;
    curve.time.push_back(time_scale * (t - start));
    curve.displacement.push_back(spring->crosshead(t) - spring->crosshead(start));
    curve.force.push_back(spring->force(u, t));
  };
  const SimulationResult r = run_scene(scene, comm, options);
  curve.completed = r.stats.completed;
  curve.wall_s = r.stats.wall_s;
  curve.mass_kg = r.mass_kg;
  curve.result = r;
  return curve;
}

DragCurve run_drag_test(const DragParameters& p, MPI_Comm comm) {
  RunOptions options;
  options.write_output = false;
  options.progress = false;
  // Reported times are crosshead travel / machine speed (the model pulls slower).
  return run_pull_scene(drag_scene(p), comm, options, p.model_speed_factor);
}

}  // namespace morphfem
