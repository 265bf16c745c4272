#include "optim/genome.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <sstream>

#include "core/errors.h"

namespace morphfem {

namespace {

// SplitMix64 finaliser: a bijective 64-bit mix (Steele, Lea, Flood 2014).
std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Shortest decimal form that reads back as the same double.
std::string shortest(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace

RandomStream::RandomStream(std::uint64_t seed, std::uint64_t stream, std::uint64_t counter)
    : engine_(splitmix64(splitmix64(splitmix64(seed) ^ stream) ^ counter)) {}

double RandomStream::uniform() {
  // 53 random bits -> [0, 1) with spacing 2^-53.
  return static_cast<double>(engine_() >> 11) * 0x1.0p-53;
}

int RandomStream::integer(int lo, int hi) {
  // Rejection sampling keeps every value exactly equally likely.
  const std::uint64_t span = static_cast<std::uint64_t>(hi - lo) + 1;
  const std::uint64_t limit = UINT64_MAX - UINT64_MAX % span;
  std::uint64_t x;
  do x = engine_();
  while (x >= limit);
  return lo + static_cast<int>(x % span);
}

double RandomStream::normal() {
  // Box-Muller: z0 = sqrt(-2 ln u1) cos(2 pi u2), z1 = sqrt(-2 ln u1) sin(2 pi u2).
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  const double u1 = 1.0 - uniform();  // (0, 1]: log is finite
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * std::numbers::pi * u2);
  has_spare_ = true;
  return r * std::cos(2.0 * std::numbers::pi * u2);
}

int wrap_gene(long x) {
  long r = x % kGeneLevels;
  return static_cast<int>(r < 0 ? r + kGeneLevels : r);
}

double clamp_round(double x, double lo, double hi) {
  const double r = std::nearbyint(x);  // default rounding mode: nearest, ties to even
  return r < lo ? lo : (r > hi ? hi : r);
}

Genome impose_fixed(Genome g, const GenomeSpace& space) {
  if (!space.orientation_free) g.orientation_deg = space.fixed_orientation_deg;
  if (!space.pressure_free) g.core_pressure_pa = space.fixed_core_pressure_pa;
  return g;
}

Genome random_genome(const GenomeSpace& space, RandomStream& rng) {
  Genome g;
  // Draw every gene even when fixed, so free and fixed spaces share the row draws.
  g.orientation_deg = rng.integer(0, static_cast<int>(kMaxOrientationDeg));
  g.core_pressure_pa = rng.integer(0, static_cast<int>(kMaxCorePressurePa));
  for (auto& row : g.rows) {
    row.f = rng.integer(0, kGeneLevels - 1);
    row.phi = rng.integer(0, kGeneLevels - 1);
  }
  return impose_fixed(g, space);
}

Genome mutate_genome(const Genome& parent, const GenomeSpace& space, RandomStream& rng) {
  Genome child = parent;
  // Fixed genes consume no draws (as in the study's semi/closed workers).
  if (space.orientation_free)
    child.orientation_deg =
        clamp_round(parent.orientation_deg + kOrientationStepDeg * rng.normal(), 0, kMaxOrientationDeg);
  if (space.pressure_free)
    child.core_pressure_pa =
        clamp_round(parent.core_pressure_pa + kCorePressureStepPa * rng.normal(), 0, kMaxCorePressurePa);
  for (int r = 0; r < kNumRows; ++r) {
    child.rows[r].f = wrap_gene(std::lrint(parent.rows[r].f + kRowGeneStep * rng.normal()));
    child.rows[r].phi = wrap_gene(std::lrint(parent.rows[r].phi + kRowGeneStep * rng.normal()));
  }
  return impose_fixed(child, space);
}

std::array<double, kGenomeLength> genome_to_vector(const Genome& g) {
  std::array<double, kGenomeLength> v{};
  v[0] = g.orientation_deg;
  v[1] = g.core_pressure_pa;
  for (int r = 0; r < kNumRows; ++r) {
    v[2 + 2 * r] = g.rows[r].f;
    v[3 + 2 * r] = g.rows[r].phi;
  }
  return v;
}

Genome genome_from_vector(const std::array<double, kGenomeLength>& v, const std::string& where) {
  auto integer_in = [&](double x, double hi, const std::string& what) {
    if (!(x >= 0 && x <= hi) || x != std::floor(x))
      throw InputError(where, what + " must be an integer in 0.." + std::to_string(static_cast<int>(hi)) + ", got " +
                                  std::to_string(x));
    return x;
  };
  Genome g;
  g.orientation_deg = integer_in(v[0], kMaxOrientationDeg, "orientation_deg");
  g.core_pressure_pa = integer_in(v[1], kMaxCorePressurePa, "core_pressure_pa");
  for (int r = 0; r < kNumRows; ++r) {
    g.rows[r].f = static_cast<int>(integer_in(v[2 + 2 * r], kGeneLevels - 1, "row " + std::to_string(r + 1) + " f"));
    g.rows[r].phi =
        static_cast<int>(integer_in(v[3 + 2 * r], kGeneLevels - 1, "row " + std::to_string(r + 1) + " phi"));
  }
  return g;
}

bool operator==(const Genome& a, const Genome& b) { return genome_to_vector(a) == genome_to_vector(b); }

Genome rolling_genome() {
  Genome g;
  g.orientation_deg = 0;
  g.core_pressure_pa = kMaxCorePressurePa;
  // Bladder b (1..8) inflated in column 9 - b only: period 9 (f = 8), anchor phi + 1 = 9 - b.
  for (int b = 1; b <= kNumBladders; ++b) g.rows[b - 1] = {8, 8 - b};
  g.rows[8] = {8, 8};  // foot A inactive throughout
  g.rows[9] = {8, 8};  // foot B inactive throughout
  return g;
}

Genome inching_genome() {
  Genome g;
  g.orientation_deg = kMaxOrientationDeg;
  g.core_pressure_pa = 0;
  for (int b = 1; b <= 4; ++b) g.rows[b - 1] = {1, 0};  // odd columns 1, 3, 5, 7
  for (int b = 5; b <= 8; ++b) g.rows[b - 1] = {8, 8};  // never
  g.rows[8] = {1, 1};                                   // foot A: even columns 2, 4, 6, 8
  g.rows[9] = {1, 0};                                   // foot B: odd columns
  return g;
}

std::string genome_schedule_yaml(const Genome& g, const std::string& name, int repeats, double column_s) {
  std::ostringstream o;
  o.precision(17);
  o << "morphfem_schedule: 1\n"
    << "name: \"" << name << "\"\n"
    << "column_s: " << shortest(column_s) << "\n"
    << "repeats: " << repeats << "\n"
    << "genome:\n"
    << "  orientation_deg: " << g.orientation_deg << "\n"
    << "  core_pressure_pa: " << g.core_pressure_pa << "\n"
    << "  columns: 8\n"
    << "  rows: [";
  for (int r = 0; r < kNumRows; ++r) o << (r ? ", " : "") << '[' << g.rows[r].f << ", " << g.rows[r].phi << ']';
  o << "]  # (f, phi) per row: bladders 1-8, foot A, foot B\n";
  return o.str();
}

}  // namespace morphfem
