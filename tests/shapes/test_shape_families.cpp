// Property tests every shape family must pass: partition of unity, zero gradient sum and exact
// reproduction of linear fields (value and gradient), in 1D, 2D and 3D, at random points across
// the whole domain including the cells next to each face and next to periodic seams, for
// undeformed particles and for sheared and stretched ones (deformation gradient F). Then the
// family-specific definitions: GIMP weights are the exact box integrals of seed 000 Sec. 2.1,
// CPDI weights the exact integrals of its bracketed (corner-interpolated) form, open-knot
// splines are 1 on the faces, the CPDI guard falls back to GIMP, and the colouring reach covers
// every stencil node.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <random>

#include "../support/config_builder.hpp"
#include "cairn/shapes/grid_functions.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/input/names.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/failure.hpp"

namespace cairn {
namespace {

template <int D>
std::unique_ptr<ShapeFamily<D>> family(const std::string& name, double smoothing_length = 0.0) {
  Config cfg = test::box_config(D, name);
  cfg.method.plugin.set("smoothing_length", smoothing_length);
  return make_shape_family<D>(ShapeContext{cfg.method, D});
}

/// A deformation gradient I + A with random entries of A in [-amp, amp] (top-left D x D).
template <int D>
Mat3 random_F(std::mt19937& rng, double amp) {
  std::uniform_real_distribution<double> u(-amp, amp);
  Mat3 F = Mat3::Identity();
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) F(a, b) += u(rng);
  return F;
}

/// Stencil of particle p as {dof position, S, G} over its slots.
template <int D>
struct Entry {
  Vec<D> x;
  std::int32_t node;
  double S;
  Vec<D> G;
};
template <int D>
std::vector<Entry<D>> stencil(const ShapeFamily<D>& fam, const Grid<D>& grid,
                              const TransferCache<D>& c, std::size_t p) {
  std::vector<Entry<D>> out;
  for (const auto& e : stencil_entries(c, p))
    out.push_back({fam.dof_position(grid, e.node), e.node, e.weight, e.gradient});
  return out;
}

template <int D>
void check_family(const std::string& name, bool periodic, double deform) {
  auto fam = family<D>(name);
  std::array<bool, D> per{};
  per.fill(periodic);
  const Grid<D> grid(Vec<D>::Zero(), IVec<D>::Constant(10), Vec<D>::Constant(0.1),
                     fam->ghost_layers(), per);
  Particles<D> parts;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 300; ++k) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = u(rng);
    if (k < 2 * D) x[k / 2] = (k % 2) ? 0.999 : 0.001;  // right next to each face
    if (k >= 2 * D && k < 4 * D) x[(k - 2 * D) / 2] = (k % 2) ? 1.0 : 0.0;  // on each face
    parts.add(x, Vec<D>::Zero(), 1.0, 1e-3, Vec<D>::Constant(0.05), 0, 0);
    if (deform > 0.0) parts.deformation_gradient.back() = random_F<D>(rng, deform);
  }
  TransferCache<D> cache;
  fam->build(grid, parts, cache);
  const Vec<D> slope = Vec<D>::LinSpaced(1.0, 2.0);
  const std::string what = name + " D=" + std::to_string(D) + (periodic ? " periodic" : "") +
                           (deform > 0.0 ? " deformed" : "");
  for (std::size_t p = 0; p < parts.n(); ++p) {
    double sum = 0.0, lin = 0.0;
    Vec<D> grad_sum = Vec<D>::Zero(), lin_grad = Vec<D>::Zero();
    for (const auto& e : stencil(*fam, grid, cache, p)) {
      sum += e.S;
      grad_sum += e.G;
      lin += e.S * slope.dot(e.x);
      lin_grad += slope.dot(e.x) * e.G;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << what << " p=" << p;
    EXPECT_LT(grad_sum.norm(), 1e-9) << what << " p=" << p;
    if (!periodic) {  // a periodic wrap maps nodes onto the other side: no linear reproduction
      EXPECT_NEAR(lin, slope.dot(parts.position[p]), 1e-12) << what << " p=" << p;
      EXPECT_LT((lin_grad - slope).norm(), 1e-9) << what << " p=" << p;
    }
    // The colouring reach must cover every node of the stencil (or P2G would race).
    if (!periodic)
      for_each_entry(cache, p, [&, cell = grid.cell_of(parts.position[p])](std::int32_t node, double, const Vec<D>&) {
        const IVec<D> j = grid.multi_index(node);
        for (int a = 0; a < D; ++a) {
          EXPECT_GE(j[a], cell[a] - cache.reach_lo[a]) << what << " p=" << p;
          EXPECT_LE(j[a], cell[a] + 1 + cache.reach_hi[a]) << what << " p=" << p;
        }
      });
  }
}

