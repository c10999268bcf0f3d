// Each material against hand-computed stresses and energies, and the energy/stress consistency
// tau = dW/dF F^T checked by finite differences.
#include <gtest/gtest.h>

#include "cairn/materials/material.hpp"

namespace cairn {
namespace {

MaterialConfig config(const std::string& model, std::map<std::string, double> numbers,
                      std::string form = "") {
  MaterialConfig m;
  m.name = "solid";
  m.model = model;
  m.numbers = std::move(numbers);
  m.numbers["density"] = 1000.0;
  if (!form.empty()) m.strings["form"] = form;
  return m;
}

Mat3 sample_F() {
  Mat3 F;
  F << 1.05, 0.02, 0.0, -0.01, 0.97, 0.03, 0.004, 0.0, 1.01;
  return F;
}

/// tau = (dW/dF) F^T from central differences of the energy.
Mat3 kirchhoff_from_energy(const Material& m, const Mat3& F) {
  Mat3 P;
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      Mat3 Fp = F, Fm = F;
      Fp(i, j) += h;
      Fm(i, j) -= h;
      P(i, j) = (m.energy_density(Fp) - m.energy_density(Fm)) / (2 * h);
    }
  return P * F.transpose();
}

TEST(Materials, LinearElasticUniaxialStrainByHand) {
  auto m = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}, "small_strain"));
  Mat3 F = Mat3::Identity();
  F(0, 0) = 1.001;
  const Mat3 sigma = m->kirchhoff(F) / F.determinant();
  EXPECT_NEAR(sigma(0, 0), (2.0 + 2 * 3.0) * 0.001, 1e-15);
  EXPECT_NEAR(sigma(1, 1), 2.0 * 0.001, 1e-15);
  EXPECT_NEAR(m->energy_density(F), 0.5 * 8.0 * 1e-6, 1e-18);
  EXPECT_NEAR(m->wave_speed(F), std::sqrt(8.0 / 1000.0), 1e-15);
}

TEST(Materials, ElasticConstantPairsAgree) {
  // E = 10 MPa, nu = 0.25  <=>  lambda = G = 4 MPa  <=>  K = 6.6667 MPa, G = 4 MPa
  auto a = make_material(config("linear_elastic", {{"youngs_modulus", 10e6}, {"poissons_ratio", 0.25}}));
  auto b = make_material(config("linear_elastic", {{"lambda", 4e6}, {"shear_modulus", 4e6}}));
  auto c = make_material(config("linear_elastic", {{"bulk_modulus", 4e6 + 8e6 / 3}, {"shear_modulus", 4e6}}));
  const Mat3 F = sample_F();
  EXPECT_LT((a->kirchhoff(F) - b->kirchhoff(F)).norm(), 1e-6);
  EXPECT_LT((a->kirchhoff(F) - c->kirchhoff(F)).norm(), 1e-6);
}

TEST(Materials, NeoHookeanLnJByHand) {
  // seed 001 Eq. 32 for uniaxial stretch F = diag(s, 1, 1): sigma_xx = (lambda ln s + G (s^2-1))/s
  auto m = make_material(config("neo_hookean", {{"lambda", 2.0}, {"shear_modulus", 3.0}}, "ln_j"));
  Mat3 F = Mat3::Identity();
  const double s = 1.2;
  F(0, 0) = s;
  const Mat3 sigma = m->kirchhoff(F) / s;
  EXPECT_NEAR(sigma(0, 0), (2.0 * std::log(s) + 3.0 * (s * s - 1.0)) / s, 1e-14);
  EXPECT_NEAR(sigma(1, 1), 2.0 * std::log(s) / s, 1e-14);
  EXPECT_NEAR(m->energy_density(F), 0.5 * 2.0 * std::log(s) * std::log(s) - 3.0 * std::log(s) +
                                        0.5 * 3.0 * (s * s - 1.0), 1e-14);
}

