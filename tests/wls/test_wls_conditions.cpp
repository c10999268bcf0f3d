// The engine's conditions under the WLS method (seed 001; issue 35 item 4, docs/wls.md "The
// engine's conditions"): tractions on particle faces (seed 000 Sec. 2.4 with the narrow shape
// S of seed 001 Eq. 5), moving walls (seed 000 Sec. 2.5) on the WLS grid update (Eq. 25-26), and
// periodic axes (the stencils, fits, cut cells and node sums wrap across the seam).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <tuple>

#include "../support/config_builder.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn {
namespace {

constexpr double E = 1.0e6, rho = 1000.0;

/// A WLS bar [0, L] x [0.275, 0.525] (x [0.275, 0.525] in 3D) on the grid [0, 1]^D, linear
/// elastic with nu = 0 (plane strain: sigma_xx = E eps_xx, sigma_yy = 0 for a free strip),
/// h = 0.05, 2 ppc: its faces lie halfway between node lines (x = L = 0.425 below).
Config bar_config(int D, double L, bool held) {
  Config c = test::box_config(D, "linear");
  c.method.integration = "wls";
  c.grid.cell_size.assign(D, 0.05);
  c.materials[0].numbers["poissons_ratio"] = 0.0;
  auto& b = c.bodies[0];
  b.shape.min.assign(D, 0.275);
  b.shape.max.assign(D, 0.525);
  b.shape.min[0] = 0.0;
  b.shape.max[0] = L;
  if (held) c.boundary.face[0] = FaceCondition::symmetry;  // the body reaches it: a mirror plane
  return c;
}

TractionConfig end_traction(int D, double T, const std::string& scale) {
  TractionConfig t;
  t.name = "pull";
  t.side = 1;  // x_max
  t.traction.assign(D, 0.0);
  t.traction[0] = T;
  t.scale = scale;
  return t;
}

/// Mean Cauchy stress sigma_xx, sigma_yy of the particles with volume and x < x_max.
template <int D>
std::pair<double, double> mean_stress(const Simulation<D>& sim, double x_max) {
  const auto& P = sim.particles();
  double sxx = 0.0, syy = 0.0;
  int n = 0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    if (wls::is_surface(P, p) || P.reference_position[p][0] > x_max) continue;
    const double J = P.deformation_gradient[p].determinant();
    sxx += P.kirchhoff_stress[p](0, 0) / J;
    syy += P.kirchhoff_stress[p](1, 1) / J;
    ++n;
  }
  return {sxx / n, syy / n};
}

// ---- tractions ----------------------------------------------------------------------------------

template <int D>
void check_traction_forces() {
  // An unstressed free bar, one step: every node force is the traction's (no stress, no body
  // force), the faces are those of the lattice particles on x = L (the surface particles there
  // have none), and the node forces sum to T times the face area.
  Config c = bar_config(D, 0.425, false);
  const double T = 1.0e3;
  c.tractions.push_back(end_traction(D, T, "1"));
  Simulation<D> sim(c);
  const std::size_t faces = D == 2 ? 10 : 100;  // 0.25 / 0.025 particles across, per transverse axis
  EXPECT_EQ(sim.tractions().n_faces(0), faces);
  sim.step(sim.next_dt());
  const double area = D == 2 ? 0.25 * c.simulation.thickness : 0.0625;
  EXPECT_NEAR(sim.tractions().total_force(0)[0], T * area, 1e-12 * T * area);
  Vec<D> sum = Vec<D>::Zero();
  const auto& nodes = sim.nodes();
  for (std::int32_t i = 0; i < sim.grid().n_nodes(); ++i) {
    sum += nodes.force[i];
    // The face centres lie at x = 0.425: only the nodes of the node planes x = 0.4 and 0.45
    // carry the load.
    if (nodes.force[i].norm() > 1e-9 * T * area) {
      const double x = sim.grid().node_position(i)[0];
      EXPECT_TRUE(std::abs(x - 0.4) < 1e-12 || std::abs(x - 0.45) < 1e-12) << i;
      EXPECT_GT(nodes.mass[i], 0.0) << i;
    }
  }
  EXPECT_NEAR(sum[0], T * area, 1e-12 * T * area);
  for (int a = 1; a < D; ++a) EXPECT_NEAR(sum[a], 0.0, 1e-12 * T * area);
}

TEST(WlsConditions, TractionNodeForcesSumToTheLoad) {
  ASSERT_NO_FATAL_FAILURE(check_traction_forces<2>());
  ASSERT_NO_FATAL_FAILURE(check_traction_forces<3>());
}

