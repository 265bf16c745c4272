#include "sim/cadence.h"

namespace morphfem {

std::shared_ptr<ScheduleClock> make_schedule_clock(const Scene& scene) {
  if (!scene.settle) return nullptr;
  const SettleSpec& settle = *scene.settle;
  return std::make_shared<ScheduleClock>(settle.schedule, settle.start, settle.tolerance_pa);
}

GasCavitySpec clocked_gas_cavity(const Scene& scene, const Model& model, std::size_t index) {
  GasCavitySpec spec = scene.gas_cavities[index];
  if (!model.schedule_clock) return spec;
  for (const auto& [valve, channel] : scene.settle->valves)
    if (valve == index && channel != kChannelCore)
      spec.supply_gauge_pressure = TimeFunction::of(
          [clock = model.schedule_clock, channel = channel](double t) { return clock->setpoint_pa(channel, t); });
  return spec;
}

FrictionSpec clocked_friction(const Scene& scene, const Model& model) {
  FrictionSpec spec = *scene.friction;
  if (!model.schedule_clock) return spec;
  const SettleSpec& settle = *scene.settle;
  for (const auto& [region, channel] : settle.feet) {
    const TimeFunction mu = TimeFunction::of(
        [clock = model.schedule_clock, channel = channel, active = settle.mu_active,
         inactive = settle.mu_inactive](double t) { return clock->foot_mu(channel, t, active, inactive); });
    spec.regions[region].mu_static = spec.regions[region].mu_kinetic = mu;
  }
  return spec;
}

void watch_valves(Model& model) {
  if (!model.schedule_clock) return;
  for (const auto& [valve, channel] : model.scene.settle->valves)  // gas cavities come first in volume_driven
    model.watched_valves.emplace_back(channel, std::dynamic_pointer_cast<GasCavityTerm>(model.volume_driven[valve]));
}

void advance_schedule_clock(Model& model, double t) {
  if (!model.schedule_clock) return;
  std::vector<ScheduleClock::Reading> readings;
  for (const auto& [channel, valve] : model.watched_valves)
    readings.push_back({channel, valve->pressure(), valve->spec().supply_gauge_pressure(t)});
  model.schedule_clock->end_of_step(t, readings);
}

}  // namespace morphfem