TEST(Materials, NeoHookean1DZeroPoissonIsSeed003Eq50) {
  // lambda = 0, G = E/2: sigma = E/2 (F - 1/F)
  auto m = make_material(config("neo_hookean", {{"youngs_modulus", 1e4}, {"poissons_ratio", 0.0}}, "ln_j"));
  Mat3 F = Mat3::Identity();
  F(0, 0) = 0.9;
  EXPECT_NEAR(m->kirchhoff(F)(0, 0) / 0.9, 0.5e4 * (0.9 - 1 / 0.9), 1e-10);
}

TEST(Materials, NeoHookeanJSquaredByHand) {
  // seed 000 Eq. 6: sigma = lambda/2 (J - 1/J) I + G/J (B - I)
  auto m = make_material(config("neo_hookean", {{"lambda", 7.29766e6}, {"shear_modulus", 3.7594e6}}, "j_squared"));
  const Mat3 F = sample_F();
  const double J = F.determinant();
  const Mat3 expected = 0.5 * 7.29766e6 * (J - 1 / J) * Mat3::Identity() +
                        3.7594e6 / J * (F * F.transpose() - Mat3::Identity());
  EXPECT_LT((m->kirchhoff(F) / J - expected).norm(), 1e-6);
}

TEST(Materials, NeoHookeanIsochoricIsDeviatoricInShear) {
  // seed 004 Eq. 18: a volume-preserving simple shear gives zero pressure.
  auto m = make_material(config("neo_hookean", {{"bulk_modulus", 2450.0}, {"shear_modulus", 940.0}}, "isochoric"));
  Mat3 F = Mat3::Identity();
  F(0, 1) = 0.1;
  const Mat3 tau = m->kirchhoff(F);
  EXPECT_NEAR(tau.trace(), 0.0, 1e-10);
  EXPECT_NEAR(tau(0, 1), 940.0 * 0.1, 1e-10);
}

TEST(Materials, EveryModelStressIsTheDerivativeOfItsEnergy) {
  const Mat3 F = sample_F();
  for (std::string form : {"ln_j", "j_squared", "isochoric"}) {
    auto m = make_material(config("neo_hookean", {{"lambda", 2.0}, {"shear_modulus", 3.0}}, form));
    EXPECT_LT((m->kirchhoff(F) - kirchhoff_from_energy(*m, F)).norm(), 1e-7) << form;
    EXPECT_NEAR(m->energy_density(Mat3::Identity()), 0.0, 1e-15) << form;
    EXPECT_LT(m->kirchhoff(Mat3::Identity()).norm(), 1e-15) << form;
  }
  auto corotational = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}));
  EXPECT_LT((corotational->kirchhoff(F) - kirchhoff_from_energy(*corotational, F)).norm(), 1e-7);
  auto le = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}, "small_strain"));
  Mat3 S = Mat3::Identity();  // symmetric small strain: small-strain law is its energy's derivative
  S(0, 0) = 1.001;
  S(1, 1) = 0.999;
  // dW/dF of the small-strain law is the Cauchy stress itself.
  const Mat3 P = kirchhoff_from_energy(*le, S) * S.transpose().inverse();
  EXPECT_LT((le->kirchhoff(S) / S.determinant() - P).norm(), 1e-8);
}

Mat3 rotation(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

TEST(Materials, CorotationalLinearElasticUniaxialStrainByHand) {
  // F = diag(f, 1, 1): V = F, tau = 2G (B - V) + lambda (tr V - 3) V.
  auto m = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}));
  const double f = 1.001;
  Mat3 F = Mat3::Identity();
  F(0, 0) = f;
  const Mat3 tau = m->kirchhoff(F);
  EXPECT_NEAR(tau(0, 0), f * (f - 1.0) * (2.0 + 2 * 3.0), 1e-15);  // = the small-strain tau_xx
  EXPECT_NEAR(tau(1, 1), 2.0 * (f - 1.0), 1e-15);
  EXPECT_NEAR(tau(0, 1), 0.0, 1e-18);
  EXPECT_NEAR(m->energy_density(F), 0.5 * 8.0 * 1e-6, 1e-18);
}

