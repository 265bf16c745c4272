// The voxel study's actuation (ROBOT.md; Voxelyze "external scale factor" of the
// bladder voxels), turned into prescribed growth of the finite-element bladder
// blocks so the lattice and the finite-element model run the same actuation.
//
// Voxel model (per lattice step dt):
//   * a bladder voxel's scale is s = (s_x, s_y, s_z), deflated s_z = s_min = 0.2;
//   * inflating adds (r/20, r/c(p), r) per step until s_z >= s_max = 2.5, deflating
//     subtracts the same until s_z <= s_min, with r = 3e-4 and the core-pressure
//     dependent divisor c(p) = 1.7 + 8.3 p / 12000 Pa (so the along-y growth that
//     bends the skin shrinks as the core is pressurised);
//   * a column = an actuation phase (as long as the slowest bladder needs: one full
//     swing takes n = ceil((s_max - s_min)/r) steps, or 1 step when nothing
//     changes) with the column's foot frictions, then a settle phase of 4001 steps
//     with every foot active.
// Finite-element blocks are built at the deflated thickness, so the growth
// relative to the mesh is G = diag(s_x, s_y, s_z / s_min): G = I when deflated.
//
// Times are simulation times: the gait (column 0) starts at `start` [s].
#pragma once
#include <Eigen/Dense>
#include <functional>
#include <vector>

#include "actuation/schedule.h"
#include "fem/time_function.h"

namespace morphfem {

struct VoxelActuation {
  double step_s = 1.0602478421508119e-4;  // lattice time step dt [s] (baselines.txt)
  double rate_per_step = 3e-4;            // r: scale change per step along z [-]
  double min_scale = 0.2;                 // s_min: deflated z scale [-]
  double max_scale = 2.5;                 // s_max: inflated z scale [-]
  int settle_steps = 4001;                // after each column's actuation phase
  double max_core_pressure_pa = 12000;    // p at which c(p) = 10

  // Along-y divisor c(p) = 1.7 + 8.3 p / p_max [-].
  double y_divisor(double core_pressure_pa) const { return 1.7 + 8.3 * core_pressure_pa / max_core_pressure_pa; }
  // Steps of one full swing s_min <-> s_max.
  int swing_steps() const;
};

// Start, end of the actuation phase, and end of every played column [gait time, s].
struct VoxelTimeline {
  std::vector<double> column_start, actuation_end, column_end;
  double duration() const { return column_end.empty() ? 0.0 : column_end.back(); }
};
VoxelTimeline voxel_timeline(const Schedule& schedule, const VoxelActuation& model = {});

using StretchFunction = std::function<Eigen::Vector3d(double t)>;

// Growth stretches G(t) = (s_x, s_y, s_z / s_min) of bladder `bladder` (0..7): linear
// in time during the swings of the timeline, constant otherwise; deflated before the
// gait. core_pressure_pa sets c(p).
StretchFunction voxel_bladder_growth(const Schedule& schedule, int bladder, double start, double core_pressure_pa,
                                     const VoxelActuation& model = {});

// Foot friction with the voxel timing: the column's state during its actuation
// phase, active during settle phases and before/after the gait; switches take
// `switch_s` [s].
TimeFunction voxel_foot_friction(const Schedule& schedule, int foot_channel, double start, double mu_active,
                                 double mu_inactive, const VoxelActuation& model = {}, double switch_s = 1e-3);

// The study's third foot material (pancakerobot.jl, varF[3]: the foot voxels of the skin
// columns between bladder groups, x = 4, 8, 12): inactive (mu_inactive) from the start,
// raised to mu_active with every settle phase like the other feet, but never lowered again,
// since the study's code switches only feet A and B per column. So: mu_inactive until
// the first settle phase, mu_active from then on (switch over `switch_s` [s]).
// Those voxels' x scale (the study's setExternalScaleFactor(varF[3], 0.9, 1, 1)).
constexpr double kVoxelGapFootScaleX = 0.9;
TimeFunction voxel_gap_foot_friction(const Schedule& schedule, double start, double mu_active, double mu_inactive,
                                     const VoxelActuation& model = {}, double switch_s = 1e-3);

}  // namespace morphfem