TEST(WlsConditions, TractionAcceleratesAFreeBody) {
  // A free bar pulled at one end for a few wave transits: its momentum grows with the load's
  // impulse T A t. Not exactly: WLS's node masses are the cut-cell integrals (seed 001 Eq. 22,
  // the rounded corners lose h^2/2 each) and its particle update (Eq. 27) weighs the node
  // accelerations with the particles' masses, so the particles' momentum follows the impulse
  // only to about the difference of those masses (measured: below 1 %).
  Config c = bar_config(2, 0.425, false);
  const double T = 1.0e3;
  c.tractions.push_back(end_traction(2, T, "1"));
  c.simulation.end_time = 0.04;
  Simulation<2> sim(c);
  while (sim.time() < 0.04 - 1e-12) sim.step(sim.next_dt());
  const auto& P = sim.particles();
  double px = 0.0, py = 0.0, mass = 0.0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    px += P.mass[p] * P.velocity[p][0];
    py += P.mass[p] * P.velocity[p][1];
    mass += P.mass[p];
  }
  // Central differences (seed 001 Sec. 4.7): the particles carry the velocity of t - dt/2, which
  // brackets the impulse between its values at t - dt and t.
  const double impulse = T * 0.25 * c.simulation.thickness * sim.time();
  std::printf("free bar: momentum %.6g, impulse T A t %.6g (ratio %.5f), transverse %.3g\n", px, impulse,
              px / impulse, py);
  EXPECT_NEAR(px / impulse, 1.0, 0.02);
  EXPECT_NEAR(py, 0.0, 1e-9 * impulse);
  EXPECT_NEAR(mass, rho * 0.425 * 0.25 * c.simulation.thickness, 1e-9);
}

TEST(WlsConditions, HeldBarCarriesTheTraction) {
  // A bar on a symmetry face, pulled at x = 0.425 by a traction ramped smoothly over eight wave
  // transits (c = sqrt(E/rho), L/c = 0.0126) and then held: it carries sigma_xx = T, sigma_yy =
  // 0, and its end moves by T L / E.
  Config c = bar_config(2, 0.425, true);
  const double T = 1.0e3, ramp = 0.1;
  c.tractions.push_back(end_traction(2, T, "t < 0.1 ? 0.5 * (1 - cos(pi * t / 0.1)) : 1"));
  c.simulation.end_time = 0.2;
  Simulation<2> sim(c);
  double sxx = 0.0, syy = 0.0, end = 0.0;
  int samples = 0;
  const auto& P = sim.particles();
  while (sim.time() < 0.2 - 1e-12) {
    sim.step(sim.next_dt());
    if (sim.time() < ramp + 0.05) continue;
    const auto [xx, yy] = mean_stress(sim, 0.3);
    sxx += xx;
    syy += yy;
    double u = 0.0;
    int n = 0;
    for (std::size_t p = 0; p < P.n(); ++p)
      if (!wls::is_surface(P, p) && P.reference_position[p][0] > 0.4) {
        u += P.position[p][0] - P.reference_position[p][0];
        ++n;
      }
    end += u / n;
    ++samples;
  }
  sxx /= samples;
  syy /= samples;
  end /= samples;
  // The particles next to x = 0.425 sit at X = 0.4125: their displacement is T X / E.
  std::printf("held bar: sigma_xx %.5g (T = %g), sigma_yy %.3g, end displacement %.5g (T X / E = %.5g)\n", sxx, T,
              syy, end, T * 0.4125 / E);
  EXPECT_NEAR(sxx / T, 1.0, 0.02);
  EXPECT_NEAR(syy / T, 0.0, 0.02);
  EXPECT_NEAR(end / (T * 0.4125 / E), 1.0, 0.03);
}

TEST(WlsConditions, TractionOnARadialBodyIsRefused) {
  Config c = bar_config(2, 0.425, false);
  auto& b = c.bodies[0];
  b.shape.kind = "circle";
  b.shape.center = {0.5, 0.5};
  b.shape.radius = 0.3;
  b.arrangement = "radial";
  c.tractions.push_back(end_traction(2, 1.0, "1"));
  EXPECT_THROW(Simulation<2>{c}, std::invalid_argument);
}

// ---- moving walls -------------------------------------------------------------------------------

