// Tests of the WLS pieces (seed 001): the weights (Eq. 4-6), the planar least squares (Eq. 7-12)
// reproducing linear fields exactly, the cut cells (every marching-squares case; exact volumes
// and centroids for planar cuts in 2D and 3D; the 3D tetrahedral pieces against sampling), the
// signed distance of a circle (Eq. 13-17), the particle arrangements, and whole-method
// properties (linear velocity fields reproduced at the nodes, the integration volume of a body,
// rigid motion and uniform stress giving no spurious deformation or interior force).
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <numbers>
#include <random>

#include "../support/config_builder.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/wls/arrangement.hpp"
#include "cairn/wls/cut_cell.hpp"
#include "cairn/wls/grid_stencil.hpp"
#include "cairn/wls/integrator.hpp"
#include "cairn/wls/least_squares.hpp"
#include "cairn/wls/weights.hpp"

namespace cairn {
namespace {

using wls::CellRegion;

// ---- weights ------------------------------------------------------------------------------------

TEST(WlsWeights, PartitionOfUnityAndZeroGradientSum) {
  const double h = 0.3;
  for (double x = -1.0; x <= 1.0; x += 0.0137) {
    double sw = 0.0, ss = 0.0, sg = 0.0;
    for (int i = -6; i <= 6; ++i) {
      const double r = x - i * h;
      sw += wls::wide_weight(r, h);
      ss += wls::narrow_shape(r, h);
      sg += wls::narrow_gradient(r, h);
    }
    EXPECT_NEAR(sw, 1.0, 1e-13) << x;
    EXPECT_NEAR(ss, 1.0, 1e-13) << x;
    if (std::abs(std::remainder(x, h)) > 1e-9) { EXPECT_NEAR(sg, 0.0, 1e-12) << x; }
  }
  EXPECT_DOUBLE_EQ(wls::wide_weight(0.0, h), 0.75);
  EXPECT_DOUBLE_EQ(wls::wide_weight(h, h), 0.125);
  EXPECT_DOUBLE_EQ(wls::wide_weight(1.5 * h, h), 0.0);
  EXPECT_DOUBLE_EQ(wls::narrow_gradient(-0.5 * h, h), 1.0 / h);
  EXPECT_DOUBLE_EQ(wls::narrow_gradient(0.0, h), -1.0 / h);  // sign(0) = 1
}

// ---- least squares ------------------------------------------------------------------------------

template <int D>
void check_plane_fit(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.4, 1.4), c(-2.0, 2.0);
  using Fit = wls::PlaneFit<D>;
  typename Fit::Matrix M = Fit::Matrix::Zero();
  typename Fit::Vector l = Fit::Vector::Zero();
  const double a0 = c(rng);
  Vec<D> g;
  for (int a = 0; a < D; ++a) g[a] = c(rng);
  for (int p = 0; p < 12; ++p) {
    Vec<D> r;
    double W = 1.0;
    for (int a = 0; a < D; ++a) {
      r[a] = u(rng);
      W *= wls::wide_weight(r[a], 1.0);
    }
    const auto b = Fit::basis(r);
    M += W * b * b.transpose();
    l += W * (a0 + g.dot(r)) * b;
  }
  bool reduced = true;
  const auto inv = Fit::inverse(M, false, &reduced);
  ASSERT_FALSE(reduced);
  const typename Fit::Vector coef = inv * l;
  EXPECT_NEAR(coef[0], a0, 1e-12);  // Eq. 11
  for (int a = 0; a < D; ++a) EXPECT_NEAR(coef[1 + a], g[a], 1e-11);  // Eq. 12
  // The reduced basis (Sec. 3.5) is the W-weighted mean.
  const auto inv0 = Fit::inverse(M, true, &reduced);
  EXPECT_TRUE(reduced);
  EXPECT_NEAR((inv0 * l)[0], l[0] / M(0, 0), 1e-14);
  EXPECT_EQ((inv0 * l).template tail<D>().norm(), 0.0);
}

TEST(WlsLeastSquares, PlanarBasisReproducesLinearFieldsExactly) {
  // The checks are in the helper; ASSERT_NO_FATAL_FAILURE stops at the first seed whose fit fails.
  for (unsigned s = 1; s <= 20; ++s) {
    SCOPED_TRACE(s);
    ASSERT_NO_FATAL_FAILURE(check_plane_fit<2>(s));
    ASSERT_NO_FATAL_FAILURE(check_plane_fit<3>(100 + s));
  }
}

TEST(WlsLeastSquares, SingularMomentMatrixFallsBackToTheConstantFit) {
  // Three particles on one line: the planar basis in 2D is singular.
  using Fit = wls::PlaneFit<2>;
  Fit::Matrix M = Fit::Matrix::Zero();
  for (double t : {-0.5, 0.1, 0.7}) {
    const auto b = Fit::basis(Vec<2>(t, 2.0 * t));
    M += 0.3 * b * b.transpose();
  }
  bool reduced = false;
  const auto inv = Fit::inverse(M, false, &reduced);
  EXPECT_TRUE(reduced);
  EXPECT_NEAR(inv(0, 0), 1.0 / M(0, 0), 1e-15);
}

// ---- cut cells ----------------------------------------------------------------------------------

/// Exact area and first moments of {x in [0,1]^2 : n . x <= c} (inclusion-exclusion over the
/// corners; every n_a != 0): A = sum_v s_v (c - n.v)_+^2 / (2 n1 n2),
/// M_a = sum_v s_v [v_a (c - n.v)_+^2 / (2 P) + (c - n.v)_+^3 / (6 P n_a)], s_v = (-1)^|v|.
/// In 3D the same with powers 3, 4 and 6 P, 24 P n_a.
template <int D>
std::pair<double, Vec<D>> half_space_in_unit_cell(const Vec<D>& n, double c) {
  double P = n.prod(), V = 0.0;
  Vec<D> M = Vec<D>::Zero();
  const double f1 = D == 2 ? 2.0 : 6.0, f2 = D == 2 ? 6.0 : 24.0;
  for (int k = 0; k < (1 << D); ++k) {
    Vec<D> v;
    int bits = 0;
    for (int a = 0; a < D; ++a) {
      v[a] = (k >> a) & 1;
      bits += (k >> a) & 1;
    }
    const double s = (bits % 2) ? -1.0 : 1.0;
    const double t = std::max(0.0, c - n.dot(v));
    V += s * std::pow(t, D) / (f1 * P);
    for (int a = 0; a < D; ++a) M[a] += s * (v[a] * std::pow(t, D) / (f1 * P) + std::pow(t, D + 1) / (f2 * P * n[a]));
  }
  return {V, M / V};
}

template <int D>
void check_planar_cuts(unsigned seed, int trials) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.5, 2.0);
  const Vec<D> lo = Vec<D>::Constant(0.37), h = Vec<D>::Ones();  // unit cells; offset origin
  int checked = 0;
  for (int t = 0; t < trials; ++t) {
    Vec<D> n;
    for (int a = 0; a < D; ++a) {
      do n[a] = u(rng);
      while (std::abs(n[a]) < 0.05);
    }
    const double c = u(rng) * n.cwiseAbs().sum();
    std::array<double, (1 << D)> d;
    for (int k = 0; k < (1 << D); ++k) {
      Vec<D> v;
      for (int a = 0; a < D; ++a) v[a] = (k >> a) & 1;
      d[k] = c - n.dot(v);  // positive inside: the half space n . x < c
    }
    std::array<CellRegion<D>, wls::max_regions<D>> out;
    const int nr = wls::cut_cell<D>(d, lo, h, out);
    const auto [V, centroid] = half_space_in_unit_cell<D>(n, c);
    if (V < 1e-12) {
      EXPECT_EQ(nr, 0);
      continue;
    }
    ASSERT_EQ(nr, 1) << "a plane leaves one connected region";
    EXPECT_NEAR(out[0].volume, V, 1e-12);
    for (int a = 0; a < D; ++a) EXPECT_NEAR(out[0].centroid[a], lo[a] + centroid[a], 1e-11);
    ++checked;
  }
  EXPECT_GT(checked, trials / 2);
}

