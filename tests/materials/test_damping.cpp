// Kelvin-Voigt damping of linear_elastic (damping_time = beta; docs/materials.md): the
// viscous stress by hand, no effect when off, a free bar's mode decaying at the analytic damping
// ratio zeta = beta omega / 2 with its energy balance closed, the stable time step, and the
// refusals (plane stress, the FEM).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "../fem/fem_case.hpp"
#include "../support/config_builder.hpp"
#include "cairn/fem/solver.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

MaterialConfig elastic(double beta, const std::string& form = "corotational") {
  MaterialConfig m;
  m.name = "m";
  m.model = "linear_elastic";
  m.numbers = {{"density", 1000.0}, {"lambda", 2.0e6}, {"shear_modulus", 3.0e6}};
  if (beta >= 0.0) m.numbers["damping_time"] = beta;
  m.strings["form"] = form;
  return m;
}

Mat3 sample_F() {
  Mat3 F;
  F << 1.004, 0.002, 0.0, -0.001, 0.997, 0.0, 0.0, 0.0, 1.0;
  return F;
}

Mat3 sample_L() {
  Mat3 L;
  L << 0.3, 0.5, 0.0, -0.1, -0.2, 0.0, 0.0, 0.0, 0.0;
  return L;
}

TEST(Damping, OffIsTheElasticLawBitForBit) {
  // damping_time = 0 (the default) and no key at all: no state, no increments, the same stress.
  for (std::string form : {"corotational", "small_strain"}) {
    auto plain = make_material(elastic(-1.0, form));
    auto zero = make_material(elastic(0.0, form));
    EXPECT_EQ(zero->n_state(), 0);
    EXPECT_FALSE(zero->uses_increment());
    EXPECT_EQ(zero->damping_time(), 0.0);
    const Mat3 F = sample_F(), L = sample_L();
    MaterialPoint point{F, L, nullptr, 1e-3};
    point.planar = true;
    SymMat3 a, b;
    plain->update_stress(point, a);
    zero->update_stress(point, b);
    EXPECT_EQ(a, b) << form;
    EXPECT_EQ(zero->update(point), plain->kirchhoff(F)) << form;
    EXPECT_EQ(zero->dissipated_energy_density(nullptr), 0.0);
  }
}

TEST(Damping, AddsTheKelvinVoigtStressAndCountsItsWork) {
  // tau = tau_e(F) + J beta (lambda tr(D) I + 2G D), D = sym(L); the state gains tau_v : D dt.
  const double beta = 2e-4, dt = 1e-5, lambda = 2.0e6, G = 3.0e6;
  auto m = make_material(elastic(beta));
  auto e = make_material(elastic(0.0));
  ASSERT_EQ(m->n_state(), 1);
  EXPECT_TRUE(m->uses_increment());
  EXPECT_EQ(m->damping_time(), beta);
  const Mat3 F = sample_F(), L = sample_L();
  const Mat3 D = 0.5 * (L + L.transpose());
  const double J = F.determinant();
  const Mat3 tau_v = J * beta * (lambda * D.trace() * Mat3::Identity() + 2.0 * G * D);
  double state = 0.25;  // some earlier work
  MaterialPoint point{F, L, &state, dt};
  point.planar = true;
  SymMat3 tau;
  m->update_stress(point, tau);
  EXPECT_LT((tau.full() - e->kirchhoff(F) - tau_v).norm(), 1e-9 * tau_v.norm());
  const double power = tau_v.cwiseProduct(D).sum();
  EXPECT_GT(power, 0.0);
  EXPECT_NEAR(state, 0.25 + power * dt, 1e-12 * power * dt);
  EXPECT_EQ(m->dissipated_energy_density(&state), state);
  // The general update (plane stress, FEM) gives the same stress and leaves the state alone.
  double untouched = 0.0;
  MaterialPoint general{F, L, &untouched, dt};
  EXPECT_LT((m->update(general) - tau.full()).norm(), 1e-9 * tau_v.norm());
  EXPECT_EQ(untouched, 0.0);
}

// A free-free 1D bar (uniaxial strain, 50 quadratic B-spline cells over its length L) started in
// its first mode, v = A cos(pi X / L): with damping_time beta the mode decays at
// zeta = beta omega / 2. Kinetic energy peaks twice per damped period T_d, each
// exp(-2 zeta omega T_d / 2) of the one before (the motion repeats itself scaled by
// exp(-zeta omega T_d) every period, exactly, for a linear damped oscillator).
struct BarDecay {
  double zeta = 0.0, omega = 0.0, energy_drift = 0.0, dissipated = 0.0, initial = 0.0;
};