TEST(ShapeFamilies, EveryRegisteredFamilyIsAPartitionOfUnityAndReproducesLinearFields) {
  const auto names = shape_family_names();
  ASSERT_GE(names.size(), 11u);
  for (const auto& name : names) {
    for (bool periodic : {false, true}) {
      for (double deform : {0.0, 0.3}) {  // undeformed; sheared and stretched by up to 30 %
        check_family<1>(name, periodic, deform);
        check_family<2>(name, periodic, deform);
        check_family<3>(name, periodic, deform);
      }
    }
  }
}

TEST(ShapeFamilies, AllFamiliesOfTheIssueAreRegistered) {
  const auto names = shape_family_names();
  for (const char* n : {"linear", "ugimp", "gimp", "cpgimp", "bspline2", "bspline3",
                        "bspline2_open", "bspline3_open", "cpdi", "b2gimp", "b2cpdi"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

/// Map of node -> (S, G) of one particle.
template <int D>
std::map<std::int32_t, std::pair<double, Vec<D>>> weights_of(const TransferCache<D>& c, std::size_t p) {
  std::map<std::int32_t, std::pair<double, Vec<D>>> out;
  for (const auto& e : stencil_entries(c, p)) out[e.node] = {e.weight, e.gradient};
  return out;
}

template <int D>
void expect_same_weights(const TransferCache<D>& a, const TransferCache<D>& b, std::size_t p,
                         double tol, const std::string& what) {
  auto wa = weights_of(a, p), wb = weights_of(b, p);
  for (const auto& [node, sg] : wb) {
    if (sg.first == 0.0 && sg.second.isZero(0.0)) continue;
    ASSERT_TRUE(wa.count(node)) << what << " node " << node;
    EXPECT_NEAR(wa[node].first, sg.first, tol) << what << " node " << node;
    EXPECT_LT((wa[node].second - sg.second).norm(), tol * 10.0) << what << " node " << node;
  }
  for (const auto& [node, sg] : wa)
    if (!wb.count(node)) {
      EXPECT_LT(std::abs(sg.first) + sg.second.norm(), tol) << what;
    }
}

TEST(ShapeFamilies, UGimpWithSmoothingLengthHEqualsTheQuadraticSpline) {
  auto gimp = family<1>("ugimp", 0.1);  // l = h (seed 003 Sec. 4.1)
  auto spline = family<1>("bspline2");
  const Grid<1> grid(Vec<1>::Zero(), IVec<1>::Constant(10), Vec<1>::Constant(0.1), 2, {false});
  Particles<1> parts;
  for (double x : {0.123, 0.25, 0.5, 0.777, 0.9501})
    parts.add(Vec<1>::Constant(x), Vec<1>::Zero(), 1.0, 1.0, Vec<1>::Constant(0.05), 0, 0);
  TransferCache<1> c1, c2;
  gimp->build(grid, parts, c1);
  spline->build(grid, parts, c2);
  for (std::size_t p = 0; p < parts.n(); ++p) expect_same_weights(c1, c2, p, 1e-14, "ugimp l=h");
}

TEST(ShapeFamilies, UGimpWithVanishingSmoothingLengthIsLinear) {
  auto gimp = family<2>("ugimp", 1e-14);
  auto lin = family<2>("linear");
  const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1), 2, {false, false});
  Particles<2> parts;
  for (double x : {0.123, 0.25, 0.5, 0.777})
    parts.add(Vec<2>(x, 1.0 - x * 0.7), Vec<2>::Zero(), 1.0, 1.0, Vec<2>::Constant(0.05), 0, 0);
  TransferCache<2> c1, c2;
  gimp->build(grid, parts, c1);
  lin->build(grid, parts, c2);
  for (std::size_t p = 0; p < parts.n(); ++p) expect_same_weights(c1, c2, p, 1e-12, "ugimp l->0");
}

/// Midpoint quadrature of f over the axis-aligned box centre x, edges len (n points per axis).
template <int D>
double box_average(const Vec<D>& x, const Vec<D>& len, int n, const std::function<double(const Vec<D>&)>& f) {
  double sum = 0.0;
  int total = 1;
  for (int a = 0; a < D; ++a) total *= n;
  for (int k = 0; k < total; ++k) {
    int rem = k;
    Vec<D> y;
    for (int a = 0; a < D; ++a) {
      y[a] = x[a] - 0.5 * len[a] + (rem % n + 0.5) * len[a] / n;
      rem /= n;
    }
    sum += f(y);
  }
  return sum / total;
}

/// GIMP weights are the exact integrals over the particle box, seed 000 Sec. 2.1:
/// S = (1/V) int N_i (checked by quadrature), and G = (1/V) int grad N_i = dS/dx_p for a box that
/// moves with the particle (checked by central differences of S). `box` is the box edge lengths.
template <int D>
::testing::AssertionResult box_integrals_match(const std::string& name, double (*N)(double), const Mat3& F,
                                               const Vec<D>& box, double smoothing = 0.0) {
  auto fam = family<D>(name, smoothing);
  const double h = 0.1;
  const Grid<D> grid(Vec<D>::Zero(), IVec<D>::Constant(10), Vec<D>::Constant(h), fam->ghost_layers(),
                     std::array<bool, D>{});
  Vec<D> x;
  for (int a = 0; a < D; ++a) x[a] = 0.4321 + 0.0917 * a;
  const double delta = 1e-7;
  Particles<D> parts;  // particle 0 at x, then pairs shifted by +-delta along each axis
  parts.add(x, Vec<D>::Zero(), 1.0, 1.0, Vec<D>::Constant(0.07), 0, 0);
  for (int b = 0; b < D; ++b)
    for (double sign : {1.0, -1.0}) {
      Vec<D> y = x;
      y[b] += sign * delta;
      parts.add(y, Vec<D>::Zero(), 1.0, 1.0, Vec<D>::Constant(0.07), 0, 0);
    }
  for (auto& Fp : parts.deformation_gradient) Fp = F;
  TransferCache<D> c;
  fam->build(grid, parts, c);
  const int n = D == 1 ? 20000 : D == 2 ? 400 : 40;
  const double tol = D == 1 ? 1e-8 : D == 2 ? 1e-5 : 1e-3;
  std::vector<std::map<std::int32_t, std::pair<double, Vec<D>>>> w;
  for (std::size_t p = 0; p < parts.n(); ++p) w.push_back(weights_of(c, p));
  double worst_S = 0.0, worst_G = 0.0;  // errors relative to their tolerances
  for (const auto& [node, sg] : w[0]) {
    const Vec<D> xi = grid.node_position(node);
    auto Ni = [&](const Vec<D>& y) {
      double v = 1.0;
      for (int a = 0; a < D; ++a) v *= N((y[a] - xi[a]) / h);
      return v;
    };
    worst_S = std::max(worst_S, std::abs(sg.first - box_average<D>(x, box, n, Ni)) / tol);
    for (int b = 0; b < D; ++b) {
      const double dS = (w[1 + 2 * b][node].first - w[2 + 2 * b][node].first) / (2.0 * delta);
      worst_G = std::max(worst_G, std::abs(sg.second[b] - dS) / (1e-4 * (1.0 + std::abs(dS))));
    }
  }
  if (!w[0].empty() && worst_S <= 1.0 && worst_G <= 1.0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << name << " D=" << D << ": " << w[0].size()
                                       << " nodes, worst weight error " << worst_S
                                       << " tolerances, worst gradient error " << worst_G << " tolerances";
}

TEST(ShapeFamilies, GimpWeightsAreTheExactIntegralsOverTheParticleBox) {
  const Mat3 I = Mat3::Identity();
  Mat3 F = I;
  F(0, 0) = 1.3;
  F(1, 1) = 0.8;
  F(0, 1) = 0.2;  // off-diagonal terms do not change the cpGIMP box
  EXPECT_TRUE(box_integrals_match<1>("gimp", hat, I, Vec<1>::Constant(0.07)));
  EXPECT_TRUE(box_integrals_match<2>("gimp", hat, I, Vec<2>::Constant(0.07)));
  EXPECT_TRUE(box_integrals_match<3>("gimp", hat, I, Vec<3>::Constant(0.07)));
  EXPECT_TRUE(box_integrals_match<1>("ugimp", hat, I, Vec<1>::Constant(0.13), 0.13));
  EXPECT_TRUE(box_integrals_match<2>("ugimp", hat, I, Vec<2>::Constant(0.03), 0.03));
  EXPECT_TRUE(box_integrals_match<1>("cpgimp", hat, F, Vec<1>::Constant(0.07 * 1.3)));
  EXPECT_TRUE(box_integrals_match<2>("cpgimp", hat, F, Vec<2>(0.07 * 1.3, 0.07 * 0.8)));
  EXPECT_TRUE(box_integrals_match<1>("b2gimp", quadratic_spline, I, Vec<1>::Constant(0.07)));
  EXPECT_TRUE(box_integrals_match<2>("b2gimp", quadratic_spline, I, Vec<2>::Constant(0.07)));
  EXPECT_TRUE(box_integrals_match<3>("b2gimp", quadratic_spline, I, Vec<3>::Constant(0.07)));
}

/// CPDI weights are the exact integrals of the bracketed forms of seed 000 Sec. 2.1 over the
/// convected domain: S = (1/V) int sum_c M_c(x) N_i(x_c) dx, G = (1/V) int sum_c grad M_c(x)
/// N_i(x_c) dx, with M_c the multilinear functions of the domain mapped from [-1, 1]^D. The
/// quadrature walks the domain through that map (constant Jacobian), with grad M_c from the
/// chain rule, independently of the closed form in shapes/cpdi.hpp.
template <int D>
::testing::AssertionResult cpdi_integrals_match(const std::string& name, double (*N)(double), const Mat3& F3,
                                                const Vec<D>& x, double size) {
  auto fam = family<D>(name);
  const double h = 0.1;
  const Grid<D> grid(Vec<D>::Zero(), IVec<D>::Constant(10), Vec<D>::Constant(h), fam->ghost_layers(),
                     std::array<bool, D>{});
  Particles<D> parts;
  parts.add(x, Vec<D>::Zero(), 1.0, 1.0, Vec<D>::Constant(size), 0, 0);
  parts.deformation_gradient[0] = F3;
  TransferCache<D> c;
  fam->build(grid, parts, c);
  using MatD = Eigen::Matrix<double, D, D>;
  const MatD R = F3.template topLeftCorner<D, D>() * (0.5 * size);
  const MatD RinvT = R.inverse().transpose();
  constexpr int n_corners = 1 << D;
  const int n = D == 1 ? 2000 : D == 2 ? 60 : 16;
  int total = 1;
  for (int a = 0; a < D; ++a) total *= n;
  double worst_S = 0.0, worst_G = 0.0;
  const auto entries = stencil_entries(c, 0);
  for (const auto& e : entries) {
    const Vec<D> xi = grid.node_position(e.node);
    std::array<double, n_corners> Nc;
    for (int k = 0; k < n_corners; ++k) {
      Vec<D> sgn;
      for (int a = 0; a < D; ++a) sgn[a] = (k >> a) & 1 ? 1.0 : -1.0;
      const Vec<D> xc = x + R * sgn;
      double v = 1.0;
      for (int a = 0; a < D; ++a) v *= N((xc[a] - xi[a]) / h);
      Nc[k] = v;
    }
    double S = 0.0;
    Vec<D> G = Vec<D>::Zero();
    for (int q = 0; q < total; ++q) {  // midpoint rule over the reference cube
      int rem = q;
      Vec<D> ref;
      for (int a = 0; a < D; ++a) {
        ref[a] = -1.0 + (rem % n + 0.5) * 2.0 / n;
        rem /= n;
      }
      for (int k = 0; k < n_corners; ++k) {
        double M = 1.0;
        Vec<D> dM = Vec<D>::Ones();
        for (int a = 0; a < D; ++a) {
          const double sa = (k >> a) & 1 ? 1.0 : -1.0;
          const double fa = 0.5 * (1.0 + sa * ref[a]);
          M *= fa;
          for (int b = 0; b < D; ++b) dM[b] *= a == b ? 0.5 * sa : fa;
        }
        S += M * Nc[k] / total;
        G += (RinvT * dM) * Nc[k] / total;
      }
    }
    worst_S = std::max(worst_S, std::abs(e.weight - S));
    worst_G = std::max(worst_G, (e.gradient - G).norm());
  }
  if (!entries.empty() && worst_S <= 1e-12 && worst_G < 1e-9) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << name << " D=" << D << ": " << entries.size() << " nodes, worst |dS| "
                                       << worst_S << " (1e-12 allowed), worst |dG| " << worst_G << " (1e-9)";
}

TEST(ShapeFamilies, CpdiWeightsAreTheExactIntegralsOfTheCornerInterpolation) {
  Mat3 shear = Mat3::Identity();
  shear(0, 1) = 0.6;  // simple shear
  shear(1, 1) = 1.4;  // and stretch
  shear(1, 0) = -0.2;
  shear(2, 2) = 0.7;
  shear(2, 0) = 0.3;
  // The identity keeps the domain inside the fixed (n_nodes + 1)^D node box of the fast path;
  // the stretched shear spans more than one cell along x, so it takes the general box.
  Mat3 stretched = shear;
  stretched(0, 0) = 2.0;  // span 1.82 cells, inside the default guard cpdi_max_span = 2
  for (const char* name : {"cpdi", "b2cpdi"}) {
    double (*N)(double) = std::string(name) == "cpdi" ? hat : quadratic_spline;
    for (const Mat3& F : {Mat3(Mat3::Identity()), shear, stretched}) {
      EXPECT_TRUE(cpdi_integrals_match<1>(name, N, F, Vec<1>(0.4321), 0.07));
      EXPECT_TRUE(cpdi_integrals_match<2>(name, N, F, Vec<2>(0.4321, 0.5917), 0.07));
      EXPECT_TRUE(cpdi_integrals_match<3>(name, N, F, Vec<3>(0.4321, 0.5917, 0.3333), 0.07));
    }
  }
}

TEST(ShapeFamilies, UndeformedCpdiInsideOneCellEqualsGimp) {
  // N_i is multilinear inside a cell, so interpolating it from the corners is exact: CPDI gives
  // the exact GIMP integral when the undeformed domain holds no node line.
  auto cpdi = family<2>("cpdi");
  auto gimp = family<2>("gimp");
  const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1), 2, {false, false});
  Particles<2> parts;
  parts.add(Vec<2>(0.425, 0.575), Vec<2>::Zero(), 1.0, 1.0, Vec<2>::Constant(0.05), 0, 0);
  parts.add(Vec<2>(0.44, 0.53), Vec<2>::Zero(), 1.0, 1.0, Vec<2>::Constant(0.05), 0, 0);
  TransferCache<2> c1, c2;
  cpdi->build(grid, parts, c1);
  gimp->build(grid, parts, c2);
  for (std::size_t p = 0; p < parts.n(); ++p) expect_same_weights(c1, c2, p, 1e-13, "cpdi = gimp");
}