TEST(WlsCutCell, PlanarCutsGiveExactAreasAndCentroidsIn2D) { ASSERT_NO_FATAL_FAILURE(check_planar_cuts<2>(7, 400)); }

TEST(WlsCutCell, PlanarCutsGiveExactVolumesAndCentroidsIn3D) { ASSERT_NO_FATAL_FAILURE(check_planar_cuts<3>(11, 400)); }

TEST(WlsCutCell, AxisAlignedCutsAndScaledCells) {
  // Cell [1, 3] x [2, 2.5] cut at x = 1.5 (d = 1.5 - x): the left quarter.
  std::array<CellRegion<2>, 2> out;
  std::array<double, 4> d{0.5, -1.5, 0.5, -1.5};
  ASSERT_EQ(wls::cut_cell<2>(d, Vec<2>(1.0, 2.0), Vec<2>(2.0, 0.5), out), 1);
  EXPECT_NEAR(out[0].volume, 0.25, 1e-15);
  EXPECT_NEAR(out[0].centroid[0], 1.25, 1e-15);
  EXPECT_NEAR(out[0].centroid[1], 2.25, 1e-15);
  // 3D: cell [0,2]^3 cut at z = 0.5 (d = 0.5 - z).
  std::array<CellRegion<3>, 6> o3;
  std::array<double, 8> d3;
  for (int k = 0; k < 8; ++k) d3[k] = 0.5 - ((k & 4) ? 2.0 : 0.0);
  ASSERT_EQ(wls::cut_cell<3>(d3, Vec<3>::Zero(), Vec<3>::Constant(2.0), o3), 1);
  EXPECT_NEAR(o3[0].volume, 2.0, 1e-14);
  EXPECT_NEAR((o3[0].centroid - Vec<3>(1.0, 1.0, 0.25)).norm(), 0.0, 1e-14);
}

/// Area and centroid of the marching-squares region by sampling a fine lattice, from an
/// independent description of the region: without a saddle, one cut segment crosses the square
/// and the region is the side of its line holding the inside corners; a saddle is either the
/// square minus the two triangles at its outside corners (connected) or the two triangles at
/// its inside corners (separated).
std::pair<double, Vec<2>> sampled_region(const std::array<double, 4>& d, bool saddle, bool separated, int n) {
  auto corner = [](int k) { return Vec<2>(k & 1, (k >> 1) & 1); };
  auto cut = [&](int i, int o) { return Vec<2>(corner(i) - d[i] * (corner(i) - corner(o)) / (d[i] - d[o])); };
  auto cross = [](const Vec<2>& u, const Vec<2>& v, const Vec<2>& w) {
    return (v[0] - u[0]) * (w[1] - u[1]) - (v[1] - u[1]) * (w[0] - u[0]);
  };
  auto in_triangle = [&](const Vec<2>& p, const Vec<2>& a, const Vec<2>& b, const Vec<2>& c) {
    const double s1 = cross(a, b, p), s2 = cross(b, c, p), s3 = cross(c, a, p);
    return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
  };
  auto corner_triangle = [&](const Vec<2>& p, int k) { return in_triangle(p, corner(k), cut(k, k ^ 1), cut(k, k ^ 2)); };
  std::vector<Vec<2>> cuts;
  int some_inside = -1;
  for (int k = 0; k < 4; ++k) {
    if (d[k] > 0.0) some_inside = k;
    for (int o : {k ^ 1, k ^ 2})
      if (d[k] > 0.0 && d[o] <= 0.0) cuts.push_back(cut(k, o));
  }
  double area = 0.0;
  Vec<2> m = Vec<2>::Zero();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec<2> p((i + 0.5) / n, (j + 0.5) / n);
      bool inside;
      if (some_inside < 0) {
        inside = false;
      } else if (cuts.empty()) {
        inside = true;
      } else if (!saddle) {
        inside = cross(cuts[0], cuts[1], p) * cross(cuts[0], cuts[1], corner(some_inside)) > 0.0;
      } else if (separated) {
        inside = false;
        for (int k = 0; k < 4; ++k)
          if (d[k] > 0.0) inside |= corner_triangle(p, k);
      } else {
        inside = true;
        for (int k = 0; k < 4; ++k)
          if (d[k] <= 0.0) inside &= !in_triangle(p, corner(k), cut(k ^ 1, k), cut(k ^ 2, k));
      }
      if (inside) {
        area += 1.0;
        m += p;
      }
    }
  return {area / (double(n) * n), area > 0 ? Vec<2>(m / area) : Vec<2>::Zero()};
}

