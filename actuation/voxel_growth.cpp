#include "actuation/voxel_growth.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace morphfem {

int VoxelActuation::swing_steps() const {
  return static_cast<int>(std::ceil((max_scale - min_scale) / rate_per_step - 1e-9));
}

VoxelTimeline voxel_timeline(const Schedule& schedule, const VoxelActuation& model) {
  VoxelTimeline timeline;
  std::array<bool, kNumBladders> inflated{};  // all deflated before the gait
  double t = 0.0;
  for (int k = 0; k < schedule.total_columns(); ++k) {
    bool changes = false;
    for (int b = 0; b < kNumBladders; ++b) {
      const bool target = schedule.active(b, k);
      changes = changes || target != inflated[b];
      inflated[b] = target;
    }
    // The lattice loop runs one step even when every bladder is already where it should be.
    const int actuation_steps = changes ? model.swing_steps() + 1 : 1;
    timeline.column_start.push_back(t);
    t += actuation_steps * model.step_s;
    timeline.actuation_end.push_back(t);
    t += model.settle_steps * model.step_s;
    timeline.column_end.push_back(t);
  }
  return timeline;
}

StretchFunction voxel_bladder_growth(const Schedule& schedule, int bladder, double start, double core_pressure_pa,
                                     const VoxelActuation& model) {
  if (bladder < 0 || bladder >= kNumBladders) throw std::invalid_argument("voxel growth: bladder must be 0..7");
  const VoxelTimeline timeline = voxel_timeline(schedule, model);
  // Swing fraction q(t) in [0, 1] (0 deflated, 1 inflated) as a piecewise-linear table.
  const double swing_s = model.swing_steps() * model.step_s;
  std::vector<std::pair<double, double>> q{{start - 1.0, 0.0}};
  double level = 0.0;
  for (size_t k = 0; k < timeline.column_start.size(); ++k) {
    const double target = schedule.active(bladder, static_cast<int>(k)) ? 1.0 : 0.0;
    if (target == level) continue;
    const double t0 = start + timeline.column_start[k];
    q.emplace_back(t0, level);
    q.emplace_back(t0 + swing_s, target);
    level = target;
  }
  q.emplace_back(std::max(q.back().first, start + timeline.duration()) + 1.0, level);
  const TimeFunction swing(q);
  // Scale at full swing: n steps of (r/20, r/c, r) from (1, 1, s_min).
  const double n = model.swing_steps(), r = model.rate_per_step;
  const Eigen::Vector3d full(n * r / 20.0, n * r / model.y_divisor(core_pressure_pa),
                             (model.max_scale - model.min_scale) / model.min_scale);
  return [swing, full](double t) -> Eigen::Vector3d { return Eigen::Vector3d::Ones() + swing(t) * full; };
}

TimeFunction voxel_foot_friction(const Schedule& schedule, int foot_channel, double start, double mu_active,
                                 double mu_inactive, const VoxelActuation& model, double switch_s) {
  const int row = channel_row(foot_channel);
  if (row != 8 && row != 9) throw std::invalid_argument("voxel_foot_friction: not a foot channel");
  const VoxelTimeline timeline = voxel_timeline(schedule, model);
  switch_s = std::min(switch_s, 0.5 * model.step_s);  // an actuation phase may last a single lattice step
  std::vector<std::pair<double, double>> table{{start - 1.0, mu_active}};
  double level = mu_active;
  auto set = [&](double t, double mu) {
    if (mu == level) return;
    table.emplace_back(t, level);
    table.emplace_back(t + switch_s, mu);
    level = mu;
  };
  for (size_t k = 0; k < timeline.column_start.size(); ++k) {
    set(start + timeline.column_start[k], schedule.active(row, static_cast<int>(k)) ? mu_active : mu_inactive);
    set(start + timeline.actuation_end[k], mu_active);  // settle: every foot active
  }
  table.emplace_back(std::max(table.back().first, start + timeline.duration()) + 1.0, level);
  return TimeFunction(table);
}

TimeFunction voxel_gap_foot_friction(const Schedule& schedule, double start, double mu_active, double mu_inactive,
                                     const VoxelActuation& model, double switch_s) {
  const VoxelTimeline timeline = voxel_timeline(schedule, model);
  if (timeline.actuation_end.empty()) return TimeFunction::constant(mu_inactive);
  const double raised = start + timeline.actuation_end.front();  // the first settle phase starts
  switch_s = std::min(switch_s, 0.5 * model.step_s);
  return TimeFunction({{raised, mu_inactive}, {raised + switch_s, mu_active}});
}

}  // namespace morphfem