TEST(Materials, CorotationalLinearElasticIgnoresRotations) {
  // A rigid rotation gives no stress and no energy, for any angle, in 3D and in the plane; the
  // small-strain form gives stress of order G (1 - cos theta).
  const double G = 3.0e9, lambda = 2.0e9;
  auto m = make_material(config("linear_elastic", {{"lambda", lambda}, {"shear_modulus", G}}));
  auto small = make_material(config("linear_elastic", {{"lambda", lambda}, {"shear_modulus", G}}, "small_strain"));
  for (double angle : {0.01, 0.3, 1.5, 3.0, 6.0, 100.0}) {
    for (const Eigen::Vector3d& axis : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, -2, 0.5)}) {
      const Mat3 R = rotation(axis, angle);
      EXPECT_LT(m->kirchhoff(R).norm(), 1e-6 * G) << angle;  // round-off of G (V - I)
      EXPECT_LT(std::abs(m->energy_density(R)), 1e-12 * G) << angle;
      if (angle > 0.2) {
        EXPECT_GT(small->kirchhoff(R).norm(), 1e-3 * G) << angle;
      }
    }
  }
}

TEST(Materials, CorotationalLinearElasticIsObjective) {
  // tau(Q F) = Q tau(F) Q^T for a stretch-and-shear F and rotations Q about any axis.
  auto m = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}));
  const Mat3 F = sample_F(), tau = m->kirchhoff(F);
  for (double angle : {0.2, 2.0, 4.0}) {
    const Mat3 Q = rotation(Eigen::Vector3d(0.3, 1.0, -0.7), angle);
    EXPECT_LT((m->kirchhoff(Q * F) - Q * tau * Q.transpose()).norm(), 1e-13) << angle;
    EXPECT_NEAR(m->energy_density(Q * F), m->energy_density(F), 1e-15) << angle;
  }
}

TEST(Materials, CorotationalLinearElasticIsHookesLawForSmallStrains) {
  // For F = I + eps (eps symmetric, small), tau = lambda tr(eps) I + 2G eps + O(eps^2).
  auto m = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}));
  Mat3 eps;
  eps << 1.0, 0.4, -0.2, 0.4, -0.5, 0.3, -0.2, 0.3, 0.7;
  for (double size : {1e-3, 1e-5}) {
    const Mat3 e = size * eps;
    const Mat3 hooke = 2.0 * e.trace() * Mat3::Identity() + 2.0 * 3.0 * e;
    EXPECT_LT((m->kirchhoff(Mat3::Identity() + e) - hooke).norm(), 30.0 * size * size) << size;
  }
}

TEST(Materials, CorotationalLinearElasticSeriesAndEigenPathsAgree) {
  // 3D: small strains take the binomial series of sqrt(I + D), large ones the eigen-decomposition;
  // both against V = sqrt(F F^T) from Eigen's iterative symmetric solver, across the switch.
  const double lambda = 2.0, G = 3.0;
  auto m = make_material(config("linear_elastic", {{"lambda", lambda}, {"shear_modulus", G}}));
  Mat3 A;
  A << 0.3, -0.5, 0.2, 0.7, -0.1, 0.4, -0.6, 0.25, 0.45;
  for (double size : {1e-6, 1e-3, 0.01, 0.02, 0.03, 0.045, 0.06, 0.1, 0.3}) {
    const Mat3 F = rotation(Eigen::Vector3d(1, 2, 3), 0.4) * (Mat3::Identity() + size * A);
    const Mat3 V = Eigen::SelfAdjointEigenSolver<Mat3>(F * F.transpose()).operatorSqrt();
    const Mat3 E = V - Mat3::Identity();  // loses about 1e-16 absolute: the tolerance below
    const Mat3 reference = 2.0 * G * (E + E * E) + lambda * E.trace() * (Mat3::Identity() + E);
    const Mat3 tau = m->kirchhoff(F);
    EXPECT_LT((tau - reference).norm(), 1e-13 * reference.norm() + 1e-14) << size;
    EXPECT_LT((tau - tau.transpose()).norm(), 1e-15 * tau.norm()) << size;
  }
}

