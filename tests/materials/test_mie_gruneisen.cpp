// The Mie-Grueneisen hyperelastic-plastic material (seed 004 Eq. 18, 51, 52): sign convention,
// the EOS branches, the Hugoniot it implies, radial return, artificial viscosity and heating.
#include <gtest/gtest.h>

#include "cairn/materials/material.hpp"
#include "cairn/math/tensor.hpp"

namespace cairn {
namespace {

MaterialConfig nickel(double yield = 0.0, double a1 = 0.0, double a2 = 0.0) {
  MaterialConfig m;
  m.name = "nickel";
  m.model = "mie_gruneisen";
  m.numbers = {{"density", 8870.0},       {"bulk_modulus", 188e9},   {"shear_modulus", 76e9},
               {"gamma0", 2.0},           {"s1", 1.44},              {"yield_stress", yield},
               {"hardening_modulus", 0.0}, {"hardening_exponent", 0.0}, {"hardening_strain", 1.0},
               {"av_a1", a1},             {"av_a2", a2},             {"heat_capacity", 440.0},
               {"initial_temperature", 300.0}};
  m.strings["hardening"] = "linear";
  return m;
}

struct Point {
  explicit Point(const Material& m) : state(m.n_state()) { m.initialize_state(state.data()); }
  /// Advance by a uniaxial strain rate along x for one step; returns the Kirchhoff stress.
  Mat3 step(const Material& m, double rate_xx, double rate_xy, double dt, double dx = 0.0) {
    Mat3 L = Mat3::Zero();
    L(0, 0) = rate_xx;
    L(0, 1) = rate_xy;
    const Mat3 dF = tensor_exp(L * dt);
    F = dF * F;
    MaterialPoint pt{F, L, state.data(), dt};
    pt.dF = &dF;
    const SymMat3 tau_old = tau;
    pt.tau_old = &tau_old;
    pt.cell_size = dx;
    pt.temperature = &T;
    tau = m.update(pt);
    return tau;
  }
  Mat3 F = Mat3::Identity();
  Mat3 tau = Mat3::Zero();
  double T = 300.0;
  std::vector<double> state;
};

TEST(MieGruneisen, CompressionGivesPositivePressure) {
  auto m = make_material(nickel());
  Point p(*m);
  for (int i = 0; i < 100; ++i) p.step(*m, -100.0, 0.0, 1e-5);  // J = exp(-0.1)
  const double J = p.F.determinant();
  const double pressure = -p.tau.trace() / (3.0 * J);
  EXPECT_LT(J, 1.0);
  EXPECT_GT(pressure, 0.0);
  // Eq. 51 compression branch with the internal energy the material accumulated (the EOS sees
  // the predictor of U, which differs from the final U by one step's work).
  const double eta = 1.0 - J, U = p.state[0];
  const double expected = 188e9 * eta * (1.0 - eta) / std::pow(1.0 - 1.44 * eta, 2) + 8870.0 * 2.0 * U;
  EXPECT_NEAR(pressure, expected, 0.005 * expected);
  // Tension takes the linear branch: p = K eta < 0.
  Point t(*m);
  for (int i = 0; i < 10; ++i) t.step(*m, +100.0, 0.0, 1e-5);
  EXPECT_LT(-t.tau.trace() / (3.0 * t.F.determinant()), 0.0);
}

TEST(MieGruneisen, EnergyOnTheHugoniotGivesTheReferenceHugoniot) {
  // With U = p eta / (2 rho0) (Rankine-Hugoniot) the EOS returns p_H = K eta / (1 - S1 eta)^2.
  auto m = make_material(nickel());
  for (double eta : {0.05, 0.15, 0.25}) {
    const double pH = 188e9 * eta / std::pow(1.0 - 1.44 * eta, 2);
    const double U = pH * eta / (2.0 * 8870.0);
    // Probe the EOS through a state with U set and no deviatoric stress.
    std::vector<double> st(m->n_state());
    m->initialize_state(st.data());
    st[0] = U;
    Mat3 F = Mat3::Identity() * std::cbrt(1.0 - eta);  // isotropic: no shear stress
    const Mat3 L = Mat3::Zero(), dF = Mat3::Identity();
    MaterialPoint pt{F, L, st.data(), 0.0};
    pt.dF = &dF;
    const SymMat3 zero_stress;
    pt.tau_old = &zero_stress;
    const Mat3 tau = m->update(pt);
    EXPECT_NEAR(-tau.trace() / (3.0 * F.determinant()), pH, 1e-9 * pH) << eta;
  }
}

TEST(MieGruneisen, RadialReturnKeepsTheStressOnTheYieldSurface) {
  const double sy = 0.5e9;
  auto m = make_material(nickel(sy));
  Point p(*m);
  for (int i = 0; i < 200; ++i) p.step(*m, 0.0, 100.0, 1e-5);  // simple shear to gamma = 0.2
  const Mat3 sigma = p.tau / p.F.determinant();
  EXPECT_NEAR(von_mises(sigma), sy, 1e-6 * sy * 10);
  EXPECT_GT(p.state[1], 0.05);   // plastic strain accumulated
  EXPECT_GT(p.T, 300.0);          // plastic work heats
}

TEST(MieGruneisen, ArtificialViscosityActsOnlyInCompression) {
  auto plain = make_material(nickel());
  auto viscous = make_material(nickel(0.0, 0.4, 4.0));
  Point a(*plain), b(*viscous);
  const Mat3 ta = a.step(*plain, -1e4, 0.0, 1e-8, 2.5e-4), tb = b.step(*viscous, -1e4, 0.0, 1e-8, 2.5e-4);
  EXPECT_GT(-tb.trace(), -ta.trace());  // q adds pressure in compression
  Point c(*plain), d(*viscous);
  const Mat3 tc = c.step(*plain, +1e4, 0.0, 1e-8, 2.5e-4), td = d.step(*viscous, +1e4, 0.0, 1e-8, 2.5e-4);
  EXPECT_EQ(tc, td);  // and nothing in expansion
}

TEST(MieGruneisen, ArtificialViscosityHasTheValueOfSeed004Eq52) {
  // One step of strong uniaxial compression to J = 0.8 from the same state with and without
  // viscosity: the Kirchhoff stresses differ by exactly -J q I, with (seed 004 Eq. 52)
  //     q = rho dx |D_kk| (A1 C + A2 dx |D_kk|),  rho = rho0 / J,
  // and C the current bulk wave speed, C^2 = dp/drho along the reference Hugoniot
  // p_H = K eta / (1 - S1 eta)^2, eta = 1 - rho0 / rho (seed 004 Eq. 51 with U = U_H), taken here
  // by a central difference in rho.
  const double dt = 1e-6, dx = 2.5e-4, J = 0.8;
  const double rate = std::log(J) / dt;  // D_kk = rate < 0
  const double rho0 = 8870.0, K = 188e9, S1 = 1.44;
  auto p_hugoniot = [&](double rho) {
    const double eta = 1.0 - rho0 / rho;
    return K * eta / ((1.0 - S1 * eta) * (1.0 - S1 * eta));
  };
  const double rho = rho0 / J, drho = 1e-4 * rho;
  const double C = std::sqrt((p_hugoniot(rho + drho) - p_hugoniot(rho - drho)) / (2.0 * drho));
  auto plain = make_material(nickel());
  for (const auto& [a1, a2] : std::vector<std::pair<double, double>>{{0.4, 0.0}, {0.0, 4.0}, {0.4, 4.0}}) {
    auto viscous = make_material(nickel(0.0, a1, a2));
    Point a(*plain), b(*viscous);
    const Mat3 ta = a.step(*plain, rate, 0.0, dt, dx), tb = b.step(*viscous, rate, 0.0, dt, dx);
    ASSERT_NEAR(b.F.determinant(), J, 1e-12);
    const double expected = rho * dx * std::abs(rate) * (a1 * C + a2 * dx * std::abs(rate));
    const Mat3 diff = ta - tb;  // = J q I
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(diff(i, i) / J, expected, 1e-6 * expected) << "A1 = " << a1 << ", A2 = " << a2;
      for (int j = 0; j < 3; ++j) {
        if (j != i) {
          EXPECT_NEAR(diff(i, j), 0.0, 1e-9 * expected);
        }
      }
    }
  }
}

TEST(MieGruneisen, InternalEnergyIsTheStressWork) {
  // U integrates tau : D dt / rho0; for slow elastic compression it matches the cold-curve work.
  auto m = make_material(nickel());
  Point p(*m);
  double work = 0.0;
  for (int i = 0; i < 400; ++i) {
    const Mat3 before = p.tau;
    p.step(*m, -50.0, 0.0, 1e-5);
    work += 0.5 * (before(0, 0) + p.tau(0, 0)) * (-50.0) * 1e-5;
  }
  EXPECT_NEAR(m->internal_energy_density(p.F, p.state.data()), work, 1e-9 * std::abs(work));
  EXPECT_GT(work, 0.0);
}

}  // namespace
}  // namespace cairn
