// The time loop around the solver: resuming from a checkpoint, the steps with
// their records, checkpoints every output.checkpoint_s of wall time and at the
// end, and the stop after RunOptions::stop_after_steps.
#pragma once
#include <chrono>
#include <string>

#include "core/state_file.h"
#include "sim/model.h"
#include "sim/observers.h"
#include "sim/simulation.h"

namespace morphfem {

// Wall time of a run [s]: of this process since it started the run, and of the
// earlier parts of a resumed run.
struct RunClock {
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();
  double before = 0.0;  // wall time of the earlier parts of a resumed run [s]
  double here() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
  double total() const { return before + here(); }
};

// A resumed run's checkpoint: its directory, its file (`where`, for messages) and its state.
struct ResumePoint {
  std::string dir, where;
  StateRecord state;
};

// Resuming (RunOptions::resume; needs the scene's output directory): reads the
// checkpoint, checks it against this run (rank count, mesh, scene, an end time
// still ahead) and loads the solver's state from it: result.stats,
// result.resumed_at, clock.before. Extending a finished run copies its output to
// OUTPUT.partial. Collective; throws InputError.
ResumePoint resume_solver(Model& model, const RunOptions& options, SimulationResult& result, RunClock& clock);

class Stepper {
 public:
  Stepper(Model& model, Observers& observers, const RunOptions& options, SimulationResult& result,
          const RunClock& clock);

  // What the loop accumulated before the checkpoint.
  void restore(const ResumePoint& checkpoint);
  // Steps to solver.end_time: result.stats, the final checkpoint and wall time;
  // or result.stopped after RunOptions::stop_after_steps (output left in OUTPUT.partial).
  void run();

 private:
  void on_step(const StepReport& r);
  bool checkpoint_due(bool last) const;
  void save_checkpoint(const std::string& dir);
  void stop();
  void finish();

  Model& model_;
  Observers& observers_;
  const RunOptions& options_;
  SimulationResult& result_;
  const RunClock& clock_;
  int last_written_ = 0;  // the last step in the output
  int steps_here_ = 0;    // steps of this process
  std::chrono::steady_clock::time_point last_checkpoint_;
};

}  // namespace morphfem