TEST(WlsCutCell, EveryMarchingSquaresCase) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> mag(0.1, 1.0);
  for (int mask = 0; mask < 16; ++mask)
    for (int variant = 0; variant < 4; ++variant) {
      std::array<double, 4> d;
      for (int k = 0; k < 4; ++k) d[k] = ((mask >> k) & 1) ? mag(rng) : -mag(rng);
      const bool saddle = mask == 6 || mask == 9;
      const bool separated = saddle && (d[0] + d[1] + d[2] + d[3]) <= 0.0;
      std::array<CellRegion<2>, 2> out;
      const int nr = wls::cut_cell<2>(d, Vec<2>::Zero(), Vec<2>::Ones(), out);
      const int expected = mask == 0 ? 0 : separated ? 2 : 1;
      ASSERT_EQ(nr, expected) << "mask " << mask;
      if (nr == 0) continue;
      double area = 0.0;
      Vec<2> m = Vec<2>::Zero();
      for (int r = 0; r < nr; ++r) {
        EXPECT_GT(out[r].volume, 0.0);
        area += out[r].volume;
        m += out[r].volume * out[r].centroid;
      }
      const auto [ref_area, ref_centroid] = sampled_region(d, saddle, separated, 800);
      EXPECT_NEAR(area, ref_area, 4e-3) << "mask " << mask;
      EXPECT_NEAR((m / area - ref_centroid).norm(), 0.0, 4e-3) << "mask " << mask;
    }
}

TEST(WlsCutCell, SaddleDecidedByTheCentreValue) {
  std::array<CellRegion<2>, 2> out;
  // Corners 0 and 3 inside, strongly: the centre is inside, one hexagon.
  EXPECT_EQ(wls::cut_cell<2>({1.0, -0.2, -0.2, 1.0}, Vec<2>::Zero(), Vec<2>::Ones(), out), 1);
  EXPECT_NEAR(out[0].centroid[0], 0.5, 1e-14);
  // Weakly inside: two corner triangles of area 1/2 * (1/3)^2 each (cuts at 1/3).
  ASSERT_EQ(wls::cut_cell<2>({0.5, -1.0, -1.0, 0.5}, Vec<2>::Zero(), Vec<2>::Ones(), out), 2);
  EXPECT_NEAR(out[0].volume, 1.0 / 18.0, 1e-15);
  EXPECT_NEAR(out[1].volume, 1.0 / 18.0, 1e-15);
  EXPECT_NEAR(out[0].centroid[0], 1.0 / 9.0, 1e-15);
  EXPECT_NEAR(out[1].centroid[0], 1.0 - 1.0 / 9.0, 1e-15);
}

/// Volume and centroid of the positive part of the Kuhn-piecewise-linear interpolant of the
/// corner values, by sampling: a point's tetrahedron is the ordering of its coordinates.
std::pair<double, Vec<3>> sampled_kuhn(const std::array<double, 8>& d, int n) {
  double vol = 0.0;
  Vec<3> m = Vec<3>::Zero();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const Vec<3> p((i + 0.5) / n, (j + 0.5) / n, (k + 0.5) / n);
        int ax[3] = {0, 1, 2};
        std::sort(ax, ax + 3, [&](int a, int b) { return p[a] > p[b]; });
        // Barycentric weights along the path 0 -> e_ax0 -> e_ax0+e_ax1 -> 7.
        const int v1 = 1 << ax[0], v2 = v1 | (1 << ax[1]);
        const double value = (1.0 - p[ax[0]]) * d[0] + (p[ax[0]] - p[ax[1]]) * d[v1] +
                             (p[ax[1]] - p[ax[2]]) * d[v2] + p[ax[2]] * d[7];
        if (value > 0.0) {
          vol += 1.0;
          m += p;
        }
      }
  return {vol / (double(n) * n * n), vol > 0 ? Vec<3>(m / vol) : Vec<3>::Zero()};
}

TEST(WlsCutCell, TetrahedralPiecesMatchTheInterpolantIn3D) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    std::array<double, 8> d;
    for (double& x : d) x = u(rng);
    std::array<CellRegion<3>, 6> out;
    const int nr = wls::cut_cell<3>(d, Vec<3>::Zero(), Vec<3>::Ones(), out);
    double vol = 0.0;
    Vec<3> m = Vec<3>::Zero();
    for (int r = 0; r < nr; ++r) {
      vol += out[r].volume;
      m += out[r].volume * out[r].centroid;
    }
    const auto [ref_vol, ref_centroid] = sampled_kuhn(d, 90);
    EXPECT_NEAR(vol, ref_vol, 3e-3) << trial;
    if (ref_vol > 0.02) { EXPECT_NEAR((m / vol - ref_centroid).norm(), 0.0, 1e-2) << trial; }
  }
}

TEST(WlsCutCell, SeparatedCornersInTheCubeAreTwoRegions) {
  // Corners 1 (+x) and 6 (+y+z) inside, no tetrahedron holds both: two corner regions.
  std::array<double, 8> d;
  d.fill(-1.0);
  d[1] = d[6] = 0.5;
  std::array<CellRegion<3>, 6> out;
  ASSERT_EQ(wls::cut_cell<3>(d, Vec<3>::Zero(), Vec<3>::Ones(), out), 2);
  EXPECT_LT(out[0].centroid[1], 0.5);  // near corner 1
  EXPECT_GT(out[1].centroid[1], 0.5);  // near corner 6
  // Corners 0 and 7 share the diagonal of every tetrahedron: one region.
  d.fill(-1.0);
  d[0] = d[7] = 0.5;
  EXPECT_EQ(wls::cut_cell<3>(d, Vec<3>::Zero(), Vec<3>::Ones(), out), 1);
  d.fill(1.0);
  ASSERT_EQ(wls::cut_cell<3>(d, Vec<3>::Zero(), Vec<3>::Ones(), out), 1);
  EXPECT_DOUBLE_EQ(out[0].volume, 1.0);
  d.fill(-1.0);
  EXPECT_EQ(wls::cut_cell<3>(d, Vec<3>::Zero(), Vec<3>::Ones(), out), 0);
}

