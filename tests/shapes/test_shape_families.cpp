// Property tests every shape family must pass: partition of unity, zero gradient sum and exact
// reproduction of linear fields (value and gradient), in 1D, 2D and 3D, at random points across
// the whole domain including the cells next to each face and next to periodic seams.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "../support/config_builder.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/sim/names.hpp"

namespace cairn {
namespace {

template <int D>
void check_family(const std::string& name, bool periodic) {
  Config cfg = test::box_config(D, name);
  ShapeContext ctx{cfg.method, D};
  auto family = make_shape_family<D>(ctx);
  std::array<bool, D> per{};
  per.fill(periodic);
  const Grid<D> grid(Vec<D>::Zero(), IVec<D>::Constant(10), Vec<D>::Constant(0.1),
                     family->ghost_layers(), per);
  Particles<D> parts;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 400; ++k) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = u(rng);
    if (k < 2 * D) x[k / 2] = (k % 2) ? 0.999 : 0.001;  // right next to each face
    parts.add(x, Vec<D>::Zero(), 1.0, 1e-3, Vec<D>::Constant(0.05), 0, 0);
  }
  TransferCache<D> cache;
  family->build(grid, parts, cache);
  const Vec<D> slope = Vec<D>::LinSpaced(1.0, 2.0);
  for (std::size_t p = 0; p < parts.n(); ++p) {
    double sum = 0.0, lin = 0.0;
    Vec<D> grad_sum = Vec<D>::Zero(), lin_grad = Vec<D>::Zero();
    Vec<D> pos_sum = Vec<D>::Zero();
    for (std::size_t s = p * cache.stride; s < p * cache.stride + cache.count[p]; ++s) {
      const Vec<D> xi = grid.node_position(cache.node[s]);
      sum += cache.weight[s];
      grad_sum += cache.gradient[s];
      lin += cache.weight[s] * slope.dot(xi);
      lin_grad += slope.dot(xi) * cache.gradient[s];
      pos_sum += cache.weight[s] * xi;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << name << " D=" << D << " p=" << p;
    EXPECT_LT(grad_sum.norm(), 1e-9) << name << " D=" << D << " p=" << p;
    if (!periodic) {  // a periodic wrap maps nodes onto the other side: no linear reproduction
      EXPECT_NEAR(lin, slope.dot(parts.position[p]), 1e-12) << name << " D=" << D;
      EXPECT_LT((lin_grad - slope).norm(), 1e-9) << name << " D=" << D;
    }
  }
}

TEST(ShapeFamilies, EveryRegisteredFamilyIsAPartitionOfUnityAndReproducesLinearFields) {
  const auto names = shape_family_names();
  ASSERT_GE(names.size(), 3u);
  for (const auto& name : names) {
    for (bool periodic : {false, true}) {
      check_family<1>(name, periodic);
      check_family<2>(name, periodic);
      check_family<3>(name, periodic);
    }
  }
}

TEST(ShapeFamilies, UGimpWithSmoothingLengthHEqualsTheQuadraticSpline) {
  Config cfg = test::box_config(1, "ugimp");
  cfg.method.smoothing_length = 0.1;  // l = h (seed 003 Sec. 4.1)
  auto gimp = make_shape_family<1>(ShapeContext{cfg.method, 1});
  Config cfg2 = test::box_config(1, "bspline2");
  auto spline = make_shape_family<1>(ShapeContext{cfg2.method, 1});
  const Grid<1> grid(Vec<1>::Zero(), IVec<1>::Constant(10), Vec<1>::Constant(0.1), 2, {false});
  Particles<1> parts;
  for (double x : {0.123, 0.25, 0.5, 0.777, 0.9501})
    parts.add(Vec<1>::Constant(x), Vec<1>::Zero(), 1.0, 1.0, Vec<1>::Constant(0.05), 0, 0);
  TransferCache<1> c1, c2;
  gimp->build(grid, parts, c1);
  spline->build(grid, parts, c2);
  for (std::size_t p = 0; p < parts.n(); ++p) {
    std::map<int, std::pair<double, double>> a, b;
    for (std::size_t s = p * c1.stride; s < p * c1.stride + c1.count[p]; ++s)
      if (c1.weight[s] != 0.0) a[c1.node[s]] = {c1.weight[s], c1.gradient[s][0]};
    for (std::size_t s = p * c2.stride; s < p * c2.stride + c2.count[p]; ++s)
      if (c2.weight[s] != 0.0) b[c2.node[s]] = {c2.weight[s], c2.gradient[s][0]};
    ASSERT_EQ(a.size(), b.size());
    for (const auto& [node, wg] : b) {
      EXPECT_NEAR(a[node].first, wg.first, 1e-14);
      EXPECT_NEAR(a[node].second, wg.second, 1e-11);
    }
  }
}

TEST(ShapeFamilies, UGimpWeightIsTheExactIntegralOfTheHatOverTheParticle) {
  // seed 000 Sec. 2.1: S_pi = (1/V_p) int_{V_p} N_i dx. Compare with a fine midpoint quadrature.
  Config cfg = test::box_config(1, "ugimp");
  auto gimp = make_shape_family<1>(ShapeContext{cfg.method, 1});
  const Grid<1> grid(Vec<1>::Zero(), IVec<1>::Constant(10), Vec<1>::Constant(0.1), 2, {false});
  Particles<1> parts;
  parts.add(Vec<1>::Constant(0.4321), Vec<1>::Zero(), 1.0, 1.0, Vec<1>::Constant(0.07), 0, 0);
  TransferCache<1> c;
  gimp->build(grid, parts, c);
  for (std::size_t s = 0; s < c.count[0]; ++s) {
    const double xi = grid.node_position(c.node[s])[0];
    const int n = 20000;
    double integral = 0.0;
    for (int k = 0; k < n; ++k) {
      const double x = 0.4321 - 0.035 + (k + 0.5) * 0.07 / n;
      integral += std::max(0.0, 1.0 - std::abs(x - xi) / 0.1) / n;
    }
    EXPECT_NEAR(c.weight[s], integral, 1e-8);
  }
}

TEST(ShapeFamilies, ParticleOutsideTheGridIsReported) {
  Config cfg = test::box_config(2, "linear");
  auto fam = make_shape_family<2>(ShapeContext{cfg.method, 2});
  const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1), 1, {false, false});
  Particles<2> parts;
  parts.add(Vec<2>(0.5, 0.5), Vec<2>::Zero(), 1, 1, Vec<2>::Constant(0.05), 0, 0);
  parts.add(Vec<2>(1.35, 0.5), Vec<2>::Zero(), 1, 1, Vec<2>::Constant(0.05), 0, 0);
  TransferCache<2> c;
  try {
    fam->build(grid, parts, c);
    FAIL() << "expected a SimulationFailure";
  } catch (const SimulationFailure& f) {
    EXPECT_EQ(f.particle(), 1);
    EXPECT_NE(std::string(f.what()).find("left the grid"), std::string::npos);
  }
}

}  // namespace
}  // namespace cairn
