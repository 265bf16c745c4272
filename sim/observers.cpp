#include "sim/observers.h"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/plot.h"
#include "sim/broadcast.h"

namespace morphfem {

namespace {

std::vector<std::string> cavity_columns(const Model& m) {
  std::vector<std::string> columns{"time"};
  for (const auto& c : m.cavities) {
    columns.push_back(c->spec().name + "_pressure_Pa");
    columns.push_back(c->spec().name + "_volume_m3");
  }
  for (const auto& c : m.volume_driven) {
    columns.push_back(c->wall().name + "_pressure_Pa");
    columns.push_back(c->wall().name + "_volume_m3");
    columns.push_back(c->wall().name + "_" + c->state_column());
  }
  return columns;
}

std::vector<std::string> pull_columns(const Model& m) {
  std::vector<std::string> columns{"time"};
  for (const auto& p : m.pulls) {
    columns.push_back(p->spec().surface + "_force_N");
    columns.push_back(p->spec().surface + "_crosshead_m");
    columns.push_back(p->spec().surface + "_mean_position_m");
  }
  return columns;
}

std::vector<std::string> energy_columns(const Model& m) {
  std::vector<std::string> columns{"time"};
  for (const auto& term : m.assembler->terms()) columns.push_back(term->name() + "_J");
  if (m.inertia) columns.push_back("kinetic_J");
  if (m.friction) columns.push_back("friction_dissipated_J");
  if (m.damping) columns.push_back("damping_dissipated_J");
  return columns;
}

template <class Matrix>
Field vector_field(const std::string& name, const Matrix& v) {
  return Field{name, 3, std::vector<double>(v.data(), v.data() + v.size())};
}

template <class Status>
Field status_field(const std::string& name, const Status& status) {
  return Field{name, 1, std::vector<double>(status.begin(), status.end())};
}

// Which calibration (and its checksum) produced which value.
std::vector<Json> calibrations_summary(const Scene& scene) {
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
  return used;
}

}  // namespace

bool writes_output(const Scene& scene, const RunOptions& options) {
  return options.write_output && !scene.output_dir.empty();
}

// ---- Gait

GaitMeter::GaitMeter(const Scene& scene, const Mesh& mesh, std::shared_ptr<const ScheduleClock> clock)
    : scene_(scene),
      clock_(std::move(clock)),
      body_length_(scene.gait.body_length > 0 ? scene.gait.body_length
                                              : mesh.X.col(1).maxCoeff() - mesh.X.col(1).minCoeff()),
      mean_X_(mesh.X.colwise().mean()) {}

double GaitMeter::start_time() const { return clock_ ? clock_->gait_start() : scene_.gait.start; }

double GaitMeter::end_time() const { return clock_ ? clock_->gait_end() : scene_.gait.end; }

// The cadence the speed belongs to (SimulationResult::cadence, column_starts, gait_s).
void GaitMeter::note_cadence(SimulationResult& result) const {
  result.cadence = scene_.gait.cadence;
  result.column_starts = clock_ ? clock_->column_starts() : scene_.gait.column_starts;
  result.gait_s = clock_ ? end_time() - start_time() : scene_.gait.nominal_s;
}

void GaitMeter::sample(double t, const RowMatrixXd& u, SimulationResult& result) {
  const Eigen::Vector3d centroid = mean_X_ + Eigen::Vector3d(u.colwise().mean());
  result.trajectory.push_back({t, centroid.x(), centroid.y(), centroid.z()});
  note_cadence(result);
  const double along = centroid.dot(scene_.gait.heading), eps = 1e-9 * std::max(1.0, scene_.solver.t_end);
  if (std::abs(t - start_time()) <= eps) heading_at_start_ = along;
  if (std::abs(t - end_time()) <= eps && std::isfinite(heading_at_start_)) {
    result.gait_displacement_m = along - heading_at_start_;
    result.speed_bl_per_s = result.gait_displacement_m / body_length_ / result.gait_s;
    result.gait_complete = true;
  }
}

void GaitMeter::save(const SimulationResult& result, StateRecord& state) const {
  state.set_number("run.heading_at_start", heading_at_start_);
  state.integers["run.gait_complete"] = result.gait_complete;
  state.set_number("run.gait_displacement_m", result.gait_displacement_m);
  state.set_number("run.speed_bl_per_s", result.speed_bl_per_s);
  std::vector<double> path;
  for (const auto& p : result.trajectory) path.insert(path.end(), p.begin(), p.end());
  state.arrays["run.trajectory"] = path;
}

void GaitMeter::load(const StateRecord& saved, const std::string& where, SimulationResult& result) {
  heading_at_start_ = saved.number("run.heading_at_start", where);
  result.gait_complete = saved.integer("run.gait_complete", where) != 0;
  result.gait_displacement_m = saved.number("run.gait_displacement_m", where);
  result.speed_bl_per_s = saved.number("run.speed_bl_per_s", where);
  const auto& path = saved.array("run.trajectory", where);
  for (size_t i = 0; i + 3 < path.size(); i += 4)
    result.trajectory.push_back({path[i], path[i + 1], path[i + 2], path[i + 3]});
  note_cadence(result);  // the clock is loaded first (Stepper::restore)
}

// The cadence: its mode and parameters, the columns' start times [s] (settle: as
// realised; with the gait's end as the last entry once it ended) and their mean length.
Json GaitMeter::cadence_summary(const SimulationResult& result) const {
  const Cadence& cadence = scene_.gait.cadence;
  const std::vector<double>& starts = result.column_starts;
  // The columns that ended: in settle mode each start but the last ends one.
  const double ended = clock_ ? static_cast<double>(starts.size()) - 1 : static_cast<double>(starts.size());
  const double last = clock_ ? (starts.empty() ? 0.0 : starts.back()) : end_time();
  Json json;
  json.add("mode", cadence_mode_name(cadence.mode));
  if (clock_) {
    Json tolerance;
    for (const auto& [index, channel] : scene_.settle->valves)
      tolerance.add(channel_name(channel), clock_->tolerance_pa(channel));
    json.add("min_hold_s", cadence.min_hold_s)
        .add("timeout_s", cadence.timeout_s)
        .add("tolerance_pa", tolerance)
        .add("channel_map", scene_.settle->channel_map)
        .add("timed_out_column", clock_->timed_out_column() + 1);  // 1-based, 0: none
  }
  json.add("column_starts_s", starts)
      .add("gait_end_s", end_time())
      .add("mean_column_s", ended > 0 ? (last - starts.front()) / ended : std::numeric_limits<double>::quiet_NaN());
  return json;
}

void GaitMeter::summarize(const SimulationResult& result, Json& summary) const {
  const GaitSpec& gait = scene_.gait;
  summary.add("gait_complete", result.gait_complete)
      .add("displacement_m", result.gait_displacement_m)
      .add("speed_bl_per_s", result.speed_bl_per_s)
      .add("gait_time_s", result.gait_s)
      .add("simulated_gait_s", end_time() - start_time())
      .add("gait_start_s", start_time())
      .add("cadence", cadence_summary(result))
      .add("body_length_m", body_length_)
      .add("heading", std::vector<double>{gait.heading.x(), gait.heading.y(), gait.heading.z()});
}

void GaitMeter::write_trajectory(const SimulationResult& result, const std::string& dir) {
  std::string csv = "time_s,centroid_x_m,centroid_y_m,centroid_z_m\n";
  char line[160];
  for (const auto& p : result.trajectory) {
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.9g,%.9g\n", p[0], p[1], p[2], p[3]);
    csv += line;
  }
  write_file_atomic(dir + "/trajectory.csv", csv);
}

// ---- Observers

Observers::Observers(Model& model, const RunOptions& options, SimulationResult& result)
    : model_(model),
      scene_(model.scene),
      options_(options),
      result_(result),
      write_(writes_output(model.scene, options)),
      cavity_columns_(cavity_columns(model)),
      pull_columns_(pull_columns(model)),
      energy_columns_(energy_columns(model)),
      pull_force_(model.pulls.size(), 0.0),
      gait_(model.scene, model.mesh, model.schedule_clock),
      progress_(model.scene.name, model.scene.solver.t_end, options.progress) {
  if (!write_ || model.rank != 0) return;
  if (options.resume) {
    tmp_dir_ = scene_.output_dir + ".partial";
    writer_ = std::make_unique<ResultWriter>(tmp_dir_, scene_.name, model.mesh, result.resumed_at);
  } else {
    tmp_dir_ = temporary_output_dir(scene_.output_dir);
    writer_ = std::make_unique<ResultWriter>(tmp_dir_, scene_.name, model.mesh);
  }
  if (!options.scene_file.empty()) write_file_atomic(tmp_dir_ + "/scene.yaml", options.scene_file);
}

void Observers::save(StateRecord& state) const {
  state.set_number("run.friction_dissipated", friction_dissipated_);
  gait_.save(result_, state);
}

void Observers::load(const StateRecord& state, const std::string& where) {
  friction_dissipated_ = state.number("run.friction_dissipated", where);
  gait_.load(state, where, result_);
}

void Observers::start(bool resumed) {
  if (resumed)
    progress_.set_resumed_from(result_.resumed_at);
  else
    record(0.0, true, 0);
}

void Observers::record(double t, bool force_write, int step) {
  Model& m = model_;
  result_.u = m.assembler->gather_all(m.solver->solution());
  for (size_t i = 0; i < m.pulls.size(); ++i) pull_force_[i] = m.pulls[i]->force(result_.u, t);
  if (scene_.gait.enabled) gait_.sample(t, result_.u, result_);
  sample_cavities();
  const bool output_now = force_write || (step % scene_.output_every == 0);
  const CellFields cells = cell_measures(output_now);
  const std::vector<double> energy = energies(step);
  const std::vector<Field> contact = contact_fields(output_now);
  if (writer_ && output_now) write_step(t, cells, contact, energy);
  if (options_.on_step) options_.on_step(t, m.mesh, result_.u, result_);
}

void Observers::sample_cavities() {
  result_.cavity_pressure.clear();
  result_.cavity_volume.clear();
  for (const auto& c : model_.cavities) {
    result_.cavity_pressure.push_back(c->pressure());
    result_.cavity_volume.push_back(c->volume(*model_.assembler, model_.solver->solution()));
  }
  for (const auto& c : model_.volume_driven) {
    result_.cavity_pressure.push_back(c->pressure());
    result_.cavity_volume.push_back(c->cavity_volume());
  }
}

// Cell measures: each rank fills its own cells, a reduction gathers them (only
// when written); the smallest det F goes to every rank.
Observers::CellFields Observers::cell_measures(bool output_now) {
  const Mesh& mesh = model_.mesh;
  const ElasticTerm& elastic = *model_.elastic;
  std::vector<double> J(mesh.n_cells(), 0.0), vm(mesh.n_cells(), 0.0);
  CellFields gathered{std::vector<double>(mesh.n_cells()), std::vector<double>(mesh.n_cells())};
  double local_min_J = std::numeric_limits<double>::infinity();
  const auto measures = elastic.measures_all(result_.u);
  for (int k = 0; k < elastic.n_pieces(); ++k) {
    J[elastic.cell_of_piece(k)] = measures[k].J_mean;
    vm[elastic.cell_of_piece(k)] = measures[k].von_mises;
    local_min_J = std::min(local_min_J, measures[k].J_min);
  }
  MPI_Allreduce(&local_min_J, &result_.min_J, 1, MPI_DOUBLE, MPI_MIN, model_.comm);
  if (write_ && output_now) {
    MPI_Reduce(J.data(), gathered.J.data(), mesh.n_cells(), MPI_DOUBLE, MPI_SUM, 0, model_.comm);
    MPI_Reduce(vm.data(), gathered.von_mises.data(), mesh.n_cells(), MPI_DOUBLE, MPI_SUM, 0, model_.comm);
  }
  return gathered;
}

// Each term's energy, then the kinetic energy and what friction and damping dissipated.
std::vector<double> Observers::energies(int step) {
  Model& m = model_;
  std::vector<double> energy = m.assembler->term_energies(m.solver->solution());
  if (m.inertia) energy.push_back(m.inertia->kinetic_energy(*m.assembler));
  if (m.friction) {
    if (step > 0) friction_dissipated_ += m.friction->dissipated(*m.assembler, m.solver->solution());
    energy.push_back(friction_dissipated_);
  }
  if (m.damping) energy.push_back(m.damping->total_dissipated());
  return energy;
}

// Contact forces, gaps and states of the ground, friction and self-contact terms (when written).
std::vector<Field> Observers::contact_fields(bool output_now) {
  Model& m = model_;
  std::vector<Field> fields;
  if (m.ground && write_ && output_now) {
    auto c = m.ground->nodal_contact(*m.assembler, m.solver->solution());
    fields.push_back(vector_field("contact_force_N", c.force));
    for (double& g : c.gap)
      if (!std::isfinite(g)) g = -1.0;  // -1: node not on a contact surface (gaps are always > 0)
    fields.push_back(Field{"contact_gap_m", 1, c.gap});
    fields.push_back(status_field("contact_status", c.status));
    if (m.friction) {
      auto f = m.friction->nodal_friction(*m.assembler, m.solver->solution());
      fields.push_back(vector_field("friction_force_N", f.force));
      fields.push_back(status_field("friction_status", f.status));
    }
  }
  if (m.self_contact && write_ && output_now) {
    auto c = m.self_contact->nodal_contact(*m.assembler, m.solver->solution());
    fields.push_back(vector_field("self_contact_force_N", c.force));
    for (double& g : c.gap)
      if (!std::isfinite(g)) g = -1.0;  // -1: node in no candidate pair
    fields.push_back(Field{"self_contact_gap_m", 1, c.gap});
  }
  return fields;
}

// One output step (rank 0): the nodal and cell fields, and a row of each table.
void Observers::write_step(double t, const CellFields& cells, const std::vector<Field>& contact,
                           const std::vector<double>& energy) {
  const Model& m = model_;
  std::vector<Field> nodal{vector_field("displacement", result_.u)};
  nodal.insert(nodal.end(), contact.begin(), contact.end());
  writer_->write_step(t, nodal, {Field{"J", 1, cells.J}, Field{"von_mises_Pa", 1, cells.von_mises}});
  std::vector<double> row{t};
  for (size_t i = 0; i < m.cavities.size(); ++i) {
    row.push_back(result_.cavity_pressure[i]);
    row.push_back(result_.cavity_volume[i]);
  }
  for (size_t i = 0; i < m.volume_driven.size(); ++i) {
    row.push_back(result_.cavity_pressure[m.cavities.size() + i]);
    row.push_back(result_.cavity_volume[m.cavities.size() + i]);
    row.push_back(m.volume_driven[i]->state_value());
  }
  if (cavity_columns_.size() > 1) writer_->append_row("cavities", cavity_columns_, row);
  if (!m.pulls.empty()) {
    std::vector<double> prow{t};
    for (size_t i = 0; i < m.pulls.size(); ++i) {
      prow.push_back(pull_force_[i]);
      prow.push_back(m.pulls[i]->crosshead(t));
      prow.push_back(m.pulls[i]->mean_position(result_.u));
    }
    writer_->append_row("pulls", pull_columns_, prow);
  }
  std::vector<double> erow{t};
  erow.insert(erow.end(), energy.begin(), energy.end());
  writer_->append_row("energy", energy_columns_, erow);
}

void Observers::progress(const StepReport& r) {
  progress_.update(r.t, "step " + std::to_string(r.step) + " newton " + std::to_string(r.newton_its));
}

void Observers::stopped() {
  progress_.finish("stopped");
  if (writer_) writer_->close();
}

void Observers::finished(bool completed) { progress_.finish(completed ? "done" : "FAILED"); }

// summary.json: the run's counters and end state, then what the scene has of
// self-contact, cavities, pulls, gait and calibrations.
Json Observers::summary(const long self_candidates[2]) const {
  const Model& m = model_;
  const SimulationResult& r = result_;
  Json summary;
  summary.add("scene", scene_.name)
      .add("status", r.stats.completed ? "completed" : "failed")
      .add("failure", r.stats.failure)
      .add("end_time_reached", m.solver->time())
      .add("ranks", m.size)
      .add("order", m.mesh.order)
      .add("nodes", m.mesh.n_nodes())
      .add("cells", m.mesh.n_cells())
      .add("dofs", r.dofs)
      .add("steps", r.stats.steps)
      .add("newton_its", r.stats.newton_its)
      .add("linear_its", r.stats.linear_its)
      .add("step_cuts", r.stats.step_cuts)
      .add("step_cuts_by_cause",
           [&] {
             Json causes;
             for (const auto& [cause, n] : r.stats.cuts_by_cause) causes.add(cause, n);
             return causes;
           }())
      .add("wall_s", r.stats.wall_s)
      .add("resumed_at_s", r.resumed_at)
      .add("min_J", r.min_J)
      .add("mass_kg", r.mass_kg)
      .add("max_displacement_m", r.u.rowwise().norm().maxCoeff())
      .add("pattern_rebuilds", m.solver->pattern_rebuilds())
      .add("exact_hessian_its", r.stats.exact_hessian_its)  // adaptive Hessian projection
      .add("projection_fallbacks", r.stats.projection_fallbacks);
  if (m.self_contact)  // candidate searches, and rigid moves of the trust region instead of one
    summary.add("self_contact", Json()
                                    .add("refreshes", m.self_contact->n_refreshes())
                                    .add("rigid_reanchors", m.self_contact->n_reanchors())
                                    .add("point_triangle_candidates", self_candidates[0])
                                    .add("edge_edge_candidates", self_candidates[1]));
  std::vector<Json> cavs;
  for (size_t i = 0; i < r.cavity_names.size(); ++i) {
    Json c;
    c.add("name", r.cavity_names[i]).add("pressure_Pa", r.cavity_pressure[i]).add("volume_m3", r.cavity_volume[i]);
    cavs.push_back(c);
  }
  summary.add("cavities", cavs);
  if (!m.pulls.empty()) {
    std::vector<Json> pull_summary;
    for (size_t i = 0; i < m.pulls.size(); ++i) {
      Json p;
      p.add("surface", m.pulls[i]->spec().surface)
          .add("stiffness_N_per_m", m.pulls[i]->spec().stiffness)
          .add("force_N", pull_force_[i])
          .add("crosshead_m", m.pulls[i]->crosshead(m.solver->time()));
      pull_summary.push_back(p);
    }
    summary.add("pulls", pull_summary);
  }
  if (scene_.gait.enabled) gait_.summarize(r, summary);
  if (!scene_.calibrations.empty()) summary.add("calibrations", calibrations_summary(scene_));
  return summary;
}

void Observers::finish() {
  // Candidate pairs of the last self-contact search, over every rank.
  long self_candidates[2] = {0, 0};
  if (model_.self_contact) {
    self_candidates[0] = model_.self_contact->n_pairs();
    self_candidates[1] = model_.self_contact->n_edge_pairs();
    MPI_Allreduce(MPI_IN_PLACE, self_candidates, 2, MPI_LONG, MPI_SUM, model_.comm);
  }
  if (!write_) return;
  if (model_.rank == 0) {
    writer_->close();
    const Json summary_json = summary(self_candidates);
    if (scene_.gait.enabled) GaitMeter::write_trajectory(result_, tmp_dir_);
    write_file_atomic(tmp_dir_ + "/summary.json", summary_json.str(true) + "\n");
    commit_output_dir(tmp_dir_, scene_.output_dir);
    result_.output_dir = scene_.output_dir;
    // trajectory.png beside trajectory.csv
    if (scene_.gait.enabled) run_plot_script("plot_trajectory.py", {result_.output_dir}, "the trajectory");
  }
  bcast_string(result_.output_dir, model_.comm);
}

}  // namespace morphfem