TEST(ShapeFamilies, CpdiOfAVanishingDomainIsItsGridFunction) {
  for (const auto& [cpdi_name, grid_name] :
       {std::pair<std::string, std::string>{"cpdi", "linear"}, {"b2cpdi", "bspline2"}}) {
    auto cpdi = family<3>(cpdi_name);
    auto base = family<3>(grid_name);
    const Grid<3> grid(Vec<3>::Zero(), IVec<3>::Constant(10), Vec<3>::Constant(0.1), 3, {});
    Particles<3> parts;
    parts.add(Vec<3>(0.4321, 0.5917, 0.3333), Vec<3>::Zero(), 1, 1, Vec<3>::Constant(1e-9), 0, 0);
    TransferCache<3> c1, c2;
    cpdi->build(grid, parts, c1);
    base->build(grid, parts, c2);
    expect_same_weights(c1, c2, 0, 1e-7, cpdi_name);
  }
}

TEST(ShapeFamilies, CpGimpBoxFollowsTheDiagonalOfF) {
  auto cp = family<2>("cpgimp");
  auto gimp = family<2>("gimp");
  const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1), 2, {false, false});
  Particles<2> a, b;
  Mat3 F = Mat3::Identity();
  F(0, 0) = 1.5;
  F(1, 1) = 0.6;
  F(0, 1) = 0.4;
  a.add(Vec<2>(0.43, 0.51), Vec<2>::Zero(), 1, 1, Vec<2>::Constant(0.05), 0, 0);
  a.deformation_gradient[0] = F;
  b.add(Vec<2>(0.43, 0.51), Vec<2>::Zero(), 1, 1, Vec<2>(0.075, 0.03), 0, 0);
  TransferCache<2> c1, c2;
  cp->build(grid, a, c1);
  gimp->build(grid, b, c2);
  expect_same_weights(c1, c2, 0, 1e-14, "cpgimp");
}

