// Step control of a scheduled scene: steps land on the loads' breakpoints (the
// schedule's column boundaries and ramp ends), the steps up to each stop are equal and
// no longer than max_step, and breakpoints closer than kBreakpointMerge * max_step to
// the one before share its stop.
#include <gtest/gtest.h>
#include <petscsys.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fem/solver.h"
#include "sim/scene.h"
#include "sim/simulation.h"
#include "tests/support/temp_dir.h"
#include "tests/support/tube_scene.h"

namespace morphfem {
namespace {

// b1 inflates in column 1 over a 0.03 s ramp, deflates in column 2 with a step (1 ms,
// channel_pressure's step_s) and inflates again in column 3; columns of 0.137 s from
// start = 0.05 s, steps of at most 0.06 s (breakpoints within 1.2 ms merge).
const std::string kTube = "name: breakpoint_tube\n" +
                          quarter_tube("inner_radius: 0.005, outer_radius: 0.01, height: 0.004, mesh_size: 0.004",
                                       "{model: dragon_skin_30}") +
                          R"(actuation:
  schedule: {morphfem_schedule: 1, column_s: 0.137,
             matrix: ["101", "000", "000", "000", "000", "000", "000", "000", "000", "000"],
             pressures: {b1: {inflate_pa: 20000, deflate_pa: 0, inflate_ramp_s: 0.03, deflate_ramp_s: 0},
                         feet: {inflate_pa: 0, deflate_pa: 0}}}
  start: 0.05
  bladders: {b1: inner}
  volume_axes: [x, y]
solver: {end_time: 0.5, initial_step: 0.06, max_step: 0.06}
output: {every: 1000, checkpoint_s: 0}
)";

std::vector<double> step_times(bool land_on_breakpoints) {
  YAML::Node doc = YAML::Load(kTube);
  const auto dir = temp_dir(land_on_breakpoints ? "steps_land" : "steps_free");
  doc["output"]["directory"] = (dir / "out").string();
  doc["solver"]["land_on_breakpoints"] = land_on_breakpoints;
  const Scene scene = scene_from_yaml(doc, (dir / "scene.yaml").string());
  RunOptions options;
  options.progress = false;
  const auto result = run_scene(scene, PETSC_COMM_WORLD, options);
  EXPECT_TRUE(result.stats.completed) << result.stats.failure;
  std::vector<double> times;
  for (const auto& row : result.trajectory) times.push_back(row[0]);
  return times;
}

bool has_time(const std::vector<double>& times, double t) {
  return std::any_of(times.begin(), times.end(), [&](double s) { return std::abs(s - t) < 1e-12; });
}

TEST(StepControl, StepsLandOnTheScheduleBreakpointsInEqualSteps) {
  const double start = 0.05, column = 0.137, ramp = 0.03, max_step = 0.06;
  const std::vector<double> times = step_times(true);
  ASSERT_GT(times.size(), 2u);
  // The ramps' ends and starts, the deflation and the gait's end are step ends.
  const std::vector<double> stops = {
      start, start + ramp, start + column, start + 2 * column, start + 2 * column + ramp, start + 3 * column, 0.5};
  for (double t : stops) EXPECT_TRUE(has_time(times, t)) << "no step ends at the breakpoint t = " << t << " s";
  // The end of column 2's 1 ms deflation step shares the column boundary's stop.
  EXPECT_FALSE(has_time(times, start + column + 1e-3)) << "a 1 ms switch should not be a stop of its own";
  // Steps are at most max_step, and equal between consecutive stops.
  for (std::size_t i = 1; i < times.size(); ++i) {
    const double h = times[i] - times[i - 1];
    EXPECT_LE(h, max_step * (1 + 1e-12)) << "step ending at " << times[i];
    const auto next = std::lower_bound(stops.begin(), stops.end(), times[i] - 1e-12);
    if (i + 1 < times.size() && next != stops.end() && times[i + 1] <= *next + 1e-12 &&
        std::abs(times[i] - *next) > 1e-12) {
      EXPECT_NEAR(times[i + 1] - times[i], h, 1e-12) << "unequal steps before the stop " << *next;
    }
  }
  // The same scene without landing: the first column boundary is crossed, not hit.
  EXPECT_FALSE(has_time(step_times(false), start + column));
}

}  // namespace
}  // namespace morphfem
