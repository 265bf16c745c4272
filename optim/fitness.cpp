#include "optim/fitness.h"

#include <cmath>
#include <cstdlib>
#include <map>

#include "core/errors.h"
#include "core/strings.h"
#include "optim/genome.h"

namespace morphfem {

namespace {

struct Entry {
  FitnessFunction fn;
  std::string description;
};

// The registry, created on first use with the built-in fitnesses in it.
std::map<std::string, Entry>& registry() {
  static std::map<std::string, Entry> r = [] {
    std::map<std::string, Entry> m;
    m["synthetic"] = {[](const Genome& g, const Environment& env, const std::string& fidelity, MPI_Comm) {
                        return synthetic_speed(g, env, fidelity);
                      },
                      "analytic test function with a known optimum (levels: integer >= 0, or 'exact')"};
    return m;
  }();
  return r;
}

bool is_hill(const Environment& env) { return env.slope_deg >= 7.5; }

// Circular distance between two genes on 0..8 (period 9): 0..4.
int circular_distance(int a, int b) {
  const int d = std::abs(a - b) % kGeneLevels;
  return std::min(d, kGeneLevels - d);
}

}  // namespace

void register_fitness(const std::string& name, FitnessFunction fn, const std::string& description) {
  registry()[name] = {std::move(fn), description};
}

bool has_fitness(const std::string& name) { return registry().count(name) > 0; }

const FitnessFunction& find_fitness(const std::string& name) {
  auto it = registry().find(name);
  if (it == registry().end()) {
    throw InputError("--fitness", "unknown fitness '" + name + "' (known: " + join_keys(registry(), ", ") + ")");
  }
  return it->second.fn;
}

std::vector<std::string> fitness_descriptions() {
  std::vector<std::string> out;
  for (const auto& [n, e] : registry()) out.push_back(n + ": " + e.description);
  return out;
}

Genome synthetic_optimum(const Environment& env) { return is_hill(env) ? inching_genome() : rolling_genome(); }

double synthetic_speed(const Genome& g, const Environment& env, const std::string& fidelity) {
  const Genome target = synthetic_optimum(env);
  const bool hill = is_hill(env);
  const double v_max = hill ? 0.03 : 0.2;    // BL/s at the optimum
  const double v_back = hill ? 0.06 : 0.02;  // BL/s lost by the worst genome below zero
  const double d_theta = (g.orientation_deg - target.orientation_deg) / kMaxOrientationDeg;
  const double d_p = (g.core_pressure_pa - target.core_pressure_pa) / kMaxCorePressurePa;
  double d_rows = 0;
  for (int r = 0; r < kNumRows; ++r) {
    const double df = circular_distance(g.rows[r].f, target.rows[r].f) / 4.0;
    const double dphi = circular_distance(g.rows[r].phi, target.rows[r].phi) / 4.0;
    d_rows += (df * df + dphi * dphi) / (2 * kNumRows);
  }
  const double penalty = 0.3 * d_theta * d_theta + 0.3 * d_p * d_p + 0.4 * d_rows;
  double speed = v_max - (v_max + v_back) * penalty;
  if (fidelity == "exact") return speed;
  char* end = nullptr;
  const long level = std::strtol(fidelity.c_str(), &end, 10);
  if (fidelity.empty() || *end != '\0' || level < 0 || level > 60)
    throw InputError("--fidelity",
                     "the synthetic fitness takes an integer level 0..60 or 'exact', got '" + fidelity + "'");
  double phase = 0.37 * g.orientation_deg + 0.0011 * g.core_pressure_pa;
  for (int r = 0; r < kNumRows; ++r) phase += (1.3 * g.rows[r].f + 0.7 * g.rows[r].phi) * (r + 1);
  return speed + 0.02 * std::ldexp(1.0, -static_cast<int>(level)) * std::sin(phase);
}

}  // namespace morphfem