TEST(Materials, CorotationalLinearElasticPlanarPathMatchesTheFullOne) {
  // update_stress with planar = true (the closed-form 2x2 square root) equals kirchhoff (the
  // 3x3 eigen-decomposition) for a block-diagonal F, also after a large rotation in the plane.
  auto m = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}));
  Mat3 F = Mat3::Identity();
  F.topLeftCorner<2, 2>() << 1.02, 0.05, -0.03, 0.96;
  F(2, 2) = 0.99;
  for (double angle : {0.0, 0.7, 2.5}) {
    const Mat3 QF = rotation(Eigen::Vector3d(0, 0, 1), angle) * F;
    const Mat3 L = Mat3::Zero();
    MaterialPoint point{QF, L, nullptr, 0.0};
    point.planar = true;
    SymMat3 tau;
    m->update_stress(point, tau);
    const Mat3 full = m->kirchhoff(QF);
    EXPECT_LT((Mat3(tau) - full).norm(), 1e-14) << angle;
    EXPECT_NEAR(full(0, 2), 0.0, 1e-15);
  }
}

TEST(Materials, SmallStrainLinearElasticWarnsOnceWhenAParticleTurns) {
  auto m = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}, "small_strain"));
  const Mat3 L = Mat3::Zero();
  SymMat3 tau;
  const Mat3 small_turn = rotation(Eigen::Vector3d(0, 0, 1), 4.0 * std::acos(-1.0) / 180.0);
  m->update_stress(MaterialPoint{small_turn, L, nullptr, 0.0}, tau);
  EXPECT_TRUE(m->take_notes().empty());  // 4 degrees: below the stated 5
  const Mat3 turn = rotation(Eigen::Vector3d(1, 1, 0), 6.0 * std::acos(-1.0) / 180.0);
  m->update_stress(MaterialPoint{turn, L, nullptr, 0.0}, tau);
  m->update_stress(MaterialPoint{turn, L, nullptr, 0.0}, tau);
  const auto notes = m->take_notes();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("corotational"), std::string::npos) << notes[0];
  m->update_stress(MaterialPoint{turn, L, nullptr, 0.0}, tau);
  EXPECT_TRUE(m->take_notes().empty());  // said once per run
  auto corotational = make_material(config("linear_elastic", {{"lambda", 2.0}, {"shear_modulus", 3.0}}));
  corotational->update_stress(MaterialPoint{turn, L, nullptr, 0.0}, tau);
  EXPECT_TRUE(corotational->take_notes().empty());
}

}  // namespace
}  // namespace cairn

#include "cairn/materials/plane_stress.hpp"

