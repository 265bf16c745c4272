#include "sim/simulation.h"

#include <memory>

#include "sim/model.h"
#include "sim/observers.h"
#include "sim/stepper.h"

namespace morphfem {

namespace {

// What the result says of the model before any step: its size, mass and cavities.
void describe_model(const Model& model, SimulationResult& result) {
  result.mass_kg = model.mass_kg;
  result.dofs = model.assembler->n_dofs();
  for (const auto& c : model.cavities) result.cavity_names.push_back(c->spec().name);
  for (const auto& c : model.volume_driven) result.cavity_names.push_back(c->wall().name);
}

}  // namespace

std::string scene_identity(const YAML::Node& doc) {
  YAML::Node copy = YAML::Clone(doc);
  // Neither changes the steps: how far the run goes, how often it checkpoints.
  if (copy["solver"] && copy["solver"].IsMap() && copy["solver"]["end_time"]) copy["solver"].remove("end_time");
  if (copy["output"] && copy["output"].IsMap() && copy["output"]["checkpoint_s"]) copy["output"].remove("checkpoint_s");
  YAML::Emitter out;
  out << copy;
  return out.c_str();
}

// Build the model; resume if asked; open the observers; step; finish the observers.
SimulationResult run_scene(const Scene& scene, MPI_Comm comm, const RunOptions& options) {
  RunClock clock;
  SimulationResult result;
  // Everything that can be wrong with the input is checked before any output.
  result.mesh = build_scene_mesh(scene, comm);
  const std::unique_ptr<Model> model = build_model(scene, result.mesh, comm);
  describe_model(*model, result);
  ResumePoint checkpoint;
  if (options.resume) checkpoint = resume_solver(*model, options, result, clock);
  Observers observers(*model, options, result);
  Stepper stepper(*model, observers, options, result, clock);
  if (options.resume) stepper.restore(checkpoint);
  observers.start(options.resume);
  stepper.run();
  if (!result.stopped) observers.finish();  // a stopped run leaves its output partial
  return result;
}

}  // namespace morphfem
