// The engine's conditions under the WLS method (seed 001; issue 35 item 4, docs/wls.md "The
// engine's conditions"): moving walls (seed 000 Sec. 2.5) on the WLS grid update (Eq. 25-26),
// periodic axes (the stencils, fits, cut cells and node sums wrap across the seam), and
// tractions spread over the cut-cell surface.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <algorithm>
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
Config bar_config(int D, double L, bool held, double h = 0.05) {
  Config c = test::box_config(D, "linear");
  c.method.integration = "wls";
  c.grid.cell_size.assign(D, h);
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

// ---- tractions -----------------------------------------------------------------------------------

/// A traction T e_x on the bar's +x faces, with the time factor `scale`.
TractionConfig end_traction(int D, double T, const std::string& scale) {
  TractionConfig t;
  t.name = "pull";
  t.side = 1;  // the +x faces
  t.traction.assign(D, 0.0);
  t.traction[0] = T;
  t.scale = scale;
  return t;
}

struct HeldBar {
  double mean = 0.0;         ///< mean over the hold of the bar's mean sigma_xx, / T
  double oscillation = 0.0;  ///< half the range of the bar's mean sigma_xx over the hold, / T
  double scatter = 0.0;      ///< rms deviation of the particles' sigma_xx from T at the end, / T
  double section = 0.0;      ///< cross-section of the integrated body / that of the bar
};

/// The held bar of docs/wls.md ("Tractions"): the bar [0, L] x [lo, hi]^(D-1) on a symmetry
/// face, pulled at x = L by a traction T ramped smoothly, 0.5 (1 - cos(pi t / t_r)), over
/// `transits` wave transits L / c and then held for eight more; the particles with X < 0.3
/// sampled over the last four transits (one period of the bar's fundamental mode).
template <int D>
HeldBar held_bar(double L, double lo, double hi, double transits, double h = 0.05,
                 const std::vector<std::pair<std::string, std::string>>& keys = {}) {
  constexpr double T = 1.0e3;
  Config c = bar_config(D, L, true, h);
  for (const auto& [key, value] : keys) c.method.plugin.set(key, value);
  for (int a = 1; a < D; ++a) {
    c.bodies[0].shape.min[a] = lo;
    c.bodies[0].shape.max[a] = hi;
  }
  const double transit = L / std::sqrt(E / 1000.0), t_r = transits * transit, end = t_r + 8.0 * transit;
  const std::string r = std::to_string(t_r);
  c.tractions.push_back(end_traction(D, T, "t < " + r + " ? 0.5 * (1 - cos(pi * t / " + r + ")) : 1"));
  c.simulation.end_time = end;
  Simulation<D> sim(c);
  double sum = 0.0, low = 1e300, high = -1e300;
  int samples = 0;
  while (sim.time() < end - 1e-12) {
    sim.step(std::min(sim.next_dt(), end - sim.time()));
    if (sim.time() < end - 4.0 * transit) continue;
    const double sxx = mean_stress(sim, 0.3).first;
    sum += sxx;
    low = std::min(low, sxx);
    high = std::max(high, sxx);
    ++samples;
  }
  // The cross-section of the body WLS integrates (seed 001 Sec. 3.4): the regions of the cells
  // in 0.1 < x < 0.3. In 3D it is smaller than the bar's, as every convex edge along the bar is
  // rounded (docs/wls.md, "Cut cells"), so the same force gives a larger stress.
  double volume = 0.0;
  for (const auto& q : sim.wls()->regions())
    if (q.centroid[0] > 0.1 && q.centroid[0] < 0.3) volume += q.volume;
  const double area = std::pow(hi - lo, D - 1);
  HeldBar result;
  result.section = volume / 0.2 / area;
  result.mean = sum / samples / T;
  result.oscillation = 0.5 * (high - low) / T;
  const auto& P = sim.particles();
  double sq = 0.0;
  int n = 0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    if (wls::is_surface(P, p)) continue;
    const double s = P.kirchhoff_stress[p](0, 0) / P.deformation_gradient[p].determinant() / T - 1.0;
    sq += s * s;
    ++n;
  }
  result.scatter = std::sqrt(sq / n);
  std::printf("held bar %dD, h = %g, x in [0, %g], y in [%g, %g], ramp %g transits: mean sigma_xx / T = %.4f, oscillation "
              "+-%.4f, particle scatter (rms) %.4f; integrated cross-section / the bar's %.4f\n", D, h, L, lo, hi,
              transits, result.mean, result.oscillation, result.scatter, result.section);
  return result;
}

