// Hyperelastic laws: stress and tangent against finite differences at random and
// special states (F = I, uniaxial, equibiaxial, nearly repeated stretches), symmetry,
// objectivity, small-strain moduli, closed forms, parameter validation.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "core/errors.h"
#include "fem/kinematics.h"
#include "fem/material.h"
#include "fem/material_fit.h"

namespace morphfem {
namespace {

struct LawCase {
  std::string label;
  ParamSet params;
};

ParamSet make_params(const std::string& model, std::vector<std::pair<std::string, std::vector<double>>> numbers,
                     std::vector<std::pair<std::string, std::string>> strings = {}) {
  ParamSet p("material");
  p.set_string("model", model);
  for (auto& [k, v] : numbers) p.set(k, v);
  for (auto& [k, v] : strings) p.set_string(k, v);
  return p;
}

// Every registered law with its registry example (fem/material.cpp), so that a law is
// checked by being registered, and further parameterisations of the same laws.
std::vector<LawCase> law_cases() {
  std::vector<LawCase> cases;
  for (const auto& [name, law] : material_registry()) cases.push_back({name, example_parameters(name)});
  cases.push_back(
      {"ogden3", make_params("ogden", {{"mu", {15e3, 1e3, -500.0}}, {"alpha", {1.8, 5.0, -2.0}}, {"kappa", {5e5}}})});
  cases.push_back({"dragon_skin_30_neo", make_params("dragon_skin_30", {{"kappa", {3e6}}}, {{"law", "neo_hookean"}})});
  return cases;
}

Mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Vector4d q(n(rng), n(rng), n(rng), n(rng));
  return Eigen::Quaterniond(q.normalized()).toRotationMatrix();
}

// F = R1 diag(s) R2 with principal stretches s in [0.6, 1.6].
Mat3 random_F(std::mt19937& rng) {
  std::uniform_real_distribution<double> s(0.6, 1.6);
  return random_rotation(rng) * Eigen::Vector3d(s(rng), s(rng), s(rng)).asDiagonal() * random_rotation(rng);
}

// The states every law is checked at: F = I, uniaxial and equibiaxial (two equal
// principal stretches, rotated), pure dilatation (three equal), nearly repeated
// stretches, simple shear, random.
std::vector<std::pair<std::string, Mat3>> test_states() {
  std::mt19937 rng(20240611);
  const Mat3 R = random_rotation(rng), Q = random_rotation(rng);
  std::vector<std::pair<std::string, Mat3>> states = {
      {"identity", Mat3::Identity()},
      {"uniaxial", Mat3(Eigen::Vector3d(1.5, 0.83, 0.83).asDiagonal())},
      {"uniaxial_rotated", R * Eigen::Vector3d(0.7, 1.2, 1.2).asDiagonal() * Q},
      {"equibiaxial_rotated", R * Eigen::Vector3d(1.3, 1.3, 0.6).asDiagonal() * Q},
      {"dilatation", Mat3(1.1 * Mat3::Identity())},
      {"nearly_repeated", R * Eigen::Vector3d(1.2, 1.2 + 1e-7, 0.9).asDiagonal() * Q},
      {"simple_shear", Mat3{{1.0, 0.4, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}},
  };
  for (int k = 0; k < 5; ++k) states.push_back({"random" + std::to_string(k), random_F(rng)});
  return states;
}

Vec9 fd_stress(const Material& m, const Mat3& F, double h) {
  Vec9 P;
  for (int a = 0; a < 9; ++a) {
    Mat3 Fp = F, Fm = F;
    Fp(a / 3, a % 3) += h;
    Fm(a / 3, a % 3) -= h;
    P(a) = (m.energy(Fp) - m.energy(Fm)) / (2 * h);
  }
  return P;
}

Tangent fd_tangent(const Material& m, const Mat3& F, double h) {
  Tangent A;
  for (int b = 0; b < 9; ++b) {
    Mat3 Fp = F, Fm = F, Pp, Pm;
    double W;
    Fp(b / 3, b % 3) += h;
    Fm(b / 3, b % 3) -= h;
    m.evaluate(Fp, W, Pp, nullptr);
    m.evaluate(Fm, W, Pm, nullptr);
    A.col(b) = (flatten(Pp) - flatten(Pm)) / (2 * h);
  }
  return A;
}

TEST(MaterialLaw, StressAndTangentMatchFiniteDifferences) {
  for (const auto& law : law_cases()) {
    const auto m = make_material(law.params);
    const double mu = m->shear_modulus();
    int checked = 0;
    for (const auto& [state, F] : test_states()) {
      SCOPED_TRACE(law.label + " at " + state);
      if (!m->smooth_near(F, 1e-6)) continue;  // a kink within the difference step (a slack fibre)
      ++checked;
      double W;
      Mat3 P;
      Tangent A;
      m->evaluate(F, W, P, &A);
      EXPECT_NEAR(W, m->energy(F), 1e-12 * (std::abs(W) + mu));
      const Vec9 P_fd = fd_stress(*m, F, 1e-6);
      EXPECT_LE((flatten(P) - P_fd).cwiseAbs().maxCoeff(), 1e-7 * (P.cwiseAbs().maxCoeff() + mu));
      // Relative to the shear modulus (not to max |A| ~ kappa), so that errors in the
      // isochoric part are not hidden by the stiffer volumetric part.
      const Tangent A_fd = fd_tangent(*m, F, 1e-6);
      EXPECT_LE((A - A_fd).cwiseAbs().maxCoeff(), 1e-6 * mu);
      // Major symmetry A(iJ, kL) = A(kL, iJ) (A is a Hessian).
      EXPECT_LE((A - A.transpose()).cwiseAbs().maxCoeff(), 1e-12 * A.cwiseAbs().maxCoeff());
      // P without the tangent is the same P.
      Mat3 P_only;
      m->evaluate(F, W, P_only, nullptr);
      EXPECT_LE((P_only - P).cwiseAbs().maxCoeff(), 1e-12 * (P.cwiseAbs().maxCoeff() + mu));
      // The split of material.h: W = W_iso(F) + U(det F).
      double W_iso, U, dU, d2U;
      Mat3 P_iso;
      m->evaluate_isochoric(F, W_iso, P_iso, nullptr);
      m->volumetric_energy(F.determinant(), U, dU, d2U);
      EXPECT_NEAR(W_iso + U, W, 1e-10 * (std::abs(W) + mu));
    }
    EXPECT_GE(checked, 8) << law.label << ": too few smooth states checked";
  }
}

TEST(MaterialLaw, ObjectiveAndStressFreeAtIdentity) {
  std::mt19937 rng(7);
  for (const auto& law : law_cases()) {
    SCOPED_TRACE(law.label);
    const auto m = make_material(law.params);
    const double mu = m->shear_modulus();
    double W;
    Mat3 P;
    m->evaluate(Mat3::Identity(), W, P, nullptr);
    EXPECT_NEAR(W, 0.0, 1e-12 * mu);
    EXPECT_LE(P.cwiseAbs().maxCoeff(), 1e-12 * mu);
    for (int k = 0; k < 3; ++k) {
      const Mat3 F = random_F(rng), R = random_rotation(rng);
      double W_rot;
      Mat3 P_rot;
      m->evaluate(F, W, P, nullptr);
      m->evaluate(R * F, W_rot, P_rot, nullptr);
      EXPECT_NEAR(W_rot, W, 1e-11 * (std::abs(W) + mu));
      EXPECT_LE((P_rot - R * P).cwiseAbs().maxCoeff(), 1e-10 * (P.cwiseAbs().maxCoeff() + mu));
    }
  }
}

TEST(MaterialLaw, SmallStrainTangentIsLinearElasticity) {
  // At F = I: A_iJkL = lambda d_iJ d_kL + mu (d_ik d_JL + d_iL d_Jk), lambda = kappa - 2 mu / 3.
  for (const auto& law : law_cases()) {
    SCOPED_TRACE(law.label);
    const auto m = make_material(law.params);
    if (!m->isotropic()) continue;
    const double mu = m->shear_modulus(), kappa = m->bulk_modulus(), lame = kappa - 2.0 * mu / 3.0;
    double W;
    Mat3 P;
    Tangent A;
    m->evaluate(Mat3::Identity(), W, P, &A);
    Tangent expected = Tangent::Zero();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l)
            expected(3 * i + j, 3 * k + l) =
                lame * (i == j) * (k == l) + mu * ((i == k) * (j == l) + (i == l) * (j == k));
    EXPECT_LE((A - expected).cwiseAbs().maxCoeff(), 1e-10 * kappa);
  }
}

TEST(MaterialLaw, EnergyInfiniteForInvertedElements) {
  for (const auto& law : law_cases()) {
    const auto m = make_material(law.params);
    EXPECT_EQ(m->energy(Eigen::Vector3d(1.0, 1.0, -0.5).asDiagonal()), std::numeric_limits<double>::infinity())
        << law.label;
    EXPECT_EQ(m->energy(Mat3::Zero()), std::numeric_limits<double>::infinity()) << law.label;
  }
}

// Uniaxial tension F = diag(l, t, t): Newton on the lateral stretch t until P22 = 0;
// returns P11.
double uniaxial_P11(const Material& m, double l) {
  double t = 1.0 / std::sqrt(l), W;
  Mat3 P;
  Tangent A;
  for (int it = 0; it < 50; ++it) {
    const Mat3 F = Eigen::Vector3d(l, t, t).asDiagonal();
    m.evaluate(F, W, P, &A);
    const double dP22_dt = A(4, 4) + A(4, 8);
    const double dt = -P(1, 1) / dP22_dt;
    t += dt;
    if (std::abs(dt) < 1e-15 * t) break;
  }
  m.evaluate(Eigen::Vector3d(l, t, t).asDiagonal(), W, P, nullptr);
  EXPECT_LE(std::abs(P(1, 1)), 1e-9 * std::abs(P(0, 0)));
  return P(0, 0);
}

TEST(MaterialLaw, NeoHookeanNearlyIncompressibleUniaxialMatchesClosedForm) {
  const double mu = 80e3;
  const auto m = make_material(make_params("neo_hookean", {{"mu", {mu}}, {"kappa", {1e6 * mu}}}));
  for (double l : {0.7, 1.3, 2.0, 3.0}) {
    // P11 = mu (l - l^-2) up to O(mu / kappa).
    EXPECT_NEAR(uniaxial_P11(*m, l), mu * (l - 1.0 / (l * l)), 1e-5 * mu) << "stretch " << l;
  }
}

TEST(MaterialLaw, FitClosedFormsMatchNearlyIncompressibleLaws) {
  // The uniaxial closed forms used by the fits (material_fit.h) are the incompressible
  // limits of the 3-D laws.
  const double c1 = 21.6e3, c2 = 3.0e3, c3 = -110.0, kappa = 2e6 * c1;
  const auto yeoh = make_material(make_params("yeoh", {{"c1", {c1}}, {"c2", {c2}}, {"c3", {c3}}, {"kappa", {kappa}}}));
  const std::vector<double> mu = {15e3, 1e3}, alpha = {1.8, 5.0};
  const auto ogden = make_material(make_params("ogden", {{"mu", mu}, {"alpha", alpha}, {"kappa", {kappa}}}));
  for (double l : {0.8, 1.5, 2.5}) {
    const double P_yeoh = uniaxial_stress_yeoh(l, c1, c2, c3), P_ogden = uniaxial_stress_ogden(l, mu, alpha);
    EXPECT_NEAR(uniaxial_P11(*yeoh, l), P_yeoh, 1e-5 * std::abs(P_yeoh)) << "stretch " << l;
    EXPECT_NEAR(uniaxial_P11(*ogden, l), P_ogden, 1e-5 * std::abs(P_ogden)) << "stretch " << l;
  }
}

TEST(MaterialLaw, NeoHookeanSimpleShear) {
  // At J = 1 the volumetric part vanishes: sigma12 = mu gamma, sigma11 - sigma22 = mu gamma^2.
  const double mu = 1.7e5;
  const auto m = make_material(make_params("neo_hookean", {{"mu", {mu}}, {"nu", {0.49}}}));
  for (double gamma : {0.1, 0.5, 1.5}) {
    const Mat3 F{{1.0, gamma, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    double W;
    Mat3 P;
    m->evaluate(F, W, P, nullptr);
    const Mat3 sigma = P * F.transpose() / F.determinant();
    EXPECT_NEAR(sigma(0, 1), mu * gamma, 1e-12 * mu);
    EXPECT_NEAR(sigma(0, 0) - sigma(1, 1), mu * gamma * gamma, 1e-12 * mu);
    EXPECT_NEAR(W, 0.5 * mu * gamma * gamma, 1e-12 * mu);
  }
}

TEST(MaterialLaw, OgdenWithAlphaTwoIsNeoHookean) {
  const double mu = 5e4, kappa = 2e6;
  const auto ogden = make_material(make_params("ogden", {{"mu", {mu}}, {"alpha", {2.0}}, {"kappa", {kappa}}}));
  const auto neo = make_material(make_params("neo_hookean", {{"mu", {mu}}, {"kappa", {kappa}}}));
  EXPECT_DOUBLE_EQ(ogden->shear_modulus(), mu);
  for (const auto& [state, F] : test_states()) {
    SCOPED_TRACE(state);
    double W1, W2;
    Mat3 P1, P2;
    Tangent A1, A2;
    ogden->evaluate(F, W1, P1, &A1);
    neo->evaluate(F, W2, P2, &A2);
    EXPECT_NEAR(W1, W2, 1e-12 * (std::abs(W2) + mu));
    EXPECT_LE((P1 - P2).cwiseAbs().maxCoeff(), 1e-11 * (P2.cwiseAbs().maxCoeff() + mu));
    EXPECT_LE((A1 - A2).cwiseAbs().maxCoeff(), 1e-11 * A2.cwiseAbs().maxCoeff());
  }
}

TEST(MaterialLaw, OgdenTangentContinuousAtRepeatedStretches) {
  // Exactly repeated vs. split by 1e-9: the tangent must not jump.
  const auto m = make_material(make_params("ogden", {{"mu", {15e3, 1e3}}, {"alpha", {1.8, 5.0}}, {"kappa", {5e5}}}));
  for (const auto& s :
       {Eigen::Vector3d(1.0, 1.0, 1.0), Eigen::Vector3d(1.4, 0.85, 0.85), Eigen::Vector3d(1.2, 1.2, 0.7)}) {
    double W;
    Mat3 P;
    Tangent A_exact, A_split;
    m->evaluate(s.asDiagonal(), W, P, &A_exact);
    m->evaluate(Eigen::Vector3d(s(0), s(1) * (1 + 1e-9), s(2) * (1 - 1e-9)).asDiagonal(), W, P, &A_split);
    EXPECT_LE((A_exact - A_split).cwiseAbs().maxCoeff(), 1e-7 * A_exact.cwiseAbs().maxCoeff());
  }
}

TEST(MaterialLaw, ModuliReported) {
  auto mr = make_material(make_params("mooney_rivlin", {{"c10", {30e3}}, {"c01", {8e3}}, {"kappa", {1e6}}}));
  EXPECT_DOUBLE_EQ(mr->shear_modulus(), 76e3);
  EXPECT_DOUBLE_EQ(mr->bulk_modulus(), 1e6);
  auto yeoh = make_material(make_params("yeoh", {{"c1", {20e3}}, {"nu", {0.45}}}));
  EXPECT_DOUBLE_EQ(yeoh->shear_modulus(), 40e3);
  EXPECT_NEAR(yeoh->bulk_modulus(), 2 * 40e3 * 1.45 / (3 * 0.1), 1e-6);
  auto ogden = make_material(make_params("ogden", {{"mu", {10e3, -100.0}}, {"alpha", {2.0, -4.0}}, {"kappa", {1e6}}}));
  EXPECT_DOUBLE_EQ(ogden->shear_modulus(), 10e3 + 200.0);
  EXPECT_EQ(ogden->name(), "ogden");
  // Presets: nu = 0.49 by default.
  auto ds10 = make_material(make_params("dragon_skin_10", {}));
  EXPECT_EQ(ds10->name(), "yeoh");
  EXPECT_NEAR(ds10->bulk_modulus(), 2 * ds10->shear_modulus() * 1.49 / (3 * 0.02), 1e-6 * ds10->bulk_modulus());
  auto ds30_neo = make_material(make_params("dragon_skin_30", {{"nu", {0.45}}}, {{"law", "neo_hookean"}}));
  EXPECT_EQ(ds30_neo->name(), "neo_hookean");
  EXPECT_NEAR(ds30_neo->bulk_modulus(), 2 * ds30_neo->shear_modulus() * 1.45 / (3 * 0.1), 1e-3);
}

TEST(MaterialLaw, RegistryNames) {
  for (const char* name :
       {"neo_hookean", "mooney_rivlin", "yeoh", "ogden", "fabric", "dragon_skin_10", "dragon_skin_30"})
    EXPECT_EQ(material_registry().count(name), 1u) << name;
}

// Expects make_material to throw an InputError whose message contains `needle`.
void expect_input_error(const ParamSet& p, const std::string& needle) {
  try {
    make_material(p);
    ADD_FAILURE() << "no InputError; expected one containing '" << needle << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(MaterialLaw, RejectsBadParameters) {
  expect_input_error(make_params("rubber", {}), "unknown material model 'rubber'");
  expect_input_error(make_params("neo_hookean", {{"mu", {1e5}}}), "give kappa [Pa] or nu");
  expect_input_error(make_params("neo_hookean", {{"mu", {1e5}}, {"kappa", {1e6}}, {"nu", {0.4}}}), "not both");
  expect_input_error(make_params("neo_hookean", {{"mu", {-1.0}}, {"kappa", {1e6}}}), "mu");
  expect_input_error(make_params("neo_hookean", {{"mu", {1e5}}, {"nu", {0.5}}}), "nu = 0.5");
  expect_input_error(make_params("neo_hookean", {{"mu", {1e5}}, {"kapa", {1e6}}}), "unknown key 'kapa'");
  expect_input_error(make_params("mooney_rivlin", {{"c10", {30e3}}, {"c01", {-2e3}}, {"kappa", {1e6}}}), "not stable");
  expect_input_error(make_params("mooney_rivlin", {{"c10", {0.0}}, {"c01", {0.0}}, {"kappa", {1e6}}}),
                     "c10 + c01 must be > 0");
  expect_input_error(make_params("yeoh", {{"c1", {20e3}}, {"c3", {-5e3}}, {"kappa", {1e6}}}), "unstable");
  expect_input_error(make_params("ogden", {{"mu", {1e3, 2e3}}, {"alpha", {2.0}}, {"kappa", {1e6}}}),
                     "one alpha per mu");
  expect_input_error(make_params("ogden", {{"mu", {1e3}}, {"alpha", {0.0}}, {"kappa", {1e6}}}), "nonzero");
  expect_input_error(make_params("ogden", {{"mu", {1e3, -1e3}}, {"alpha", {2.0, 3.0}}, {"kappa", {1e6}}}),
                     "mu_p alpha_p > 0");
  expect_input_error(make_params("dragon_skin_10", {}, {{"law", "ogden"}}), "unknown preset law");
  expect_input_error(make_params("dragon_skin_10", {{"mu", {1.0}}}), "unknown key 'mu'");
  expect_input_error(make_params("fabric", {{"mu", {1e5}}, {"nu", {0.3}}}), "fibre_modulus");
  expect_input_error(make_params("fabric", {{"mu", {1e5}}, {"nu", {0.3}}, {"fibre_modulus", {-1e8}}}), "fibre modulus");
  expect_input_error(
      make_params("fabric", {{"mu", {1e5}}, {"nu", {0.3}}, {"fibre_modulus", {1e8}}, {"fibres", {1, 0, 0, 1}}}),
      "3 numbers per fibre family");
  expect_input_error(
      make_params("fabric", {{"mu", {1e5}}, {"nu", {0.3}}, {"fibre_modulus", {1e8}}, {"fibres", {1, 0, 0, 0, 0, 0}}}),
      "family 2 has no direction");
  expect_input_error(make_params("fabric", {{"mu", {1e5}}, {"fibre_modulus", {1e8}}}), "give kappa [Pa] or nu");
}

// Fabric: stress and tangent against finite differences at states where no fibre is
// within 1e-3 of going slack (the tangent jumps there), with the warp, the weft and an
// oblique family; the tangent is checked relative to the fibre modulus.
TEST(MaterialLaw, FabricStressAndTangentMatchFiniteDifferences) {
  const double Ef = 1e8;
  const auto m = make_material(make_params(
      "fabric", {{"mu", {1e5}}, {"nu", {0.3}}, {"fibre_modulus", {Ef}}, {"fibres", {1, 0, 0, 0, 1, 0, 1, 1, 0}}}));
  const std::vector<Eigen::Vector3d> fibres = {{1, 0, 0}, {0, 1, 0}, Eigen::Vector3d(1, 1, 0).normalized()};
  int checked = 0, taut = 0;
  for (const auto& [state, F] : test_states()) {
    bool near_kink = false;
    for (const auto& a : fibres) {
      const double s = (F * a).squaredNorm() - 1.0;
      near_kink = near_kink || std::abs(s) < 1e-3;
      taut += s > 0;
    }
    if (near_kink) continue;
    SCOPED_TRACE(state);
    ++checked;
    double W;
    Mat3 P;
    Tangent A;
    m->evaluate(F, W, P, &A);
    EXPECT_NEAR(W, m->energy(F), 1e-12 * (std::abs(W) + Ef));
    EXPECT_LE((flatten(P) - fd_stress(*m, F, 1e-6)).cwiseAbs().maxCoeff(), 1e-7 * (P.cwiseAbs().maxCoeff() + Ef));
    EXPECT_LE((A - fd_tangent(*m, F, 1e-6)).cwiseAbs().maxCoeff(), 1e-6 * Ef);
    EXPECT_LE((A - A.transpose()).cwiseAbs().maxCoeff(), 1e-12 * A.cwiseAbs().maxCoeff());
    // The split of material.h holds: W = W_iso + U(J).
    double Wiso, U, dU, d2U;
    Mat3 Piso;
    m->evaluate_isochoric(F, Wiso, Piso, nullptr);
    m->volumetric_energy(F.determinant(), U, dU, d2U);
    EXPECT_NEAR(Wiso + U, W, 1e-10 * (std::abs(W) + Ef));
  }
  EXPECT_GE(checked, 8);
  EXPECT_GE(taut, 10);  // the states stretch fibres, not only slacken them
}

// Uniaxial stress along the warp of a fabric with only warp fibres: the matrix's own
// uniaxial stress plus the fibre's P11 = E_f / 2 (l^2 - 1) l in tension, and exactly the
// matrix's in compression (the fibre buckles). The fibre leaves the lateral
// equilibrium P22 = P33 = 0 unchanged, so the comparison is exact.
TEST(MaterialLaw, FabricFibresCarryTensionOnly) {
  const double Ef = 5e7;
  const auto fabric = make_material(
      make_params("fabric", {{"mu", {1e5}}, {"nu", {0.3}}, {"fibre_modulus", {Ef}}, {"fibres", {1, 0, 0}}}));
  const auto matrix = make_material(make_params("neo_hookean", {{"mu", {1e5}}, {"nu", {0.3}}}));
  for (double l : {1.01, 1.05, 1.2}) {
    const double expected = uniaxial_P11(*matrix, l) + 0.5 * Ef * (l * l - 1.0) * l;
    EXPECT_NEAR(uniaxial_P11(*fabric, l), expected, 1e-9 * expected) << "stretch " << l;
  }
  for (double l : {0.5, 0.8, 0.99}) EXPECT_NEAR(uniaxial_P11(*fabric, l), uniaxial_P11(*matrix, l), 1e-6) << l;
  // Small strain: the warp's modulus is E_f plus the matrix's.
  const double eps = 1e-6, E_matrix = 2 * 1e5 * 1.3;
  EXPECT_NEAR(uniaxial_P11(*fabric, 1 + eps) / eps, Ef + E_matrix, 1e-4 * Ef);
  EXPECT_EQ(fabric->energy(Eigen::Vector3d(1.0, 1.0, -0.5).asDiagonal()), std::numeric_limits<double>::infinity());
}

}  // namespace

// Yeoh with c3 < 0 beyond its inflection x_c = -c2 / (3 c3) (uniaxial stretch ~ 3.5 for
// these Dragon Skin 10 coefficients): continued linearly in Ibar1 - 3, so the uniaxial
// stress keeps rising (the bare cubic turns it negative near stretch 4.9, and the
// energy to -inf), and stress and tangent stay consistent across x_c.
TEST(MaterialLaw, YeohWithNegativeC3StaysStableBeyondItsInflection) {
  const double c1 = 21589.8, c2 = 3044.3, c3 = -111.6, kappa = 2e6 * c1;
  const auto m = make_material(make_params("yeoh", {{"c1", {c1}}, {"c2", {c2}}, {"c3", {c3}}, {"kappa", {kappa}}}));
  double previous = 0.0;
  for (double l = 1.1; l <= 8.0; l += 0.1) {
    const double P = uniaxial_P11(*m, l);
    EXPECT_GT(P, previous) << "stretch " << l;
    previous = P;
  }
  // Below x_c the cubic itself (the fit's closed form).
  EXPECT_NEAR(uniaxial_P11(*m, 2.5), uniaxial_stress_yeoh(2.5, c1, c2, c3), 1e-5 * uniaxial_P11(*m, 2.5));
  // Stress and tangent against finite differences just below, at and beyond x_c
  // (isochoric stretch diag(l, 1/sqrt l, 1/sqrt l): Ibar1 - 3 = l^2 + 2/l - 3).
  const double xc = -c2 / (3 * c3);
  for (double x : {xc - 0.5, xc, xc + 0.5, 40.0}) {
    double l = 2.0;  // solve l^2 + 2/l - 3 = x (Newton)
    for (int it = 0; it < 50; ++it) l -= (l * l + 2 / l - 3 - x) / (2 * l - 2 / (l * l));
    Mat3 F = Mat3::Zero();
    F(0, 0) = l;
    F(1, 1) = F(2, 2) = 1 / std::sqrt(l);
    F(0, 1) = 0.05;
    double W;
    Mat3 P;
    Tangent A;
    m->evaluate(F, W, P, &A);
    EXPECT_TRUE(std::isfinite(W) && W > 0) << "x " << x;
    EXPECT_LE((flatten(P) - fd_stress(*m, F, 1e-6)).cwiseAbs().maxCoeff(), 1e-6 * (P.cwiseAbs().maxCoeff() + c1))
        << "x " << x;
    EXPECT_LE((A - fd_tangent(*m, F, 1e-6)).cwiseAbs().maxCoeff(), 1e-5 * A.cwiseAbs().maxCoeff()) << "x " << x;
  }
}

}  // namespace morphfem