// ---- arrangements -------------------------------------------------------------------------------

/// The radial arrangement of an annulus about `center` with radii 0.5 and 1 (a ring in 2D, the
/// hollow ball in 3D): every volume point between the radii, the measures adding up to the
/// annulus's, and each surface ring (shell) on its circle (sphere) with about spacing-apart points.
template <int D>
void expect_radial_annulus(const Vec<D>& center, double spacing) {
  BodyShapeConfig s;
  s.kind = "annulus";
  s.center.assign(center.data(), center.data() + D);
  s.inner_radius = 0.5;
  s.outer_radius = 1.0;
  double measure = 0.0;
  int on_inner = 0, on_outer = 0;
  for (const auto& p : wls::radial_arrangement<D>(s, spacing, true)) {
    measure += p.measure;
    const double r = (p.X - center).norm();
    if (p.measure == 0.0) {
      if (std::abs(r - 0.5) < 1e-12) ++on_inner;
      else if (std::abs(r - 1.0) < 1e-12) ++on_outer;
      else ADD_FAILURE() << "surface particle off the annulus's circles at r = " << r;
    } else {
      EXPECT_GT(r, 0.5);
      EXPECT_LT(r, 1.0);
    }
  }
  const double pi = std::numbers::pi;
  // ring: pi (1 - 0.25), 2 pi r / spacing points; shell: 4/3 pi (1 - 0.125), 4 pi r^2 / spacing^2
  EXPECT_NEAR(measure, D == 2 ? pi * 0.75 : 4.0 / 3.0 * pi * 0.875, 1e-12);
  auto points_on = [&](double r) {
    return static_cast<int>(std::lround(D == 2 ? 2 * pi * r / spacing : 4 * pi * r * r / (spacing * spacing)));
  };
  EXPECT_EQ(on_inner, points_on(0.5));
  EXPECT_EQ(on_outer, points_on(1.0));
}

TEST(WlsArrangement, RadialRingsCoverTheAnnulusAndPutSurfaceRingsOnItsCircles) {
  expect_radial_annulus<2>(Vec<2>(0.1, -0.2), 0.05);
  // In 3D an annulus is the hollow ball between two spheres (verification/shell_mms).
  expect_radial_annulus<3>(Vec<3>(0.1, -0.2, 0.3), 0.1);
  BodyShapeConfig s;
  s.kind = "sphere";
  s.center = {0.0, 0.0, 0.0};
  s.radius = 0.4;
  const auto shells = wls::radial_arrangement<3>(s, 0.1, true);
  double vol = 0.0;
  for (const auto& p : shells) vol += p.measure;
  EXPECT_NEAR(vol, 4.0 / 3.0 * std::numbers::pi * 0.064, 1e-12);
  s.kind = "box";
  EXPECT_THROW(wls::radial_arrangement<2>(s, 0.1, true), std::invalid_argument);
}

TEST(WlsArrangement, LatticeSurfacePointsLieOnTheSurface) {
  const double R = 0.33;
  auto in = [&](const Vec<2>& x) { return (x - Vec<2>(0.5, 0.5)).norm() <= R; };
  const auto pts = wls::lattice_surface_points<2>(in, Vec<2>::Constant(0.025), Vec<2>::Constant(0.05), IVec<2>(20, 20));
  ASSERT_GT(pts.size(), 40u);
  for (const auto& x : pts) EXPECT_NEAR((x - Vec<2>(0.5, 0.5)).norm(), R, 1e-10);
}

// ---- the method on whole bodies -----------------------------------------------------------------

/// A 2D or 3D WLS config: a circle/sphere (radial) or a box (lattice) in [0, 1]^D.
Config wls_config(int D, const std::string& kind, double h, int ppc = 2) {
  Config c = test::box_config(D, "linear", "neo_hookean");
  c.method.integration = "wls";
  c.grid.cell_size.assign(D, h);
  auto& b = c.bodies[0];
  b.particles_per_cell.assign(D, ppc);
  if (kind != "box") {
    b.shape.kind = D == 2 ? "circle" : "sphere";
    b.shape.center.assign(D, 0.5);
    b.shape.radius = 0.3;
    b.arrangement = "radial";
  }
  return c;
}

TEST(WlsSignedDistance, CircleNodesGetTheirDistanceToTheSurface) {
  for (const bool projected : {true, false}) {
    Config c = wls_config(2, "circle", 0.05);
    c.method.plugin.set("surface_distance", std::string(projected ? "projection" : "distance"));
    Simulation<2> sim(c);
    const auto& d = sim.wls()->signed_distance();
    const auto& grid = sim.grid();
    const double h = 0.05;
    double worst = 0.0;
    int near = 0;
    for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
      const double exact = 0.3 - (grid.node_position(i) - Vec<2>(0.5, 0.5)).norm();
      if (std::abs(exact) < h) {
        worst = std::max(worst, std::abs(d[i] - exact));
        ++near;
      }
      // Every node is on the right side of the surface (nodes on it excepted).
      if (std::abs(exact) > 0.1 * h) { EXPECT_EQ(d[i] > 0.0, exact > 0.0) << "node " << i << " exact " << exact; }
    }
    EXPECT_GT(near, 40);
    std::printf("signed distance (%s): max error %.3g h over %d nodes within h of the circle\n",
                projected ? "projection" : "distance", worst / h, near);
    EXPECT_LT(worst, 0.1 * h);
  }
}

