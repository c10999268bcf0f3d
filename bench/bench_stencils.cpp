// Stencil-build cost per shape family: nanoseconds per particle for one ShapeFamily::build (the
// S_pi, G_pi, node-index cache of a step), one thread, in 2D and 3D. Particles fill a block with
// 2 per cell per axis and carry a random deformation gradient (up to 10 % stretch and shear) so
// that cpGIMP, CPDI and B2CPDI do their full work. The target: CPDI and B2CPDI within
// twice the quadratic B-spline (bspline2) of the same run; docs/shape-functions.md records the
// measured ratios. Run: build/release/bench/cairn_bench --benchmark_filter=Stencil
// --benchmark_repetitions=7 --benchmark_enable_random_interleaving=true (take the minimum: single
// runs on a shared machine scatter by about 15 %).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <random>

#include "cairn/shapes/shape_family.hpp"

namespace cairn {
namespace {

template <int D>
void build_stencils(benchmark::State& state, const std::string& family) {
  omp_set_num_threads(1);
  const int cells = D == 2 ? 128 : 32;
  const double h = 1.0 / cells;
  MethodConfig method;
  method.shape = family;
  auto fam = make_shape_family<D>(ShapeContext{method, D});
  const Grid<D> grid(Vec<D>::Zero(), IVec<D>::Constant(cells), Vec<D>::Constant(h), fam->ghost_layers(),
                     std::array<bool, D>{});
  Particles<D> parts;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  const int ppc = 2, lo = cells / 8, n_axis = (cells - 2 * lo) * ppc;
  long long total = 1;
  for (int a = 0; a < D; ++a) total *= n_axis;
  for (long long k = 0; k < total; ++k) {
    long long rem = k;
    Vec<D> x;
    for (int a = 0; a < D; ++a) {
      x[a] = (lo + (static_cast<double>(rem % n_axis) + 0.5) / ppc) * h;
      rem /= n_axis;
    }
    parts.add(x, Vec<D>::Zero(), 1.0, 1.0, Vec<D>::Constant(h / ppc), 0, 0);
    Mat3& F = parts.deformation_gradient.back();
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) F(a, b) += u(rng);
  }
  TransferCache<D> cache;
  fam->build(grid, parts, cache);  // size the cache
  for (auto _ : state) {
    fam->build(grid, parts, cache);
    benchmark::DoNotOptimize(cache.weight.data());
    benchmark::DoNotOptimize(cache.axis_value.data());
  }
  const double n = static_cast<double>(parts.n());
  state.counters["particles"] = n;
  int slots = cache.stride;
  if (cache.layout == StencilLayout::tensor) {
    slots = 1;
    for (int a = 0; a < D; ++a) slots *= cache.width;
  }
  state.counters["slots"] = slots;
  state.counters["ns_per_particle"] = benchmark::Counter(
      n * static_cast<double>(state.iterations()) * 1e-9, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

const char* const families[] = {"linear",        "bspline2",      "bspline3", "bspline2_open",
                                "bspline3_open", "ugimp",         "gimp",     "cpgimp",
                                "b2gimp",        "cpdi",          "b2cpdi"};

const bool registered = [] {
  for (const char* f : families) {
    benchmark::RegisterBenchmark((std::string("BM_Stencil2D/") + f).c_str(),
                                 [f](benchmark::State& s) { build_stencils<2>(s, f); })
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark((std::string("BM_Stencil3D/") + f).c_str(),
                                 [f](benchmark::State& s) { build_stencils<3>(s, f); })
        ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
}  // namespace cairn
