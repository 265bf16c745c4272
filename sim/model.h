// Scene -> model: the mesh the scene asks for, its materials and partition, the
// assembler holding the scene's energy terms (one builder per scene section,
// sim/terms.h), the Dirichlet conditions and the solver. The model keeps handles
// to the terms the observers read (cavities, pulls, contact, dynamics).
#pragma once
#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "actuation/cavity.h"
#include "actuation/gas_cavity.h"
#include "actuation/schedule_clock.h"
#include "contact/friction.h"
#include "contact/ground.h"
#include "contact/self_contact.h"
#include "fem/assembly.h"
#include "fem/damping.h"
#include "fem/elastic.h"
#include "fem/inertia.h"
#include "fem/material.h"
#include "fem/pull_spring.h"
#include "fem/solver.h"
#include "fem/time_integrator.h"
#include "mesh/mesh.h"
#include "mesh/partition.h"
#include "sim/scene.h"

namespace morphfem {

// The model of one run. It refers to the mesh it was built on and, through the
// assembler, to its own partition: it stays where build_model made it.
struct Model {
  Model(const Scene& scene, Mesh& mesh, MPI_Comm comm);
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  const Scene& scene;
  Mesh& mesh;
  MPI_Comm comm;
  int rank = 0, size = 1;
  std::vector<std::shared_ptr<const Material>> materials;  // by region id (null: not a volume region)
  std::vector<double> density;                             // by region id [kg/m^3] (0: none given)
  double mass_kg = 0;                                      // sum of rho V over the cells [kg]
  Partition partition;
  std::unique_ptr<Assembler> assembler;
  std::unique_ptr<IncrementalSolver> solver;
  // A dynamic scene's time integrator (null if quasi-static): the inertia term
  // advances it, the damping discretises its strain rate with it.
  std::shared_ptr<TimeIntegrator> integrator;

  // The terms the observers read; null or empty when the scene has none.
  std::shared_ptr<ElasticTerm> elastic;
  std::vector<std::shared_ptr<CavityPressureTerm>> cavities;
  // Cavities whose pressure follows from their volume: gas-filled, then volume-controlled.
  std::vector<std::shared_ptr<CavityVolumeTerm>> volume_driven;
  std::vector<std::shared_ptr<PullSpringTerm>> pulls;  // test-machine pull springs
  std::shared_ptr<InertiaTerm> inertia;
  std::shared_ptr<DampingTerm> damping;
  std::shared_ptr<GroundContactTerm> ground;
  std::shared_ptr<FrictionTerm> friction;
  std::shared_ptr<SelfContactTerm> self_contact;
  // Settle mode (Scene::settle, sim/cadence.h): the clock the schedule's loads
  // follow, and the valve-fed chambers it watches (channel, term).
  std::shared_ptr<ScheduleClock> schedule_clock;
  std::vector<std::pair<int, std::shared_ptr<GasCavityTerm>>> watched_valves;
};

// Builds the mesh the scene asks for on rank 0 and broadcasts it; checks every
// region name the scene uses. Throws InputError on bad input before any output
// directory is created.
Mesh build_scene_mesh(const Scene& scene, MPI_Comm comm);

// The model of the scene on `mesh` (from build_scene_mesh): materials, partition,
// the energy terms in the order of term_builders(), the boundary conditions and
// the solver, with a dynamic scene's inertia at its initial velocity. Throws
// InputError on bad input (nothing is written).
std::unique_ptr<Model> build_model(const Scene& scene, Mesh& mesh, MPI_Comm comm);

// The scene key an input error names: `where` if given, else "SOURCE: key".
std::string scene_key(const Scene& scene, const std::string& where, const std::string& key);

// Throws InputError naming the scene key unless the mesh has surface region `name`.
void require_surface(const Scene& scene, const Mesh& mesh, const std::string& name, const std::string& where,
                     const std::string& key);

}  // namespace morphfem