TEST(ShapeFamilies, CpdiGuardFallsBackToGimpOfTheUndeformedBox) {
  // Stretched 8x along x: the domain spans 0.05 * 8 / 0.1 = 4 cells > cpdi_max_span = 2.
  for (const auto& [cpdi_name, gimp_name] :
       {std::pair<std::string, std::string>{"cpdi", "gimp"}, {"b2cpdi", "b2gimp"}}) {
    auto cpdi = family<2>(cpdi_name);
    auto gimp = family<2>(gimp_name);
    const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1), 3, {false, false});
    Particles<2> parts;
    parts.add(Vec<2>(0.43, 0.51), Vec<2>::Zero(), 1, 1, Vec<2>::Constant(0.05), 0, 0);
    parts.add(Vec<2>(0.43, 0.51), Vec<2>::Zero(), 1, 1, Vec<2>::Constant(0.05), 0, 0);
    parts.deformation_gradient[0](0, 0) = 8.0;
    parts.deformation_gradient[1](0, 0) = 3.9;  // spans 1.95 cells: still CPDI
    TransferCache<2> c1, c2;
    cpdi->build(grid, parts, c1);
    gimp->build(grid, parts, c2);
    expect_same_weights(c1, c2, 0, 1e-14, cpdi_name + " guard");
    EXPECT_GT(weights_of(c1, 1).size(), weights_of(c2, 1).size()) << cpdi_name << " below the guard";
    // An inverted domain (det F < 0) also falls back instead of producing negative weights.
    parts.deformation_gradient[0] = Mat3::Identity();
    parts.deformation_gradient[0](1, 1) = -0.5;
    cpdi->build(grid, parts, c1);
    gimp->build(grid, parts, c2);
    expect_same_weights(c1, c2, 0, 1e-14, cpdi_name + " inverted");
  }
}