TEST(WlsConditions, TractionPullsAHeldBarToTheStaticStress) {
  // docs/wls.md, "Tractions": the loaded face inside a cell (x = 0.425), on a node line
  // (x = 0.45) and a fiftieth of a cell on either side of it (slivers of cut cells), the lateral
  // faces inside cells and on node lines.
  struct Placement {
    double L, lo, hi;
  };
  for (const Placement& at : {Placement{0.425, 0.275, 0.525}, Placement{0.45, 0.275, 0.525},
                              Placement{0.45, 0.25, 0.55}, Placement{0.425, 0.25, 0.55},
                              Placement{0.449, 0.275, 0.525}, Placement{0.451, 0.275, 0.525}}) {
    const HeldBar r = held_bar<2>(at.L, at.lo, at.hi, 10.0);
    EXPECT_NEAR(r.mean, 1.0, 0.02) << at.L << " " << at.lo;
    EXPECT_LT(r.oscillation, 0.01) << at.L << " " << at.lo;  // (the ramp leaves the continuum at rest)
  }
}

TEST(WlsConditions, TractionPullsAHeldBarToTheStaticStressWithTheTransposedGradient) {
  // The set-up docs/wls.md recommends (fitted point values, transposed gradient: items 7 and 17)
  // under a traction: the loaded face inside a cell and on a node line, in 2D and 3D. Measured
  // 2026-11-30: mean sigma_xx / T 1.0000 and 1.0005 in 2D (particle scatter 0.10 and 0.04
  // against 0.19 and 0.15 with the defaults); 3D as with the defaults.
  const std::vector<std::pair<std::string, std::string>> keys = {{"velocity_gradient", "transpose"},
                                                                  {"point_values", "fit"}};
  for (const auto& [L, lo, hi] : {std::array<double, 3>{0.425, 0.275, 0.525}, std::array<double, 3>{0.425, 0.25, 0.55},
                                  std::array<double, 3>{0.45, 0.275, 0.525}}) {
    const HeldBar r = held_bar<2>(L, lo, hi, 10.0, 0.05, keys);
    EXPECT_NEAR(r.mean, 1.0, 0.02) << L << " " << lo;
    EXPECT_LT(r.oscillation, 0.01) << L << " " << lo;
  }
  const HeldBar r = held_bar<3>(0.45, 0.25, 0.55, 10.0, 0.05, keys);
  EXPECT_NEAR(r.mean * r.section, 1.0, 0.02);
  EXPECT_LT(r.oscillation, 0.02);
}

TEST(WlsConditions, TractionPullsAHeldBarToTheStaticStress3D) {
  struct Placement {
    double L, lo, hi;
  };
  for (const Placement& at : {Placement{0.425, 0.275, 0.525}, Placement{0.45, 0.25, 0.55}}) {
    const HeldBar r = held_bar<3>(at.L, at.lo, at.hi, 10.0);
    EXPECT_NEAR(r.mean * r.section, 1.0, 0.02) << at.L << " " << at.lo;  // the force T A
    EXPECT_LT(r.section, 1.0);
    EXPECT_LT(r.oscillation, 0.02) << at.L << " " << at.lo;
  }
}

// The 3D held bar on finer grids (label `long`, ctest wls.traction_refinement; about 2 min):
// the integrated body's section loses the rounded edges, O(h^2), so the section deficit falls by
// about 4 from h = 0.05 to 0.025 and the mean stress tends to T, while the load stays T A.
TEST(WlsLong, DISABLED_TractionOnAHeldBarConvergesIn3D) {
  const HeldBar coarse = held_bar<3>(0.45, 0.25, 0.55, 10.0, 0.05);
  const HeldBar fine = held_bar<3>(0.45, 0.25, 0.55, 10.0, 0.025);
  for (const HeldBar& r : {coarse, fine}) {
    EXPECT_NEAR(r.mean * r.section, 1.0, 0.01);  // the force T A
    EXPECT_LT(r.oscillation, 0.02);
  }
  const double order = std::log2((1.0 - coarse.section) / (1.0 - fine.section));
  std::printf("section deficit %.4f -> %.4f (order %.2f), mean sigma_xx / T - 1: %.4f -> %.4f\n",
              1.0 - coarse.section, 1.0 - fine.section, order, coarse.mean - 1.0, fine.mean - 1.0);
  EXPECT_GT(order, 1.6);
  EXPECT_LT(std::abs(fine.mean - 1.0), 0.4 * std::abs(coarse.mean - 1.0));
  // The particles' scatter does not fall with h in 3D (0.099, 0.106; docs/wls.md): not asserted.
}

