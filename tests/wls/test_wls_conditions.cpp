// The engine's conditions under the WLS method (seed 001; issue 35 item 4, docs/wls.md "The
// engine's conditions"): moving walls (seed 000 Sec. 2.5) on the WLS grid update (Eq. 25-26),
// periodic axes (the stencils, fits, cut cells and node sums wrap across the seam), and the
// refusal of tractions.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <array>

#include "../support/config_builder.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn {
namespace {

constexpr double E = 1.0e6;

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

// ---- tractions (refused) -----------------------------------------------------------------------

TEST(WlsConditions, TractionsAreRefused) {
  // docs/wls.md, "Tractions": a held bar under a sustained end traction grew node-scale noise
  // or blew up, depending on where the loaded face sits in its cells.
  Config c = bar_config(2, 0.425, true);
  TractionConfig t;
  t.name = "pull";
  t.side = 1;
  t.traction = {1.0e3, 0.0};
  c.tractions.push_back(t);
  EXPECT_THROW(Simulation<2>{c}, std::invalid_argument);
}

// ---- moving walls -------------------------------------------------------------------------------

TEST(WlsConditions, MovingWallCompressesAHeldBar) {
  // The bar [0, 0.425] on a symmetry face, pushed at x = 0.425 by a wall that moves by -delta
  // with a smooth velocity history over 0.1 (eight wave transits) and then stops: the wall's
  // nodes move with the wall every step, and the bar ends uniformly compressed, sigma_xx =
  // -E delta / L (measured 0.9 % below; the particles' stresses scatter by about 16 % of it).
  Config c = bar_config(2, 0.425, true);
  const double delta = 4.0e-4, t_r = 0.1;
  WallConfig w;
  w.name = "piston";
  w.axis = 0;
  w.inside_below = true;
  w.position = 0.425;
  // Default depth (1 cell) and gradient (zero): the wall holds the nodes within a cell inside
  // the material and those beyond it that carry mass (seed 000 Sec. 2.5).
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
/// periodic x axis of [0, 1]^D), with the velocity field v(X - shift): a fast translation along
/// x, a periodic stretch and a shear.
Config periodic_config(int D, double shift) {
  Config c = bar_config(D, 0.425, false);
  c.boundary.face[0] = c.boundary.face[1] = FaceCondition::periodic;
  c.materials[0].numbers["poissons_ratio"] = 0.3;
  if (D == 3) c.grid.cell_size.assign(D, 0.1);
  const std::string s = "(X - " + std::to_string(shift) + ")";
  std::vector<std::string> v = {"5 + 0.3 * sin(2 * pi * " + s + ")", "0.2 * cos(2 * pi * " + s + ") * (Y - 0.5)"};
  if (D == 3) v.push_back("0.1 * sin(2 * pi * " + s + ") * (Z - 0.5)");
  BodyConfig body = c.bodies[0];
  body.velocity = v;
  body.shape.min.assign(D, 0.3);
  body.shape.max.assign(D, 0.6);
  body.shape.min[0] = 0.3 + shift;
  body.shape.max[0] = 0.7 + shift;
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

template <int D>
void check_periodic_seam(int steps) {
  // The same body, once in the middle of the grid and once shifted by half the periodic length
  // so that the seam runs through it, for `steps` steps in which its particles travel about
  // 2 cells (2D; 1 in 3D) and those next to the seam cross it: every particle ends with the same
  // velocity, stress and (up to the period) position, to round-off.
  Simulation<D> away(periodic_config(D, 0.0)), across(periodic_config(D, 0.5));
  ASSERT_EQ(away.particles().n(), across.particles().n());
  for (int s = 0; s < steps; ++s) {
    const double dt = away.next_dt();  // (across.next_dt() differs by round-off: sin(2 pi (X - 0.5)))
    away.step(dt);
    across.step(dt);
  }
  auto key = [](const Vec<D>& X) {
    std::array<long long, 3> k{};
    k[0] = std::llround(std::fmod(X[0] + 10.0, 1.0) * 1e6) % 1000000;
    for (int a = 1; a < D; ++a) k[a] = std::llround(X[a] * 1e6);
    return k;
  };
  std::map<std::array<long long, 3>, std::size_t> of;
  const auto& A = away.particles();
  const auto& B = across.particles();
  Vec<D> half = Vec<D>::Zero();
  half[0] = 0.5;
  for (std::size_t p = 0; p < A.n(); ++p) of[key(A.reference_position[p] + half)] = p;
  ASSERT_EQ(of.size(), A.n());
  double dx = 0.0, dv = 0.0, ds = 0.0, v_max = 0.0, s_max = 0.0;
  int crossed = 0;
  for (std::size_t q = 0; q < B.n(); ++q) {
    const auto it = of.find(key(B.reference_position[q]));
    ASSERT_NE(it, of.end()) << q;
    const std::size_t p = it->second;
    Vec<D> d = B.position[q] - A.position[p] - half;
    d[0] -= std::round(d[0]);  // the period is 1
    dx = std::max(dx, d.norm());
    dv = std::max(dv, (B.velocity[q] - A.velocity[p]).norm());
    ds = std::max(ds, (B.kirchhoff_stress[q].full() - A.kirchhoff_stress[p].full()).norm());
    v_max = std::max(v_max, A.velocity[p].norm());
    s_max = std::max(s_max, A.kirchhoff_stress[p].full().norm());
    crossed += B.reference_position[q][0] < 1.0 && B.position[q][0] > 1.0;
  }
  std::printf("periodic seam (%dD): %d particles crossed; max differences: position %.3g, velocity %.3g (of %.3g), "
              "stress %.3g (of %.3g)\n", D, crossed, dx, dv, v_max, ds, s_max);
  EXPECT_GT(crossed, 10);
  EXPECT_GT(s_max, 10.0);  // the body deforms
  EXPECT_LT(dx, 1e-12);
  EXPECT_LT(dv, 1e-10 * v_max);
  EXPECT_LT(ds, 1e-9 * s_max);
}

TEST(WlsConditions, BodyAcrossAPeriodicSeamMatchesTheShiftedBody) {
  ASSERT_NO_FATAL_FAILURE(check_periodic_seam<2>(40));
  ASSERT_NO_FATAL_FAILURE(check_periodic_seam<3>(20));
}

TEST(WlsConditions, PeriodicAxisNeedsThreeCells) {
  Config c = periodic_config(2, 0.0);
  c.grid.extent[0] = 0.1;  // two cells
  c.bodies[0].shape.min[0] = 0.0;
  c.bodies[0].shape.max[0] = 0.1;
  EXPECT_THROW(Simulation<2>{c}, std::invalid_argument);
}

}  // namespace
}  // namespace cairn
