#include "sim/stepper.h"

#include <mpi.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "core/errors.h"
#include "sim/broadcast.h"
#include "sim/cadence.h"

namespace morphfem {

namespace {

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

// Finds and reads the checkpoint on rank 0 and sends it to every rank. Collective.
ResumePoint read_checkpoint(const Scene& scene, MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
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
  return point;
}

// Checks the checkpoint against this run: the rank count, the mesh, the scene (but
// the keys scene_identity drops) and an end time still ahead.
void check_checkpoint(const ResumePoint& point, const Model& model, const std::string& scene_text) {
  const StateRecord& saved = point.state;
  const std::string& where = point.where;
  const Mesh& mesh = model.mesh;
  const double t_end = model.scene.solver.t_end;
  const long ranks = saved.integer("run.ranks", where);
  if (ranks != model.size)
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

ResumePoint resume_solver(Model& model, const RunOptions& options, SimulationResult& result, RunClock& clock) {
  const Scene& scene = model.scene;
  if (!writes_output(scene, options))
    throw InputError(scene_key(scene, "", "output.directory"), "--resume needs the scene's output directory");
  ResumePoint checkpoint = read_checkpoint(scene, model.comm);
  check_checkpoint(checkpoint, model, options.scene_text);
  result.stats = model.solver->load_state(checkpoint.state, checkpoint.where);
  result.resumed_at = checkpoint.state.number("solver.t", checkpoint.where);
  clock.before = checkpoint.state.number("run.wall_s", checkpoint.where);
  if (checkpoint.dir == scene.output_dir) reopen_finished_output(scene, model.comm);
  return checkpoint;
}

Stepper::Stepper(Model& model, Observers& observers, const RunOptions& options, SimulationResult& result,
                 const RunClock& clock)
    : model_(model), observers_(observers), options_(options), result_(result), clock_(clock) {}

void Stepper::restore(const ResumePoint& checkpoint) {
  last_written_ = static_cast<int>(checkpoint.state.integer("run.last_written", checkpoint.where));
  if (model_.schedule_clock) model_.schedule_clock->load(checkpoint.state, "run.cadence.", checkpoint.where);
  observers_.load(checkpoint.state, checkpoint.where);
}

void Stepper::run() {
  last_checkpoint_ = std::chrono::steady_clock::now();
  try {
    result_.stats = model_.solver->run([this](const StepReport& r) { on_step(r); });
  } catch (const StopRun&) {
    stop();
    return;
  }
  finish();
}

void Stepper::on_step(const StepReport& r) {
  advance_schedule_clock(model_, r.t);  // first: a column that starts at r.t is recorded with its step
  const double t_end = model_.scene.solver.t_end;
  const bool last = r.t >= t_end - 1e-12 * t_end;
  observers_.record(r.t, last, r.step);
  if (last || r.step % model_.scene.output_every == 0) last_written_ = r.step;
  observers_.progress(r);
  ++steps_here_;
  const bool stop = options_.stop_after_steps > 0 && steps_here_ == options_.stop_after_steps;
  const bool due = checkpoint_due(last);
  if (observers_.writes() && (due || stop)) {
    save_checkpoint(observers_.partial_dir());
    last_checkpoint_ = std::chrono::steady_clock::now();
  }
  if (stop) throw StopRun{};
}

// Every output.checkpoint_s of wall time; rank 0's clock decides, so every rank
// takes part in the same checkpoints. Collective.
bool Stepper::checkpoint_due(bool last) const {
  const double checkpoint_s = model_.scene.checkpoint_s;
  int due = observers_.writes() && !last && checkpoint_s > 0 &&
            std::chrono::duration<double>(std::chrono::steady_clock::now() - last_checkpoint_).count() >= checkpoint_s;
  MPI_Bcast(&due, 1, MPI_INT, 0, model_.comm);
  return due != 0;
}

// Checkpoints: the solver and its terms (IncrementalSolver::save_state), what
// identifies the run, and what the loop and the observers accumulate.
// Collective; rank 0 writes.
void Stepper::save_checkpoint(const std::string& dir) {
  StateRecord state;
  model_.solver->save_state(state);
  if (model_.rank != 0) return;
  state.integers["run.ranks"] = model_.size;
  state.integers["run.nodes"] = model_.mesh.n_nodes();
  state.integers["run.cells"] = model_.mesh.n_cells();
  state.integers["run.last_written"] = last_written_;
  state.texts["run.scene"] = options_.scene_text;
  state.set_number("run.wall_s", clock_.total());
  if (model_.schedule_clock) model_.schedule_clock->save(state, "run.cadence.");
  observers_.save(state);
  write_state_file(dir + "/checkpoint.h5", state);
}

// Stopped as a kill would stop it: the checkpoint was saved, the output stays partial.
void Stepper::stop() {
  result_.stopped = true;
  result_.stats = RunStats{};
  result_.stats.failure =
      "stopped after " + std::to_string(steps_here_) + " steps (checkpoint in " + observers_.partial_dir() + ")";
  result_.stats.wall_s = clock_.here();
  observers_.stopped();
}

// A failed run records its last converged state; the final state is checkpointed
// so a later run may extend it (--resume).
void Stepper::finish() {
  if (!result_.stats.completed && last_written_ != result_.stats.steps)
    observers_.record(model_.solver->time(), true, result_.stats.steps);
  observers_.finished(result_.stats.completed);
  if (observers_.writes()) save_checkpoint(observers_.partial_dir());
  result_.stats.wall_s = clock_.total();
}

}  // namespace morphfem