BarDecay damped_bar(double beta) {
  Config cfg = test::box_config(1, "bspline2");
  cfg.grid.cell_size = {0.01};
  cfg.materials[0] = elastic(beta);
  cfg.materials[0].name = "mat";
  cfg.bodies[0].shape.min = {0.25};
  cfg.bodies[0].shape.max = {0.75};
  cfg.bodies[0].velocity = {"1e-3*cos(3.141592653589793*(X-0.25)/0.5)"};
  Simulation<1> sim(cfg);
  const Totals t0 = sim.totals();
  BarDecay out;
  out.initial = t0.kinetic_energy + t0.strain_energy;
  std::vector<double> peak_time, peak_ke;
  double prev2 = t0.kinetic_energy, prev = prev2, t_prev = 0.0, t = 0.0;
  while (peak_time.size() < 5) {
    const double dt = sim.next_dt();
    sim.step(dt);
    t += dt;
    const Totals now = sim.totals();
    const double balance = now.kinetic_energy + now.strain_energy + sim.dissipated_energy() - out.initial;
    out.energy_drift = std::max(out.energy_drift, std::abs(balance));
    if (prev > prev2 && prev >= now.kinetic_energy && t_prev > 0.0) {
      // parabola through the three samples around the peak
      const double a = 0.5 * (prev2 + now.kinetic_energy) - prev, b = 0.5 * (now.kinetic_energy - prev2);
      peak_time.push_back(t_prev - 0.5 * dt * b / a);  // equal steps (constant wave speed)
      peak_ke.push_back(prev - 0.25 * b * b / a);
    }
    prev2 = prev;
    prev = now.kinetic_energy;
    t_prev = t;
    if (t > 1.0) break;
  }
  if (peak_time.size() < 5) return out;
  // Over four half periods (the first peak lies half a period in, away from the start).
  const double half = (peak_time[4] - peak_time[0]) / 4.0;
  const double rate = -std::log(peak_ke[4] / peak_ke[0]) / (2.0 * (peak_time[4] - peak_time[0]));  // zeta omega
  const double omega_d = std::numbers::pi / half;
  out.omega = std::sqrt(omega_d * omega_d + rate * rate);
  out.zeta = rate / out.omega;
  out.dissipated = sim.dissipated_energy();
  return out;
}

TEST(Damping, FreeBarModeDecaysAtTheAnalyticDampingRatio) {
  // omega = c pi / L = 562 rad/s (c = sqrt((lambda + 2G) / rho) = 89.44 m/s, L = 0.5 m); beta
  // for zeta = 0.05, which makes zeta = 1.6 at the grid's highest mode (dt x 0.29).
  const double omega = std::sqrt(8.0e6 / 1000.0) * std::numbers::pi / 0.5, beta = 2.0 * 0.05 / omega;
  const BarDecay undamped = damped_bar(0.0);
  const BarDecay damped = damped_bar(beta);
  ASSERT_GT(damped.omega, 0.0);
  EXPECT_NEAR(undamped.omega / omega, 1.0, 0.01);
  EXPECT_LT(undamped.zeta, 1e-3);  // FLIP: no damping of its own
  const double expected = beta * damped.omega / 2.0;
  // measured 0.012 % off
  EXPECT_NEAR(damped.zeta / expected, 1.0, 0.005) << "zeta " << damped.zeta << " expected " << expected;
  // The viscous work closes the energy balance: kinetic + strain + dissipated stays at its start.
  EXPECT_GT(damped.dissipated, 0.5 * damped.initial);
  EXPECT_LT(damped.energy_drift, 0.01 * damped.initial);  // measured 0.41 %, with 79 % dissipated
}

TEST(Damping, TheTimeStepShrinksBySqrtOnePlusZetaSquaredMinusZeta) {
  // dt = cfl h / (c (sqrt(1 + zeta^2) + zeta) + max |v|), zeta = beta c / h, for a body at rest.
  const double beta = 1e-4, h = 0.1, c = std::sqrt(8.0e6 / 1000.0);
  for (double b : {0.0, beta}) {
    Config cfg = test::box_config(2, "bspline2");
    cfg.materials[0] = elastic(b);
    cfg.materials[0].name = "mat";
    Simulation<2> sim(cfg);
    const double zeta = b * c / h;
    const double expected = cfg.simulation.cfl * h / (c * (std::sqrt(1.0 + zeta * zeta) + zeta));
    EXPECT_NEAR(sim.next_dt() / expected, 1.0, 1e-12) << "beta " << b;
  }
}

TEST(Damping, TheFemRefusesIt) {
  // The FEM's energy totals and time step do not know the viscous stress.
  Config cfg = test::fem_config("shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\nsize = 0.25\n");
  cfg.materials[0].model = "linear_elastic";
  cfg.materials[0].strings["form"] = "corotational";
  cfg.materials[0].numbers["damping_time"] = 1e-4;
  EXPECT_THROW(fem::Solver solver(cfg), std::invalid_argument);
  cfg.materials[0].numbers["damping_time"] = 0.0;
  EXPECT_NO_THROW(fem::Solver solver(cfg));
}

TEST(Damping, PlaneStressRefusesIt) {
  Config cfg = test::box_config(2, "bspline2");
  cfg.simulation.mode = Mode::plane_stress;
  cfg.materials[0] = elastic(1e-4);
  cfg.materials[0].name = "mat";
  EXPECT_THROW(Simulation<2> sim(cfg), std::invalid_argument);
}

}  // namespace
}  // namespace cairn