TEST(WlsConditions, MovingWallCompressesAHeldBar) {
  // The bar [0, 0.425] on a symmetry face, pushed at x = 0.425 by a wall that moves by -delta with a
  // smooth velocity history over 0.1 and then stops: the wall's nodes move with the wall every
  // step, and the bar ends uniformly compressed, sigma_xx = -E delta / L.
  Config c = bar_config(2, 0.425, true);
  const double delta = 4.0e-4, t_r = 0.1;
  WallConfig w;
  w.name = "piston";
  w.axis = 0;
  w.inside_below = true;
  w.position = 0.425;
  w.depth = 0.0;  // the nodes on the wall and the ones beyond it with mass: the whole bar strains
  w.velocity = "t < 0.1 ? -0.5 * 4e-4 * pi / 0.1 * sin(pi * t / 0.1) : 0";
  c.walls.push_back(w);
  c.simulation.end_time = 0.2;
  Simulation<2> sim(c);
  double sxx = 0.0, syy = 0.0;
  int samples = 0, wall_nodes = 0;
  while (sim.time() < 0.2 - 1e-12) {
    sim.step(sim.next_dt());
    // Every node the wall controls ends the step with the wall's velocity (seed 000 Sec. 2.5).
    for (const auto& e : sim.velocity_conditions().entries()) {
      EXPECT_NEAR(sim.nodes().velocity_new[e.node][0], e.end, 1e-15) << e.node;
      ++wall_nodes;
    }
    if (sim.time() < t_r + 0.05) continue;
    const auto [xx, yy] = mean_stress(sim, 0.3);
    sxx += xx;
    syy += yy;
    ++samples;
  }
  sxx /= samples;
  syy /= samples;
  const double expected = -E * delta / 0.425;
  std::printf("wall: sigma_xx %.5g (expected %.5g), sigma_yy %.3g, wall at %.8f; %d wall node-steps\n", sxx, expected,
              syy, sim.velocity_conditions().walls()[0].position(), wall_nodes);
  EXPECT_NEAR(sim.velocity_conditions().walls()[0].position(), 0.425 - delta, 1e-3 * delta);
  EXPECT_GT(wall_nodes, 100);
  EXPECT_NEAR(sxx / expected, 1.0, 0.03);
  EXPECT_NEAR(syy / expected, 0.0, 0.02);
}

// ---- periodic axes ------------------------------------------------------------------------------

/// A box body of the WLS bar's material, as two boxes when it crosses x = 1 (the seam of the
/// periodic x axis of [0, 1]^2), with the velocity field v(X - shift): a fast translation along
/// x, a periodic stretch and a shear.
Config periodic_config(double shift) {
  Config c = bar_config(2, 0.425, false);
  c.boundary.face[0] = c.boundary.face[1] = FaceCondition::periodic;
  c.materials[0].numbers["poissons_ratio"] = 0.3;
  const std::string s = "(X - " + std::to_string(shift) + ")";
  const std::vector<std::string> v = {"5 + 0.3 * sin(2 * pi * " + s + ")", "0.2 * cos(2 * pi * " + s + ") * (Y - 0.5)"};
  BodyConfig body = c.bodies[0];
  body.velocity = v;
  body.shape.min = {0.3 + shift, 0.3};
  body.shape.max = {0.7 + shift, 0.6};
  c.bodies.clear();
  if (body.shape.max[0] <= 1.0) {
    c.bodies.push_back(body);
  } else {
    BodyConfig right = body, left = body;
    right.shape.max[0] = 1.0;
    left.name = "wrapped";
    left.shape.min[0] = 0.0;
    left.shape.max[0] = body.shape.max[0] - 1.0;
    c.bodies.push_back(right);
    c.bodies.push_back(left);
  }
  return c;
}