template <int D>
void check_free_bar(double L, bool periodic) {
  // A free bar pulled at x = L by a constant traction: the node loads of every step sum to T A
  // (A the faces' current area, which the traction's total records), and the body's momentum is
  // the impulse T A t.
  constexpr double T = 1.0e3;
  Config c = bar_config(D, L, false);
  c.bodies[0].shape.min[0] = 0.1;
  if (periodic) {
    // No lateral faces: the bar spans the periodic y (and z) axes.
    for (int a = 1; a < D; ++a) {
      c.boundary.face[2 * a] = c.boundary.face[2 * a + 1] = FaceCondition::periodic;
      c.bodies[0].shape.min[a] = 0.0;
      c.bodies[0].shape.max[a] = 1.0;
    }
  }
  c.tractions.push_back(end_traction(D, T, "1"));
  Simulation<D> sim(c);
  const double A = std::pow(periodic ? 1.0 : 0.25, D - 1);  // thickness 1 in 2D
  double impulse = 0.0, worst_sum = 0.0;
  for (int s = 0; s < 60; ++s) {
    const double dt = sim.next_dt();
    sim.step(dt);
    Vec<D> sum = Vec<D>::Zero();
    for (const auto& f : sim.wls()->surface_force()) sum += f;
    const Vec<D> total = sim.tractions().total_force(0);
    worst_sum = std::max(worst_sum, (sum - total).norm() / total.norm());
    EXPECT_NEAR(total[0] / (T * A), 1.0, 0.01);  // the faces stretch a little
    impulse += (s == 0 ? 0.5 : 1.0) * total[0] * dt;  // half the first acceleration (seed 001 Sec. 4.7)
  }
  const auto& P = sim.particles();
  Vec<D> momentum = Vec<D>::Zero();
  double particle_mass = 0.0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    momentum += P.mass[p] * P.velocity[p];
    particle_mass += P.mass[p];
  }
  Vec<D> node_momentum = Vec<D>::Zero();
  double node_mass = 0.0;
  for (std::int32_t i = 0; i < sim.grid().n_nodes(); ++i) {
    node_momentum += sim.nodes().mass[i] * sim.nodes().velocity_new[i];
    node_mass += sim.nodes().mass[i];
  }
  std::printf("free bar %dD (x = %g, %s): node loads sum to T A within %.2g; momentum %.6g (nodes %.6g), impulse %.6g "
              "(T A t = %.6g); mass: particles %.6g, nodes %.6g\n",
              D, L, periodic ? "periodic" : "free lateral faces", worst_sum, momentum[0], node_momentum[0], impulse, T * A * sim.time(), particle_mass, node_mass);
  EXPECT_LT(worst_sum, 1e-12);
  for (int a = 1; a < D; ++a) EXPECT_LT(std::abs(momentum[a]), 1e-3 * impulse);
  if (periodic) {
    EXPECT_NEAR(momentum[0] / impulse, 1.0, 2e-3);
  } else {
    // The integrated body lacks the rounded convex corners (edges in 3D) of its cut cells: its
    // mass (Eq. 22) is smaller than the particles', and the load accelerates it faster by that
    // ratio (docs/wls.md, "Tractions").
    EXPECT_NEAR(momentum[0] / impulse * node_mass / particle_mass, 1.0, 0.01);
  }
}

TEST(WlsConditions, TractionImpulseMovesAFreeBar) {
  ASSERT_NO_FATAL_FAILURE(check_free_bar<2>(0.425, true));
  ASSERT_NO_FATAL_FAILURE(check_free_bar<2>(0.45, true));
  ASSERT_NO_FATAL_FAILURE(check_free_bar<3>(0.425, true));
  ASSERT_NO_FATAL_FAILURE(check_free_bar<2>(0.425, false));
  ASSERT_NO_FATAL_FAILURE(check_free_bar<3>(0.425, false));
}

TEST(WlsConditions, TractionRefusesTheNarrowGradient) {
  // Eq. 29 as printed: the held bar grows node-scale noise until det F < 0 (docs/wls.md).
  Config c = bar_config(2, 0.425, true);
  c.tractions.push_back(end_traction(2, 1.0e3, "1"));
  c.method.plugin.set("velocity_gradient", "narrow");
  EXPECT_THROW(Simulation<2>{c}, std::invalid_argument);
}