TEST(WlsIntegration, RegionsCoverTheBodyVolume) {
  // The cut cells approximate the circle by chords: second order in h.
  double error[2];
  for (int k = 0; k < 2; ++k) {
    const double h = 0.05 / (1 << k);
    Simulation<2> sim(wls_config(2, "circle", h));
    double area = 0.0;
    for (const auto& q : sim.wls()->regions()) area += q.volume;
    const double exact = std::numbers::pi * 0.09;
    error[k] = std::abs(area / exact - 1.0);
    std::printf("h = %g: region area %.6f, circle %.6f, relative error %.2e\n", h, area, exact, area / exact - 1.0);
  }
  EXPECT_LT(error[0], 0.02);
  EXPECT_GT(error[0] / error[1], 3.5);
  for (int k = 0; k < 2; ++k) {
    const double h = 0.1 / (1 << k);
    Simulation<3> sim3(wls_config(3, "sphere", h));
    double vol = 0.0;
    for (const auto& q : sim3.wls()->regions()) vol += q.volume;
    error[k] = std::abs(vol / (4.0 / 3.0 * std::numbers::pi * 0.027) - 1.0);
    std::printf("sphere, h = %g: region volume relative error %.3e\n", h, error[k]);
  }
  EXPECT_LT(error[1], 0.05);
  EXPECT_GT(error[0] / error[1], 3.0);
  Simulation<2> box(wls_config(2, "box", 0.1));
  double box_area = 0.0;
  for (const auto& q : box.wls()->regions()) box_area += q.volume;
  // The box [0.3, 0.7]^2 has its faces on cell lines: their nodes lie on the surface and the cuts
  // fall on them, exact. A corner node sees the surface particles of both faces, whose mean lies
  // inside the body, so it counts as outside and its cell keeps the triangle of the three other
  // corners: "corners tend to be rounded" (seed 001 Sec. 3.4), h^2 / 2 lost at each.
  EXPECT_NEAR(box_area, 0.16 - 4 * 0.5 * 0.01, 1e-9);
}

template <int D>
void check_linear_velocity(const std::string& kind) {
  Config c = wls_config(D, kind, 0.1);
  Eigen::Matrix<double, D, D> A;
  const double entries[9] = {0.3, -0.7, 0.2, 0.5, 0.1, -0.4, 0.6, -0.2, 0.9};
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) A(a, b) = entries[3 * a + b];
  const Vec<D> v0 = Vec<D>::Constant(0.25);
  for (int a = 0; a < D; ++a) {
    std::string e = std::to_string(v0[a]);
    for (int b = 0; b < D; ++b) e += " + " + std::to_string(A(a, b)) + " * " + std::string(1, "XYZ"[b]);
    c.bodies[0].velocity.push_back(e);
  }
  // The node values alone (the default), and with the velocity's slopes (surface_velocity =
  // "fit"), which the gradient of the fit reads: the two ways collect sums the velocity fits.
  for (const bool slopes : {false, true}) {
    if (slopes) c.method.plugin.set("surface_velocity", std::string("fit"));
    Simulation<D> sim(c);
    const auto& w = *sim.wls();
    int checked = 0;
    for (std::int32_t i = 0; i < sim.grid().n_nodes(); ++i) {
      if (!w.well_conditioned()[i]) continue;
      const Vec<D> x = sim.grid().node_position(i);
      EXPECT_NEAR((w.node_velocity()[i] - (v0 + A * x)).norm(), 0.0, 1e-11) << i;
      if (slopes) {
        EXPECT_NEAR((w.velocity_gradient_fit(i) - A).norm(), 0.0, 1e-10) << i;
      }
      ++checked;
    }
    EXPECT_GT(checked, 20);
  }
}

TEST(WlsIntegration, NodeFitsReproduceLinearVelocityFields) {
  ASSERT_NO_FATAL_FAILURE(check_linear_velocity<2>("circle"));
  ASSERT_NO_FATAL_FAILURE(check_linear_velocity<2>("box"));
  ASSERT_NO_FATAL_FAILURE(check_linear_velocity<3>("sphere"));
}