namespace cairn {
namespace {

TEST(Materials, PlaneStressSolvesForTheOutOfPlaneStretch) {
  for (std::string model : {"linear_elastic", "neo_hookean"}) {
    auto m = make_material(config(model, {{"youngs_modulus", 1e6}, {"poissons_ratio", 0.3}}, model == "neo_hookean" ? "ln_j" : ""));
    Mat3 F = Mat3::Identity();
    F(0, 0) = 1.001;  // uniaxial stress along x: sigma_yy = sigma_zz = 0 needs F_yy = F_zz
    F(1, 1) = 1.0 - 0.3 * 0.001;
    const Mat3 L = Mat3::Zero();
    const MaterialPoint point{F, L, nullptr, 0.0};
    const Mat3 tau = plane_stress_update(*m, F, point);
    EXPECT_NEAR(tau(2, 2), 0.0, 1e-6) << model;
    EXPECT_NEAR(F(2, 2), F(1, 1), 2e-6) << model;  // same lateral contraction (small strain)
    EXPECT_NEAR(tau(0, 0) / F.determinant(), 1e6 * 0.001, 2e-3 * 1e3) << model;  // sigma = E eps
  }
}

// A path-dependent model that reads the step's increment (Mie-Grueneisen: radial return on the
// elastic left stretch, internal energy in its state) under plane stress: every Newton trial of
// F_zz starts from the state before the step and sees the increment dF_zz that F_zz implies. (It
// did not: each trial fed its state to the next and kept dF_zz = 1, and a copper wedge in plane
// stress failed with det F = -196 in its third step, tests/robustness/corpus/contact_2d.toml.)
TEST(Materials, PlaneStressOfAPathDependentModelStartsEveryTrialFromTheStateBeforeTheStep) {
  MaterialConfig c = config("mie_gruneisen", {{"bulk_modulus", 1.37e11}, {"shear_modulus", 4.6e10},
                                              {"gamma0", 2.0}, {"s1", 1.49}, {"yield_stress", 1e8},
                                              {"hardening_modulus", 0.0}, {"hardening_exponent", 0.0},
                                              {"hardening_strain", 1.0}, {"av_a1", 0.0}, {"av_a2", 0.0},
                                              {"heat_capacity", 385.0}, {"initial_temperature", 300.0}});
  c.numbers["density"] = 8930.0;
  c.strings["hardening"] = "linear";
  auto m = make_material(c);
  std::vector<double> before(static_cast<std::size_t>(m->n_state()));
  m->initialize_state(before.data());
  std::vector<double> state = before;
  double temperature = m->initial_temperature();
  const double dt = 1e-6, strain = -1e-4;  // uniaxial strain along x in the plane (elastic)
  Mat3 L = Mat3::Zero();
  L(0, 0) = std::log1p(strain) / dt;
  Mat3 dF = Mat3::Identity();
  dF(0, 0) = 1.0 + strain;
  Mat3 F = dF;
  const SymMat3 tau_old{};
  MaterialPoint point{F, L, state.data(), dt, &dF, &tau_old, 0.01, &temperature, true};
  const Mat3 tau = plane_stress_update(*m, F, point);
  // Small strain: eps_zz = -lambda / (lambda + 2G) eps_xx, sigma_xx = (lambda' + 2G) eps_xx
  // with lambda' = 2 G lambda / (lambda + 2G).
  const double G = 4.6e10, lambda = 1.37e11 - 2.0 * G / 3.0;
  EXPECT_NEAR(tau(2, 2), 0.0, 1e-9 * std::abs(tau(0, 0)));
  EXPECT_NEAR(F(2, 2) - 1.0, -lambda / (lambda + 2.0 * G) * strain, 0.01 * std::abs(strain));
  EXPECT_NEAR(tau(0, 0), (2.0 * G * lambda / (lambda + 2.0 * G) + 2.0 * G) * strain, 0.01 * 2.0 * G * std::abs(strain));
  // The state it leaves is that of one update with the converged F_zz and its increment.
  std::vector<double> once = before;
  double temperature_once = m->initial_temperature();
  Mat3 dF_once = dF, L_once = L;
  dF_once(2, 2) = F(2, 2);
  L_once(2, 2) = std::log(F(2, 2)) / dt;
  const Mat3 tau_once =
      m->update(MaterialPoint{F, L_once, once.data(), dt, &dF_once, &tau_old, 0.01, &temperature_once, true});
  for (std::size_t k = 0; k < once.size(); ++k) EXPECT_NEAR(state[k], once[k], 1e-12 * (1.0 + std::abs(once[k]))) << k;
  EXPECT_NEAR(temperature, temperature_once, 1e-12 * temperature_once);
  EXPECT_NEAR((tau - tau_once).norm(), 0.0, 1e-12 * tau.norm());
}

}  // namespace
}  // namespace cairn
