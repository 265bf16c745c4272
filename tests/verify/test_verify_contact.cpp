// Contact verification cases (VERIFICATION.md cases 9 and 10) at their
// quick level, against the bounds the issue states, and their building blocks.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <cmath>
#include <string>

#include "core/errors.h"
#include "mesh/geometry.h"
#include "verify/verify_contact.h"

using namespace morphfem;

namespace {

VerifyOptions quick() {
  VerifyOptions o;
  o.quick = true;
  o.progress = false;
  return o;
}

const VerificationRecord& find_record(const std::vector<VerificationRecord>& records, const std::string& prefix) {
  for (const auto& r : records)
    if (r.quantity.rfind(prefix, 0) == 0) return r;
  throw std::runtime_error("no record starting with '" + prefix + "'");
}

}  // namespace

TEST(VerifyContact, FittedAccelerationIsTheQuadraticCoefficient) {
  std::vector<double> t, s;
  for (int i = 0; i <= 20; ++i) {
    t.push_back(0.005 * i);
    s.push_back(0.3 + 0.2 * t.back() + 0.5 * 1.7 * t.back() * t.back());
  }
  EXPECT_NEAR(fitted_acceleration(t, s), 1.7, 1e-9);
  EXPECT_THROW(fitted_acceleration({0.0, 1.0}, {0.0, 1.0}), SolveError);
}

TEST(VerifyContact, NodalVolumeWeightsGiveVolumeAndCentroid) {
  ParamSet p("geometry");
  p.set_string("type", "solid_cylinder");
  p.set("radius", 0.02);
  p.set("length", 0.01);
  p.set("mesh_size", 0.007);
  p.set("order", 2);
  const Mesh mesh = build_geometry(p);
  const std::vector<double> w = nodal_volume_weights(mesh);
  double sum = 0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (int a = 0; a < mesh.n_nodes(); ++a) {
    sum += w[a];
    moment += w[a] * mesh.X.row(a).transpose();
  }
  EXPECT_NEAR(sum / mesh.volume(), 1.0, 1e-12);
  // int N_a dV reproduces the first moment of the (isoparametric) body: the
  // centroid of the cylinder is on its axis, at mid-length.
  const Eigen::Vector3d centroid = moment / sum;
  EXPECT_NEAR(centroid.x(), 0.0, 1e-5 * 0.02);
  EXPECT_NEAR(centroid.y(), 0.005, 1e-9);
  EXPECT_NEAR(centroid.z(), 0.0, 1e-5 * 0.02);
}

// Hertz (case 10) at d/R = 0.01: F within 5 % (the bound), contact radius
// within 5 %, on the quick mesh (contact-zone elements 0.25 mm = a/4).
TEST(VerifyContact, HertzQuickLevelMeetsTheBound) {
  std::vector<VerificationRecord> records;
  hertz_case(quick(), PETSC_COMM_WORLD, records);
  const auto& F = find_record(records, "contact force F");
  EXPECT_NEAR(F.reference, 0.17546, 1e-4);  // (4/3) E/(1 - nu^2) sqrt(R) d^1.5, nu = 0.49
  EXPECT_LT(F.rel_error, 0.05) << "F = " << F.value;
  const auto& a = find_record(records, "contact radius");
  EXPECT_LT(a.rel_error, 0.05) << "a = " << a.value;
}

// Rolling (case 9) on a 30 deg slope: mu = 1 rolls at (2/3) g sin within 3 %, mu =
// 0.1 slips at g (sin - mu cos) within 3 % (the bound), on the quick level.
TEST(VerifyContact, RollingQuickLevelMeetsTheBound) {
  std::vector<VerificationRecord> records;
  rolling_case(quick(), PETSC_COMM_WORLD, records);
  const auto& roll = find_record(records, "rolling a [m/s^2]");
  EXPECT_NEAR(roll.reference, 2.0 / 3.0 * 9.8 * 0.5, 1e-9);
  EXPECT_LT(roll.rel_error, 0.03) << "a = " << roll.value;
  const auto& slip = find_record(records, "slip a [m/s^2]");
  EXPECT_LT(slip.rel_error, 0.03) << "a = " << slip.value;
}