template <int D>
void check_particle_gradient(const std::string& velocity_gradient) {
  // One step from an unstressed body moving with v = v0 + A x: the forces vanish, v+ is the
  // node fit, and particles away from the surface get grad V = A exactly, by either rule.
  Config c = wls_config(D, "circle", 0.05);
  c.method.plugin.set("velocity_gradient", std::string(velocity_gradient));
  const double entries[9] = {0.3, -0.7, 0.2, 0.5, 0.1, -0.4, 0.6, -0.2, 0.9};
  Eigen::Matrix<double, D, D> A;
  for (int a = 0; a < D; ++a) {
    std::string e = "0.1";
    for (int b = 0; b < D; ++b) {
      A(a, b) = entries[3 * a + b];
      e += " + " + std::to_string(A(a, b)) + " * (" + std::string(1, "XYZ"[b]) + " - 0.5)";
    }
    c.bodies[0].velocity.push_back(e);
  }
  Simulation<D> sim(c);
  sim.step(1e-9);
  int checked = 0;
  for (std::size_t p = 0; p < sim.particles().n(); ++p) {
    if ((sim.particles().position[p] - Vec<D>::Constant(0.5)).norm() > 0.3 - 2.5 * 0.05) continue;
    EXPECT_NEAR((sim.wls()->particle_velocity_gradient()[p] - A).norm(), 0.0, 1e-9) << p;
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

TEST(WlsIntegration, ParticleVelocityGradientsReproduceLinearFields) {
  ASSERT_NO_FATAL_FAILURE(check_particle_gradient<2>("quadrature"));
  ASSERT_NO_FATAL_FAILURE(check_particle_gradient<2>("narrow"));
  ASSERT_NO_FATAL_FAILURE(check_particle_gradient<3>("quadrature"));
}

TEST(WlsIntegration, RigidTranslationStaysUndeformed) {
  Config c = wls_config(2, "circle", 0.05);
  c.bodies[0].velocity = {"0.4", "-0.3"};
  c.simulation.end_time = 0.01;
  Simulation<2> sim(c);
  for (int s = 0; s < 20; ++s) sim.step(sim.next_dt());
  const auto& P = sim.particles();
  for (std::size_t p = 0; p < P.n(); ++p) {
    EXPECT_NEAR((P.velocity[p] - Vec<2>(0.4, -0.3)).norm(), 0.0, 1e-12);
    EXPECT_NEAR((P.deformation_gradient[p] - Mat3::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR((P.position[p] - P.reference_position[p] - sim.time() * Vec<2>(0.4, -0.3)).norm(), 0.0, 1e-12);
  }
}

/// One step (dt = 1e-9, no stress) of a WLS disk (h = 0.05) moving with a linear velocity field,
/// plus, by `field`: nothing ("linear"), a smooth wave six cells long in v_x ("wave"), particle-
/// scale noise ("noise"), or instead a translation ("translation"); the RMS deviation of the
/// particles' velocities from the field without the noise, over the particles at least 2.5 h
/// inside, with particle_velocity = `update` and method.order = `order`.
double one_step_velocity_error(const std::string& update, int order, const std::string& field) {
  const double h = 0.05;
  Config c = wls_config(2, "circle", h);
  c.method.plugin.set("particle_velocity", update);
  c.method.order = order;
  std::array<std::string, 2> v = {"0.1 + 0.3 * (X - 0.5) - 0.7 * (Y - 0.5)", "-0.2 + 0.5 * (X - 0.5) + 0.1 * (Y - 0.5)"};
  if (field == "translation") v = {"0.1", "-0.2"};
  if (field == "wave") v[0] += " + 0.05 * sin(20 * X) * cos(20 * Y)";
  if (field == "noise")
    for (std::string& e : v) e += " + 0.01 * sin(1000 * X + 700 * Y)";
  c.bodies[0].velocity = {v[0], v[1]};
  Simulation<2> sim(c);
  sim.step(1e-9);
  const auto& P = sim.particles();
  double sum = 0.0;
  int n = 0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    const Vec<2> x = P.reference_position[p], r = x - Vec<2>::Constant(0.5);
    if (r.norm() > 0.3 - 2.5 * h) continue;
    Vec<2> exact(0.1 + 0.3 * r.x() - 0.7 * r.y(), -0.2 + 0.5 * r.x() + 0.1 * r.y());
    if (field == "translation") exact = Vec<2>(0.1, -0.2);
    if (field == "wave") exact.x() += 0.05 * std::sin(20 * x.x()) * std::cos(20 * x.y());
    sum += (P.velocity[p] - exact).squaredNorm();
    ++n;
  }
  EXPECT_GT(n, 50);
  return std::sqrt(sum / n);
}

// Departure 11 (docs/wls.md): with particle_velocity = "pic" a particle takes the interpolated
// grid velocity, V_p = sum S v+ (seed 002 Eq. 1.66), instead of Eq. 27's increment. One step of
// an unstressed disk moving with a linear field: PIC keeps the linear field exactly (node fits
// and S reproduce it); with particle-scale noise added, FLIP keeps the noise on the particles and
// PIC keeps only what the node fits see of it.
TEST(WlsIntegration, PicParticleVelocityDropsTheNoiseTheGridDoesNotCarry) {
  EXPECT_LT(one_step_velocity_error("pic", 1, "linear"), 1e-9);
  const double flip = one_step_velocity_error("flip", 1, "noise"), pic = one_step_velocity_error("pic", 1, "noise");
  std::printf("particle velocity noise after one step: FLIP %.3e, PIC %.3e (added: 1.0e-02)\n", flip, pic);
  EXPECT_GT(flip, 0.5e-2);
  EXPECT_LT(pic, 0.5 * flip);
}

// Departure 18 (docs/wls.md): particle_velocity = "xpic" with method.order = k starts Eq. 27's
// increment from sum S u_k, u_(j+1) = v + u_j - F(S u_j) (seed 000's XPIC(k) with the node fit F
// for the lumped mass). One step of an unstressed disk: a translation stays exact; a linear field
// changes only by what the reduced fits at the surface feed in; a smooth wave about six cells
// long, which PIC's S F smears, comes back closer with each term; particle-scale noise, which FLIP
// keeps, stays mostly out.
TEST(WlsIntegration, XpicRestoresWhatPicSmearsAndDropsTheNoise) {
  EXPECT_LT(one_step_velocity_error("xpic", 4, "translation"), 1e-14);
  EXPECT_LT(one_step_velocity_error("xpic", 4, "linear"), 1e-5);  // measured 4.4e-7
  const double one = one_step_velocity_error("xpic", 1, "wave"), two = one_step_velocity_error("xpic", 2, "wave");
  const double four = one_step_velocity_error("xpic", 4, "wave");
  const double flip = one_step_velocity_error("flip", 1, "noise"), noise = one_step_velocity_error("xpic", 4, "noise");
  std::printf("XPIC(k): smooth wave (amplitude 5e-2) after one step, k = 1 (PIC) %.3e, 2 %.3e, 4 %.3e; "
              "particle-scale noise (1e-2), k = 4 %.3e (FLIP %.3e)\n",
              one, two, four, noise, flip);
  EXPECT_EQ(one, one_step_velocity_error("pic", 1, "wave"));  // one term is PIC
  EXPECT_LT(two, 0.5 * one);
  EXPECT_LT(four, 0.5 * two);
  EXPECT_LT(noise, 0.5 * flip);
}

// A constant body force (gravity) is fitted per particle, f_p = rho_p b (seed 001 Sec. 4.1): the
// engine keeps no per-particle copy of a constant for the MPM transfer, and the WLS fits once
// read that empty array (a crash or garbage forces; found by the sanitizer runs, issue 36).
TEST(WlsIntegration, ConstantBodyForceAcceleratesTheBody) {
  Config c = wls_config(2, "circle", 0.05);
  c.body_force.expression = {"0.5", "-9.81"};
  c.simulation.end_time = 0.01;
  Simulation<2> sim(c);
  double dt = 0.0;
  for (int s = 0; s < 20; ++s) sim.step(dt = sim.next_dt());
  // Central differences: the particles carry the half-step velocity, g (t - dt/2) (seed 001
  // Sec. 4.7); the time step shrinks a little as the body speeds up, hence the bracket on the
  // body's mean velocity. (That the body stays rigid is the next test.)
  const Vec<2> g(0.5, -9.81);
  const auto& P = sim.particles();
  Vec<2> momentum = Vec<2>::Zero();
  double mass = 0.0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    ASSERT_TRUE(P.velocity[p].allFinite()) << p;
    momentum += P.mass[p] * P.velocity[p];
    mass += P.mass[p];
  }
  const Vec<2> v = momentum / mass;
  EXPECT_NEAR(v.x() * g.y() - v.y() * g.x(), 0.0, 1e-6 * v.norm() * g.norm());  // measured 5e-9
  EXPECT_GE(v.norm(), g.norm() * (sim.time() - dt));
  EXPECT_LE(v.norm(), g.norm() * sim.time());
}

/// Largest |V_p - V_mean| / |V_mean| over every particle (surface particles included) after
/// `steps` steps of a free disk (ball) under the uniform body force g.
template <int D>
double rigid_spread(const std::string& empty_corners, int steps) {
  Config c = wls_config(D, "circle", D == 2 ? 0.05 : 0.1);
  c.body_force.expression = D == 2 ? std::vector<std::string>{"0.5", "-9.81"}
                                   : std::vector<std::string>{"0.5", "-9.81", "0.25"};
  c.simulation.end_time = 1.0;
  c.method.plugin.set("empty_corners", empty_corners);
  Simulation<D> sim(c);
  for (int s = 0; s < steps; ++s) sim.step(sim.next_dt());
  const auto& P = sim.particles();
  Vec<D> momentum = Vec<D>::Zero();
  double mass = 0.0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    momentum += P.mass[p] * P.velocity[p];
    mass += P.mass[p];
  }
  const Vec<D> mean = momentum / mass;
  double spread = 0.0;
  for (std::size_t p = 0; p < P.n(); ++p) spread = std::max(spread, (P.velocity[p] - mean).norm());
  return spread / mean.norm();
}

TEST(WlsIntegration, ConstantBodyForceKeepsTheBodyRigid) {
  // Under a uniform body force every node with mass gets the acceleration g (Eq. 22-23 with one
  // force density per unit mass), and every particle must too: also a particle on or beyond the
  // cut surface whose cell has corners without mass (docs/wls.md, departure 12).
  const double disk = rigid_spread<2>("mean", 20);
  const double ball = rigid_spread<3>("mean", 20);
  std::printf("velocity spread after 20 steps: disk %.2g, ball %.2g; disk with empty_corners = zero %.2g\n", disk,
              ball, rigid_spread<2>("zero", 20));
  EXPECT_LT(disk, 1e-12);
  EXPECT_LT(ball, 1e-12);
  // As printed, the massless corners take part of the surface particles' acceleration (measured
  // 1.7e-3 after 20 steps): the test above can fail.
  EXPECT_GT(rigid_spread<2>("zero", 20), 1e-5);
}

TEST(WlsIntegration, AccelerationFilterPassesLinearFieldsAndDampsZigZag) {
  // method.filter_acceleration: the planar fit over a node and its neighbours with mass returns a
  // linear increment field unchanged at every node with mass (also at the surface, where the
  // neighbourhood is one-sided) and removes most of a node-to-node zig-zag.
  Simulation<2> sim(wls_config(2, "circle", 0.05));
  const auto& grid = sim.grid();
  wls::Integrator<2> filter(grid, wls::Options{});
  NodeField<2> nodes = sim.nodes();
  const Vec<2> c0(0.3, -0.2);
  Eigen::Matrix2d A;
  A << 0.7, -0.4, 0.2, 1.1;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    nodes.velocity[i] = Vec<2>(0.05 * i, -0.01 * i);  // any v: the filter acts on v+ - v
    nodes.velocity_new[i] = nodes.velocity[i] + c0 + A * grid.node_position(i);
  }
  filter.filter_acceleration(grid, nodes);
  int with_mass = 0;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    if (!(nodes.mass[i] > 0.0)) continue;
    ++with_mass;
    EXPECT_NEAR((nodes.velocity_new[i] - nodes.velocity[i] - c0 - A * grid.node_position(i)).norm(), 0.0, 1e-12) << i;
  }
  EXPECT_GT(with_mass, 100);
  double before = 0.0, after = 0.0;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    const IVec<2> j = grid.multi_index(i);
    nodes.velocity[i] = Vec<2>::Zero();
    nodes.velocity_new[i] = Vec<2>((j[0] + j[1]) % 2 ? 1.0 : -1.0, 0.0);
  }
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i)
    if (nodes.mass[i] > 0.0 && sim.wls()->well_conditioned()[i]) before = std::max(before, nodes.velocity_new[i].norm());
  filter.filter_acceleration(grid, nodes);
  // Where the node and its 8 neighbours carry the same mass the fit is the W-weighted mean over
  // the symmetric stencil: 0.75^2 - 4 (0.75 0.125) + 4 0.125^2 = 0.25 of the zig-zag.
  int uniform = 0;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    if (!(nodes.mass[i] > 0.0)) continue;
    const IVec<2> j = grid.multi_index(i);
    bool same = true;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy) {
        const std::int32_t nb = grid.node_index(IVec<2>(j[0] + dx, j[1] + dy));
        same = same && nb >= 0 && std::abs(nodes.mass[nb] - nodes.mass[i]) <= 1e-12 * nodes.mass[i];
      }
    if (!same) continue;
    ++uniform;
    after = std::max(after, nodes.velocity_new[i].norm());
    EXPECT_NEAR(nodes.velocity_new[i].norm(), 0.25, 1e-12) << i;
  }
  EXPECT_EQ(before, 1.0);
  EXPECT_GT(uniform, 20);
  EXPECT_LT(after, 0.25 + 1e-12);
}

