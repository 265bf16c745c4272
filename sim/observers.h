// What a run records of its steps: the XDMF/HDF5 output and its tables (cavities,
// pulls, energy), the gait measurement, the progress line, RunOptions::on_step and,
// at the end, summary.json; rank 0 writes, every rank takes part in the gathers.
#pragma once
#include <Eigen/Dense>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/json.h"
#include "core/progress.h"
#include "core/state_file.h"
#include "fem/output.h"
#include "sim/model.h"
#include "sim/simulation.h"

namespace morphfem {

// Whether a run writes its output: RunOptions::write_output and a scene output directory.
bool writes_output(const Scene& scene, const RunOptions& options);

// The gait of a scene that plays a schedule: the mean node position (the voxel
// study's "mean vertex") every step, and its displacement along the heading from
// the gait's start to its end in body lengths per gait time: with a fixed cadence
// gait.start, gait.end and the nominal gait time; in settle mode the first
// column's start and the gait's end as the schedule clock decided them, and the
// time between them.
class GaitMeter {
 public:
  GaitMeter(const Scene& scene, const Mesh& mesh, std::shared_ptr<const ScheduleClock> clock);
  void sample(double t, const RowMatrixXd& u, SimulationResult& result);
  // The measurement so far, in a checkpoint (run.*).
  void save(const SimulationResult& result, StateRecord& state) const;
  void load(const StateRecord& state, const std::string& where, SimulationResult& result);
  // The gait keys of summary.json, and DIR/trajectory.csv.
  void summarize(const SimulationResult& result, Json& summary) const;
  static void write_trajectory(const SimulationResult& result, const std::string& dir);

 private:
  double start_time() const;  // [s], NaN while unknown
  double end_time() const;
  void note_cadence(SimulationResult& result) const;
  Json cadence_summary(const SimulationResult& result) const;

  const Scene& scene_;
  std::shared_ptr<const ScheduleClock> clock_;  // settle mode, else null
  double body_length_;
  Eigen::Vector3d mean_X_;
  double heading_at_start_ = std::numeric_limits<double>::quiet_NaN();
};

class Observers {
 public:
  // Opens the output (rank 0) when the run writes one: a new OUTPUT.partial, or
  // for a resumed run the partial output from result.resumed_at on; writes
  // RunOptions::scene_file there as scene.yaml.
  Observers(Model& model, const RunOptions& options, SimulationResult& result);

  bool writes() const { return write_; }
  const std::string& partial_dir() const { return tmp_dir_; }  // rank 0's, "" elsewhere

  // What the observers accumulate over the steps, in a checkpoint (run.*).
  void save(StateRecord& state) const;
  void load(const StateRecord& state, const std::string& where);

  // The first record: the initial state, or for a resumed run the progress from
  // where it resumed.
  void start(bool resumed);
  // Records the state at time t (collective): the result's fields, the output
  // if force_write or on every output_every-th step, then RunOptions::on_step.
  void record(double t, bool force_write, int step);
  void progress(const StepReport& r);
  // The end of the steps: stopped early (the output stays in OUTPUT.partial), or
  // done or failed.
  void stopped();
  void finished(bool completed);
  // summary.json and trajectory.csv, then OUTPUT.partial becomes OUTPUT (collective).
  void finish();

 private:
  struct CellFields {
    std::vector<double> J, von_mises;  // on rank 0, when written
  };
  void sample_cavities();
  CellFields cell_measures(bool output_now);
  std::vector<double> energies(int step);
  std::vector<Field> contact_fields(bool output_now);
  void write_step(double t, const CellFields& cells, const std::vector<Field>& contact,
                  const std::vector<double>& energies);
  Json summary(const long self_candidates[2]) const;

  Model& model_;
  const Scene& scene_;
  const RunOptions& options_;
  SimulationResult& result_;
  const bool write_;
  std::string tmp_dir_;
  std::unique_ptr<ResultWriter> writer_;
  std::vector<std::string> cavity_columns_, pull_columns_, energy_columns_;
  std::vector<double> pull_force_;  // last recorded [N]
  double friction_dissipated_ = 0.0;
  GaitMeter gait_;
  Progress progress_;
};

}  // namespace morphfem