TEST(ShapeFamilies, OpenKnotSplinesAreOneOnTheFacesAndHaveNPlusPFunctions) {
  for (const auto& [name, degree] : {std::pair<std::string, int>{"bspline2_open", 2}, {"bspline3_open", 3}}) {
    auto fam = family<1>(name);
    EXPECT_EQ(fam->face_basis(), FaceBasis::open_knot);
    const int n = 6;
    const Grid<1> grid(Vec<1>::Zero(), IVec<1>::Constant(n), Vec<1>::Constant(0.1), fam->ghost_layers(), {false});
    Particles<1> parts;
    const int samples = 601;
    for (int k = 0; k < samples; ++k)
      parts.add(Vec<1>::Constant(0.6 * k / (samples - 1)), Vec<1>::Zero(), 1, 1, Vec<1>::Constant(0.05), 0, 0);
    TransferCache<1> c;
    fam->build(grid, parts, c);
    std::map<std::int32_t, double> max_weight;
    for (std::size_t p = 0; p < parts.n(); ++p)
      for (const auto& [node, sg] : weights_of(c, p)) max_weight[node] = std::max(max_weight[node], sg.first);
    EXPECT_EQ(static_cast<int>(max_weight.size()), n + degree) << name;
    // On the faces the face function is 1 and all others vanish.
    const std::int32_t lower = grid.node_index(IVec<1>::Constant(0));
    const std::int32_t upper = grid.node_index(IVec<1>::Constant(n));
    auto w0 = weights_of(c, 0), w1 = weights_of(c, samples - 1);
    EXPECT_NEAR(w0[lower].first, 1.0, 1e-13) << name;
    EXPECT_NEAR(w1[upper].first, 1.0, 1e-13) << name;  // x = 0.6 is 6 cells up to rounding
    for (const auto& [node, sg] : w0)
      if (node != lower) {
        EXPECT_NEAR(sg.first, 0.0, 1e-13) << name;
      }
    for (const auto& [node, sg] : w1)
      if (node != upper) {
        EXPECT_NEAR(sg.first, 0.0, 1e-13) << name;
      }
    // Mirror symmetry of the basis about the middle of the domain.
    for (int k = 0; k < samples; ++k) {
      double s_lower_k = weights_of(c, k)[lower].first;
      double s_upper_mirror = weights_of(c, samples - 1 - k)[upper].first;
      EXPECT_NEAR(s_lower_k, s_upper_mirror, 1e-12) << name;
    }
    // Away from the faces the functions are the uniform B-splines: with knots at the nodes the
    // cubic ones are centred on nodes (as bspline3), the quadratic ones on cell midpoints (as
    // bspline2 half a cell away).
    auto uniform = family<1>(degree == 2 ? "bspline2" : "bspline3");
    const Grid<1> g2(Vec<1>::Zero(), IVec<1>::Constant(n), Vec<1>::Constant(0.1), 3, {false});
    Particles<1> mid, shifted;
    mid.add(Vec<1>::Constant(0.3137), Vec<1>::Zero(), 1, 1, Vec<1>::Constant(0.05), 0, 0);
    shifted.add(Vec<1>::Constant(degree == 2 ? 0.3637 : 0.3137), Vec<1>::Zero(), 1, 1,
                Vec<1>::Constant(0.05), 0, 0);
    TransferCache<1> c1, c2;
    fam->build(grid, mid, c1);
    uniform->build(g2, shifted, c2);
    std::vector<double> a, b;
    for (const auto& [node, sg] : weights_of(c1, 0)) a.push_back(sg.first);
    for (const auto& [node, sg] : weights_of(c2, 0)) b.push_back(sg.first);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-13) << name;
  }
}