/// What method.hourglass_damping does to three grid velocities (docs/wls.md, departure 13).
struct HourglassMeasure {
  int with_mass = 0;                  ///< nodes with mass
  double linear_change = 0.0;         ///< largest change of a linear field at a node with mass
  double momentum_change = 0.0;       ///< |change of sum m v| / sum m |v| for an arbitrary field
  double checkerboard_error = 0.0;    ///< largest |v_after - (1 - kappa) v_before| of a checkerboard
  int uniform_nodes = 1 << 30;        ///< fewest nodes of one mass block, over the patterns
};

template <int D>
HourglassMeasure measure_hourglass_damping(double kappa) {
  // A linear grid velocity (rigid motion, uniform strain rate), an arbitrary one (momentum), and a
  // node-scale checkerboard of each corner pattern, measured at nodes whose 3^D block carries one
  // mass.
  Simulation<D> sim(wls_config(D, "circle", 0.05));
  const auto& grid = sim.grid();
  wls::Options o;
  o.hourglass_damping = kappa;
  wls::Integrator<D> damper(grid, o);
  NodeField<D> nodes = sim.nodes();
  HourglassMeasure out;
  Vec<D> c0;
  Eigen::Matrix<double, D, D> A;
  for (int a = 0; a < D; ++a) {
    c0[a] = 0.3 - 0.2 * a;
    for (int b = 0; b < D; ++b) A(a, b) = 0.7 * (a == b) + 0.4 * (b - a) + 0.1 * a * b;  // rotation + strain
  }
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) nodes.velocity_new[i] = c0 + A * grid.node_position(i);
  damper.damp_hourglass(grid, nodes);
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    if (!(nodes.mass[i] > 0.0)) continue;
    ++out.with_mass;
    out.linear_change = std::max(out.linear_change, (nodes.velocity_new[i] - c0 - A * grid.node_position(i)).norm());
  }
  Vec<D> before = Vec<D>::Zero(), after = Vec<D>::Zero();
  double scale = 0.0;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    for (int a = 0; a < D; ++a) nodes.velocity_new[i][a] = std::sin(1.7 * i + a) + 0.3 * std::cos(0.37 * i * i);
    before += nodes.mass[i] * nodes.velocity_new[i];
    scale += nodes.mass[i] * nodes.velocity_new[i].norm();
  }
  damper.damp_hourglass(grid, nodes);
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) after += nodes.mass[i] * nodes.velocity_new[i];
  out.momentum_change = (after - before).norm() / scale;
  // Checkerboards: (-1)^(sum of the pattern's axes' node indices), one per axis set of two or more.
  for (int axes = 3; axes < (1 << D); ++axes) {
    if (std::popcount(static_cast<unsigned>(axes)) < 2) continue;
    const auto sign = [&](std::int32_t i) {
      const IVec<D> j = grid.multi_index(i);
      int sum = 0;
      for (int a = 0; a < D; ++a)
        if ((axes >> a) & 1) sum += j[a];
      return sum % 2 ? -1.0 : 1.0;
    };
    for (std::int32_t i = 0; i < grid.n_nodes(); ++i) nodes.velocity_new[i] = Vec<D>::Constant(sign(i));
    damper.damp_hourglass(grid, nodes);
    int uniform = 0;
    for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
      if (!(nodes.mass[i] > 0.0)) continue;
      bool same = true;
      wls::detail::for_each_neighbour(grid, i, [&](std::int32_t nb, const Vec<D>&) {
        same = same && std::abs(nodes.mass[nb] - nodes.mass[i]) <= 1e-12 * nodes.mass[i];
      });
      if (!same) continue;
      ++uniform;
      out.checkerboard_error = std::max(
          out.checkerboard_error, (nodes.velocity_new[i] - (1.0 - kappa) * Vec<D>::Constant(sign(i))).norm());
    }
    out.uniform_nodes = std::min(out.uniform_nodes, uniform);
  }
  return out;
}