TEST(WlsConditions, TractionOnARadialBodyIsRefused) {
  // Tractions load the faces of lattice particles; the rings of the radial arrangement have none.
  Config c = bar_config(2, 0.425, false);
  c.bodies[0].shape.kind = "circle";
  c.bodies[0].shape.center = {0.5, 0.5};
  c.bodies[0].shape.radius = 0.2;
  c.bodies[0].arrangement = "radial";
  c.tractions.push_back(end_traction(2, 1.0e3, "1"));
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

// ---- a body landing on a frictionless wall -------------------------------------------------------

/// A strip [0, 0.25] x [0.11, 0.41] across the periodic x axis (a 1D problem) falling at v0 = 0.2
/// onto the symmetry face y = 0, which it does not reach at the start (the walls of seed 001
/// Sec. 5.2); neo-Hookean as the disk impact (E = 1000, nu = 0.3, rho0 = 1000), h = 0.025, 2 ppc,
/// central differences, CFL 0.4. Returns the largest speed into the wall of any particle row
/// (mean over the row's particles with volume) until t = 0.7, in units of v0. In the exact
/// solution no part of the strip moves faster than v0: the wall stops the rows nearest to it
/// first (docs/wls.md, departure 14).
double fastest_row_into_the_wall(const std::string& mirror_planes) {
  constexpr double v0 = 0.2;
  Config c = test::box_config(2, "linear", "neo_hookean");
  c.method.integration = "wls";
  c.method.time_integration = "central_difference";
  c.method.plugin.set("mirror_planes", mirror_planes);
  c.materials[0].numbers["youngs_modulus"] = 1000.0;
  c.grid.extent = {0.25, 1.0};
  c.grid.cell_size.assign(2, 0.025);
  c.boundary.face[0] = c.boundary.face[1] = FaceCondition::periodic;
  c.boundary.face[2] = c.boundary.face[3] = FaceCondition::symmetry;
  auto& b = c.bodies[0];
  b.shape.min = {0.0, 0.11};
  b.shape.max = {0.25, 0.41};
  b.velocity = {"0", "-0.2"};
  Simulation<2> sim(c);
  const auto& P = sim.particles();
  double fastest = 0.0;
  while (sim.time() < 0.7) {
    sim.step(sim.next_dt());
    std::map<long long, std::pair<double, int>> rows;  // reference y (in 1e-6) -> sum v_y, count
    for (std::size_t p = 0; p < P.n(); ++p) {
      if (wls::is_surface(P, p)) continue;
      auto& r = rows[std::llround(P.reference_position[p][1] * 1e6)];
      r.first += P.velocity[p][1];
      ++r.second;
    }
    for (const auto& [y, r] : rows) fastest = std::max(fastest, -r.first / r.second / v0);
  }
  return fastest;
}

TEST(WlsConditions, BodyLandingOnAWallSlowsFromTheWallUp) {
  // With the wall's nodes held while the strip's surface is still up to a cell away, the cut
  // cell between the wall and the first node row holds a sliver of the strip whose small volume
  // cannot pass the wall's reaction to that row (Eq. 24): the row is pushed on towards the wall
  // by the cell above it and the rows nearest the wall speed up past v0 (measured 1.086 v0).
  // With the wall a mirror plane (method.mirror_planes = "all") the strip meets its image at the
  // wall and the nearest rows stop first (measured 1.000 v0; cpGIMP 1.008 v0).
  const double reached = fastest_row_into_the_wall("reached");
  const double all = fastest_row_into_the_wall("all");
  std::printf("fastest row into the wall / v0: mirror_planes = reached %.4f, all %.4f\n", reached, all);
  EXPECT_GT(reached, 1.05);
  EXPECT_LT(all, 1.01);
}

TEST(WlsConditions, EmptyWallCornersKeepTheWallsVelocity) {
  // A surface particle 0.3 h above a wall, in a cell whose corners on the wall carry no mass and
  // whose upper corners (with mass) move at v+ = (0.3, -1), from rest. The empty corners take
  // the mean of the corners with mass (empty_corners = "mean", docs/wls.md departure 12) except
  // in the components the wall's condition set (held: the normal one, zero): the particle takes
  // 0.3 of the normal motion, the upper corners' share of S, and all of the tangential one.
  // Without the held components it would move on into the wall at the inner corners' speed.
  Simulation<2> sim(bar_config(2, 0.425, false));
  const auto& grid = sim.grid();
  const double h = grid.cell_size()[0];
  wls::Integrator<2> wls(grid, wls::Options{});
  Particles<2> start;
  start.add(Vec<2>(0.51, 0.3 * h), Vec<2>::Zero(), 1.0, 0.0, Vec<2>::Constant(0.5 * h), 0, 0);
  wls.build_stencils(grid, start);
  NodeField<2> nodes = sim.nodes();
  std::vector<std::uint8_t> held(static_cast<std::size_t>(grid.n_nodes()), 0);
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    const double y = grid.node_position(i)[1];
    const bool above = y > 0.5 * h;
    nodes.mass[i] = above ? 1.0 : 0.0;
    nodes.velocity[i] = Vec<2>::Zero();
    nodes.velocity_new[i] = above ? Vec<2>(0.3, -1.0) : Vec<2>::Zero();
    if (std::abs(y) < 1e-12) held[i] = 0b10;  // the floor's symmetry condition: v_y = 0
  }
  const double dt = 1e-3;
  Particles<2> free = start, walled = start;
  wls.move_particles(grid, nodes, free, dt);
  wls.move_particles(grid, nodes, walled, dt, &held);
  EXPECT_NEAR((free.velocity[0] - Vec<2>(0.3, -1.0)).norm(), 0.0, 1e-14);
  EXPECT_NEAR((walled.velocity[0] - Vec<2>(0.3, -0.3)).norm(), 0.0, 1e-14);
  EXPECT_NEAR(walled.position[0][1] - start.position[0][1], -0.3 * dt, 1e-15);
  EXPECT_NEAR(walled.position[0][0] - start.position[0][0], 0.3 * dt, 1e-15);
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
void check_periodic_seam(int steps, const std::string& surface_velocity = "own") {
  // The same body, once in the middle of the grid and once shifted by half the periodic length
  // so that the seam runs through it, for `steps` steps in which its particles travel about
  // 2 cells (2D; 1 in 3D) and those next to the seam cross it: every particle ends with the same
  // velocity, stress and (up to the period) position, to round-off.
  Config c_away = periodic_config(D, 0.0), c_across = periodic_config(D, 0.5);
  c_away.method.plugin.set("surface_velocity", surface_velocity);
  c_across.method.plugin.set("surface_velocity", surface_velocity);
  Simulation<D> away(c_away), across(c_across);
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
  // The surface particles' fitted velocity (docs/wls.md, departure 16) reads the corners' fits
  // at the particle through the seam too.
  ASSERT_NO_FATAL_FAILURE(check_periodic_seam<2>(40, "fit"));
}

TEST(WlsConditions, OddPeriodicAxisIsBitIdenticalForAnyThreadCount) {
  // 21 cells along the periodic x axis: the region scatters give the last cell, whose upper nodes
  // are cell 0's lower ones, a colour of its own (Integrator constructor). A body across the seam,
  // in 1, 2 and 3 threads; with the default gradient and update, and with verification/plate_hole's
  // transposed gradient (its node sums are region scatters too) and XPIC(4) particle velocities
  // (a particle scatter per term).
  for (const std::string gradient : {"quadrature", "transpose"}) {
    Config c = periodic_config(2, 0.0);
    c.method.plugin.set("velocity_gradient", gradient);
    if (gradient == "transpose") {
      c.method.plugin.set("particle_velocity", std::string("xpic"));
      c.method.order = 4;
    }
    c.grid.extent[0] = 1.05;
    c.bodies.resize(2, c.bodies[0]);
    c.bodies[0].shape.min[0] = 0.8;
    c.bodies[0].shape.max[0] = 1.05;
    c.bodies[1].name = "wrapped";
    c.bodies[1].shape.min[0] = 0.0;
    c.bodies[1].shape.max[0] = 0.2;
    std::vector<Particles<2>> results;
    for (const int threads : {1, 2, 3}) {
      c.simulation.threads = threads;
      Simulation<2> sim(c);
      ASSERT_EQ(sim.grid().n_cells()[0], 21);
      for (int s = 0; s < 40; ++s) sim.step(sim.next_dt());
      results.push_back(sim.particles());
    }
    omp_set_num_threads(omp_get_num_procs());
    for (std::size_t r = 1; r < results.size(); ++r)
      for (std::size_t p = 0; p < results[0].n(); ++p) {
        ASSERT_EQ(results[r].position[p], results[0].position[p]) << gradient << " " << r << " " << p;
        ASSERT_EQ(results[r].velocity[p], results[0].velocity[p]) << gradient << " " << r << " " << p;
        ASSERT_EQ(results[r].kirchhoff_stress[p], results[0].kirchhoff_stress[p])
            << gradient << " " << r << " " << p;
      }
  }
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
