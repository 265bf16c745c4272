// The search genome of the voxel study (ROBOT.md "Genome for search"), its random
// initialisation and mutation, and the counter-based random streams that make a
// search independent of the number of MPI ranks and of evaluation order.
//
// Genome (actuation/schedule.h `Genome`, reused): orientation theta in 0..90 deg,
// core pressure p in 0..12000 Pa, ten pairs (f, phi) of integers in 0..8 (one per
// schedule row; rows built by actuation/schedule.h genome_row).
//
// Mutation (every free gene, one normal step each):
//   theta' = clamp(round(theta + 9 deg   * N(0,1)), 0, 90)
//   p'     = clamp(round(p     + 1200 Pa * N(0,1)), 0, 12000)
//   f'     = wrap9(round(f     + 0.9     * N(0,1)))       (same for phi)
// "Wrapped" follows the study's code (jpp46/NATURE_MI2020, worker*.jl): the
// orientation and the pressure are clipped to their range, the (f, phi) integers
// wrap cyclically (-1 -> 8, 9 -> 0). The study wraps once (x < 0 -> x + 9,
// x > 8 -> x - 9); wrap9 is the full modulo, identical whenever one wrap suffices
// (a step of 9 or more, 10 standard deviations, never happens in practice).
// Rounding is to nearest, ties to even (Julia's round), irrelevant for continuous steps.
// Initial genome: theta uniform in {0..90}, p uniform in {0..12000}, f and phi
// uniform in {0..8}; genes fixed by the experiment take the fixed value instead.
#pragma once
#include <array>
#include <cstdint>
#include <random>
#include <string>

#include "actuation/schedule.h"

namespace morphfem {

constexpr double kMaxOrientationDeg = 90;
constexpr double kMaxCorePressurePa = 12000;
constexpr int kGeneLevels = 9;  // f, phi in 0..8
// Mutation step standard deviations (the study's RATE = [90/10, MAX_PRESS/10, 9/10]).
constexpr double kOrientationStepDeg = 9;
constexpr double kCorePressureStepPa = 1200;
constexpr double kRowGeneStep = 0.9;
// Genes as a flat vector: [theta, p, f_1, phi_1, ..., f_10, phi_10].
constexpr int kGenomeLength = 2 + 2 * kNumRows;

// Which genes the search may change; fixed genes keep the given values.
struct GenomeSpace {
  bool orientation_free = true;
  bool pressure_free = true;
  double fixed_orientation_deg = 0;
  double fixed_core_pressure_pa = 0;
};

// Counter-based random stream: a std::mt19937_64 seeded from (seed, stream, counter)
// through SplitMix64, so the draws of climber c in generation g depend on nothing
// else. Normal draws by Box-Muller on 53-bit uniforms (portable across standard
// libraries, unlike std::normal_distribution).
class RandomStream {
 public:
  RandomStream(std::uint64_t seed, std::uint64_t stream, std::uint64_t counter);
  double uniform();             // [0, 1)
  int integer(int lo, int hi);  // uniform in lo..hi (inclusive)
  double normal();              // N(0, 1)

 private:
  std::mt19937_64 engine_;  // output sequence fixed by the C++ standard
  bool has_spare_ = false;
  double spare_ = 0;
};

// Integer x wrapped into 0..8 (period 9).
int wrap_gene(long x);
double clamp_round(double x, double lo, double hi);

Genome random_genome(const GenomeSpace& space, RandomStream& rng);
Genome mutate_genome(const Genome& parent, const GenomeSpace& space, RandomStream& rng);
// Same genome with the fixed genes of `space` imposed.
Genome impose_fixed(Genome g, const GenomeSpace& space);

std::array<double, kGenomeLength> genome_to_vector(const Genome& g);
// Inverse of genome_to_vector; throws InputError(where, ...) if a gene is out of range or not an integer.
Genome genome_from_vector(const std::array<double, kGenomeLength>& v, const std::string& where);
bool operator==(const Genome& a, const Genome& b);

// Hand-designed schedules of the study as genomes (ROBOT.md):
// rolling = bladders 8, 7, ..., 1 one per column, feet inactive, 0 deg, 12 kPa;
// inching = bladders 1-4 on odd columns, foot B odd, foot A even, 90 deg, 0 kPa.
// A row (8, 8) is all zeros (its only column, 9, lies outside 1..8).
Genome rolling_genome();
Genome inching_genome();

// A schedule file (actuation/schedule.h format, genome form, played `repeats`
// times) that read_schedule() turns back into exactly this genome.
std::string genome_schedule_yaml(const Genome& g, const std::string& name, int repeats = 2, double column_s = 1.237);

}  // namespace morphfem