TEST(WlsIntegration, HourglassDampingKeepsLinearFieldsAndMomentumAndDampsCheckerboards) {
  // method.hourglass_damping (docs/wls.md, departure 13): linear fields pass unchanged, momentum
  // is kept, and a checkerboard of each corner pattern loses the fraction kappa per step.
  for (const HourglassMeasure& m : {measure_hourglass_damping<2>(0.3), measure_hourglass_damping<3>(0.3)}) {
    EXPECT_GT(m.with_mass, 50);
    EXPECT_LT(m.linear_change, 1e-12);
    EXPECT_LT(m.momentum_change, 1e-13);
    EXPECT_LT(m.checkerboard_error, 1e-12);
    EXPECT_GT(m.uniform_nodes, 4);
  }
}

TEST(WlsIntegration, UniformStressGivesNoInteriorForce) {
  // A uniformly stretched box: the internal force of every node whose cells are all full
  // vanishes (the stress divergence is zero); the boundary nodes carry the traction.
  Config c = wls_config(2, "box", 0.1);
  c.bodies[0].displacement = {"0.01 * X", "-0.02 * Y"};
  Simulation<2> sim(c);
  const auto& nodes = sim.nodes();
  const auto& grid = sim.grid();
  std::vector<double> cell_volume(100, 0.0);  // 10 x 10 cells
  for (const auto& q : sim.wls()->regions()) cell_volume[q.cell] += q.volume;
  double interior = 0.0, boundary = 0.0;
  int n_interior = 0;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    const IVec<2> j = grid.multi_index(i);
    bool inner = j.minCoeff() >= 1 && j.maxCoeff() <= 9;
    for (int k = 0; k < 4 && inner; ++k)
      inner = cell_volume[(j[0] - (k & 1)) + 10 * (j[1] - (k >> 1))] > 0.01 * (1 - 1e-12);
    if (inner) {
      interior = std::max(interior, nodes.force[i].norm());
      ++n_interior;
    } else {
      boundary = std::max(boundary, nodes.force[i].norm());
    }
  }
  EXPECT_GE(n_interior, 2);
  EXPECT_GT(boundary, 1.0);
  EXPECT_LT(interior, 1e-9 * boundary);
}

TEST(WlsIntegration, RejectsFeaturesItDoesNotDefine) {
  // ([contact] works under WLS: test_wls_contact.cpp.)
  Config hot = wls_config(2, "circle", 0.05);
  hot.thermal.conduction = true;
  EXPECT_THROW(Simulation<2>{hot}, std::invalid_argument);
  Config one = test::box_config(1, "linear");
  one.method.integration = "wls";
  EXPECT_THROW(Simulation<1>{one}, std::invalid_argument);
}

}  // namespace
}  // namespace cairn