TEST(ShapeFamilies, UGimpWeightIsTheExactIntegralOfTheHatOverTheParticle) {
  // seed 000 Sec. 2.1: S_pi = (1/V_p) int_{V_p} N_i dx. Compare with a fine midpoint quadrature.
  auto gimp = family<1>("ugimp");
  const Grid<1> grid(Vec<1>::Zero(), IVec<1>::Constant(10), Vec<1>::Constant(0.1), 2, {false});
  Particles<1> parts;
  parts.add(Vec<1>::Constant(0.4321), Vec<1>::Zero(), 1.0, 1.0, Vec<1>::Constant(0.07), 0, 0);
  TransferCache<1> c;
  gimp->build(grid, parts, c);
  for (const auto& e : stencil_entries(c, 0)) {
    const double xi = grid.node_position(e.node)[0];
    const int n = 20000;
    double integral = 0.0;
    for (int k = 0; k < n; ++k) {
      const double x = 0.4321 - 0.035 + (k + 0.5) * 0.07 / n;
      integral += std::max(0.0, 1.0 - std::abs(x - xi) / 0.1) / n;
    }
    EXPECT_NEAR(e.weight, integral, 1e-8);
  }
}

TEST(ShapeFamilies, ParticleOutsideTheGridIsReported) {
  for (const char* name : {"linear", "cpdi", "bspline2_open", "bspline3_open", "b2cpdi"}) {
    auto fam = family<2>(name);
    const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1),
                       fam->ghost_layers(), {false, false});
    Particles<2> parts;
    parts.add(Vec<2>(0.5, 0.5), Vec<2>::Zero(), 1, 1, Vec<2>::Constant(0.05), 0, 0);
    parts.add(Vec<2>(1.35, 0.5), Vec<2>::Zero(), 1, 1, Vec<2>::Constant(0.05), 0, 0);
    TransferCache<2> c;
    try {
      fam->build(grid, parts, c);
      FAIL() << name << ": expected a SimulationFailure";
    } catch (const SimulationFailure& f) {
      EXPECT_EQ(f.particle(), 1) << name;
      EXPECT_NE(std::string(f.what()).find("left the grid"), std::string::npos) << name;
    }
  }
}