TEST(WlsConditions, BodyAcrossAPeriodicSeamMatchesTheShiftedBody) {
  // The same body, once in the middle of the grid and once shifted by half the periodic length
  // (10 cells) so that the seam runs through it, for 40 steps in which its particles travel
  // about 2 cells and those next to the seam cross it: every particle ends with the same velocity,
  // stress and (up to the period) position, to round-off.
  Simulation<2> away(periodic_config(0.0)), across(periodic_config(0.5));
  ASSERT_EQ(away.particles().n(), across.particles().n());
  for (int s = 0; s < 40; ++s) {
    const double dt = away.next_dt();  // (across.next_dt() differs by round-off: sin(2 pi (X - 0.5)))
    away.step(dt);
    across.step(dt);
  }
  auto key = [](const Vec<2>& X) {
    return std::make_tuple(std::llround(std::fmod(X[0] + 10.0, 1.0) * 1e6) % 1000000, std::llround(X[1] * 1e6));
  };
  std::map<std::tuple<long long, long long>, std::size_t> of;
  const auto& A = away.particles();
  const auto& B = across.particles();
  for (std::size_t p = 0; p < A.n(); ++p) of[key(A.reference_position[p] + Vec<2>(0.5, 0.0))] = p;
  ASSERT_EQ(of.size(), A.n());
  double dx = 0.0, dv = 0.0, ds = 0.0, v_max = 0.0, s_max = 0.0;
  int crossed = 0;
  for (std::size_t q = 0; q < B.n(); ++q) {
    const auto it = of.find(key(B.reference_position[q]));
    ASSERT_NE(it, of.end()) << q;
    const std::size_t p = it->second;
    Vec<2> d = B.position[q] - A.position[p] - Vec<2>(0.5, 0.0);
    d[0] -= std::round(d[0]);  // the period is 1
    dx = std::max(dx, d.norm());
    dv = std::max(dv, (B.velocity[q] - A.velocity[p]).norm());
    ds = std::max(ds, (B.kirchhoff_stress[q].full() - A.kirchhoff_stress[p].full()).norm());
    v_max = std::max(v_max, A.velocity[p].norm());
    s_max = std::max(s_max, A.kirchhoff_stress[p].full().norm());
    crossed += B.reference_position[q][0] < 1.0 && B.position[q][0] > 1.0;
  }
  std::printf("periodic seam: %d particles crossed; max differences: position %.3g, velocity %.3g (of %.3g), "
              "stress %.3g (of %.3g)\n", crossed, dx, dv, v_max, ds, s_max);
  EXPECT_GT(crossed, 10);
  EXPECT_GT(s_max, 10.0);  // the body deforms
  EXPECT_LT(dx, 1e-12);
  EXPECT_LT(dv, 1e-10 * v_max);
  EXPECT_LT(ds, 1e-9 * s_max);
}

TEST(WlsConditions, PeriodicAxisNeedsThreeCells) {
  Config c = periodic_config(0.0);
  c.grid.extent[0] = 0.1;  // two cells
  c.bodies[0].shape.min[0] = 0.0;
  c.bodies[0].shape.max[0] = 0.1;
  EXPECT_THROW(Simulation<2>{c}, std::invalid_argument);
}

}  // namespace
}  // namespace cairn
namespace cairn {
void run_variant(const char* name, bool wall, const std::string& pv, const std::string& vg, double depth, bool estimate, double cfl = 0.4, double L = 0.425) {
  Config c = bar_config(2, L, true);
  c.simulation.cfl = cfl;
  if (cfl == 0.3) { c.bodies[0].shape.min[1] = 0.3; c.bodies[0].shape.max[1] = 0.5; }
  c.method.plugin.set("point_values", pv);
  c.method.plugin.set("velocity_gradient", vg);
  if (wall) {
    WallConfig w;
    w.name = "piston";
    w.axis = 0;
    w.position = 0.425;
    w.depth = depth;
    if (estimate) w.gradient = WallGradient::estimate;
    w.velocity = "t < 0.1 ? -0.5 * 4e-4 * pi / 0.1 * sin(pi * t / 0.1) : 0";
    c.walls.push_back(w);
  } else {
    c.tractions.push_back(end_traction(2, 1.0e3, "t < 0.1 ? 0.5 * (1 - cos(pi * t / 0.1)) : 1"));
  }
  try {
    Simulation<2> sim(c);
    double sxx = 0, lo = 1e30, hi = -1e30; int n = 0;
    while (sim.time() < 0.2 - 1e-12) {
      sim.step(sim.next_dt());
      if (sim.time() < 0.15) continue;
      const auto [xx, yy] = mean_stress(sim, 0.3);
      sxx += xx; ++n; lo = std::min(lo, xx); hi = std::max(hi, xx);
    }
    double spread = 0; const auto& P = sim.particles();
    for (std::size_t p = 0; p < P.n(); ++p) if (!wls::is_surface(P, p) && P.reference_position[p][0] < 0.3) spread = std::max(spread, std::abs(P.kirchhoff_stress[p](0,0) - sxx / n));
    std::printf("%s %s pv=%s vg=%s depth=%g est=%d: sxx mean %.1f range [%.1f, %.1f] particle spread %.1f\n", name, wall ? "wall" : "traction", pv.c_str(), vg.c_str(), depth, (int)estimate, sxx / n, lo, hi, spread);
  } catch (const std::exception& e) {
    std::printf("%s %s pv=%s vg=%s: FAILED %s\n", name, wall ? "wall" : "traction", pv.c_str(), vg.c_str(), e.what());
  }
}
TEST(WlsDebug, Variants) {
  run_variant("v", false, "node", "quadrature", 0, false, 0.3, 0.425);
  run_variant("v", false, "node", "quadrature", 0, false, 0.3, 0.45);
  run_variant("v", false, "fit", "narrow", 0, false, 0.4, 0.45);
}
}
