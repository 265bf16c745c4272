// The smooth log barrier shared by ground contact and self-contact (IPC-style):
//
//   phi(s) = -(s - 1)^2 ln s   for 0 < s < 1,   0 for s >= 1,   +inf for s <= 0
//
// with s = d / dhat the gap d [m] relative to the barrier width dhat [m]. phi is
// C2 at s = 1 (phi = phi' = phi'' = 0 there), convex and decreasing on (0, 1),
// and tends to +inf as s -> 0.
//
// A contact point with area weight A [m^2] and barrier stiffness kappa [Pa] has
//   energy   E(d) = A kappa dhat phi(d / dhat)            [J]
//   force    -dE/dd = A kappa (-phi'(s))  >= 0            [N]  (pushes apart)
//   pressure p = kappa (-phi'(s))                          [Pa]
// so at a contact pressure p the gap settles where -phi'(s) = p / kappa; for
// p << kappa, s ~ 1 - sqrt(p / (3 kappa)) (the body rests just below dhat).
#pragma once
#include <cmath>

namespace morphfem {

// phi(s) and, if given, phi'(s), phi''(s). Requires s > 0 (callers test).
inline void log_barrier(double s, double& value, double* first, double* second) {
  if (s >= 1.0) {
    value = 0.0;
    if (first) *first = 0.0;
    if (second) *second = 0.0;
    return;
  }
  const double ln_s = std::log(s), sm1 = s - 1.0;
  value = -sm1 * sm1 * ln_s;
  // phi'(s)  = -2 (s - 1) ln s - (s - 1)^2 / s
  if (first) *first = -2.0 * sm1 * ln_s - sm1 * sm1 / s;
  // phi''(s) = -2 ln s - 2 (s - 1) / s - (s^2 - 1) / s^2
  if (second) *second = -2.0 * ln_s - 2.0 * sm1 / s - (s * s - 1.0) / (s * s);
}

inline double barrier_phi(double s) {
  double v;
  log_barrier(s, v, nullptr, nullptr);
  return v;
}
inline double barrier_dphi(double s) {
  double v, d;
  log_barrier(s, v, &d, nullptr);
  return d;
}
inline double barrier_d2phi(double s) {
  double v, d2;
  log_barrier(s, v, nullptr, &d2);
  return d2;
}

}  // namespace morphfem