TEST(ShapeFamilies, OpenKnotSplinesRejectAParticleJustBeyondAFace) {
  auto fam = family<1>("bspline2_open");
  const Grid<1> grid(Vec<1>::Zero(), IVec<1>::Constant(10), Vec<1>::Constant(0.1), 1, {false});
  Particles<1> parts;
  parts.add(Vec<1>::Constant(-0.001), Vec<1>::Zero(), 1, 1, Vec<1>::Constant(0.05), 0, 0);
  TransferCache<1> c;
  EXPECT_THROW(fam->build(grid, parts, c), SimulationFailure);
}

}  // namespace
}  // namespace cairn

namespace cairn {
namespace {

// The one-walk gather of the fused particle and stress update (tensor_gather_gradient) against
// the entry-by-entry sums: S v, S u and sum u (x) G over the expanded stencil, for 3D tensor
// families of width 2, 3 and 4 and random node fields.
TEST(TensorTransfers, OneWalkGatherMatchesTheEntrySums) {
  for (const std::string name : {"linear", "bspline2", "bspline3"}) {
    auto fam = family<3>(name);
    const Grid<3> grid(Vec<3>::Zero(), IVec<3>::Constant(8), Vec<3>::Constant(0.125), fam->ghost_layers(), {});
    Particles<3> parts;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u01(0.1, 0.9), uv(-1.0, 1.0);
    for (int k = 0; k < 50; ++k) parts.add(Vec<3>(u01(rng), u01(rng), u01(rng)), Vec<3>::Zero(), 1.0, 1e-3, Vec<3>::Constant(0.06), 0, 0);
    TransferCache<3> cache;
    fam->build(grid, parts, cache);
    ASSERT_EQ(cache.layout, StencilLayout::tensor) << name;
    std::vector<Vec<3>> v(grid.n_nodes()), w(grid.n_nodes());
    for (auto& x : v) x = Vec<3>(uv(rng), uv(rng), uv(rng));
    for (auto& x : w) x = Vec<3>(uv(rng), uv(rng), uv(rng));
    int checked = 0;
    with_stencils(cache, [&](auto stencil_of) {
      for (std::size_t p = 0; p < parts.n(); ++p) {
        const auto st = stencil_of(p);
        if constexpr (!std::is_same_v<std::decay_t<decltype(st)>, ListStencil<3>>) {
          double sv[3] = {}, sw[3] = {}, l[3][3] = {};
          tensor_gather_gradient(st, v, w, 0, sv, sw, l);
          Vec<3> ev = Vec<3>::Zero(), ew = Vec<3>::Zero();
          Mat3 el = Mat3::Zero();
          st.for_each([&](std::int32_t node, double S, const Vec<3>& G) {
            ev += S * v[node];
            ew += S * w[node];
            el += w[node] * G.transpose();
          });
          for (int r = 0; r < 3; ++r) {
            EXPECT_NEAR(sv[r], ev[r], 1e-14) << name << " p=" << p;
            EXPECT_NEAR(sw[r], ew[r], 1e-14) << name << " p=" << p;
            for (int c = 0; c < 3; ++c) EXPECT_NEAR(l[r][c], el(r, c), 1e-12) << name << " p=" << p;
          }
          ++checked;
        }
      }
    });
    EXPECT_EQ(checked, 50) << name;
  }
}

}  // namespace
}  // namespace cairn
