// WLS throughput in particle-steps per second per core (docs/performance.md, WLS): the ring of
// seed 001 Sec. 5.1 (annulus R_I = 0.5, R_O = 1, neo-Hookean Eq. 31-32, nu = 0, plane strain,
// central differences) spun and breathing, on a grid of h = 0.02 (about 4 particles per cell):
//   * WLS (method.integration = "wls", radial arrangement of Fig. 4b, surface particles);
//   * WLS with the set-up docs/wls.md recommends (point_values = "fit", velocity_gradient =
//     "transpose");
//   * the quadratic B-spline MPM step on the same ring and grid (Cartesian 2 x 2 lattice), the
//     reference of issue 12's "no more than 4x the quadratic B-spline step per particle".
// Run: build/release/bench/cairn_bench --benchmark_filter=Wls
#include <benchmark/benchmark.h>
#include <omp.h>

#include <string>

#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"
#include "run_steps.hpp"

namespace cairn {
namespace {

enum class Ring { wls, wls_fit_transpose, bspline2 };

Config ring_config(Ring kind) {
  const bool wls = kind != Ring::bspline2;
  std::string text = R"(
[simulation]
dimension = 2
mode = "plane_strain"
end_time = 1.0
cfl = 0.3
[grid]
origin = [-1.2, -1.2]
extent = [2.4, 2.4]
cell_size = 0.02
[[material]]
name = "m"
model = "neo_hookean"
form = "ln_j"
density = 1.0
youngs_modulus = 1.0e4
poissons_ratio = 0.0
[[body]]
name = "ring"
material = "m"
shape = { annulus = { center = [0.0, 0.0], inner_radius = 0.5, outer_radius = 1.0 } }
particles_per_cell = 2
velocity = ["0.5*X - 0.3*Y", "0.5*Y + 0.3*X"]
)";
  text += wls ? "arrangement = \"radial\"\n[method]\nshape = \"linear\"\nintegration = \"wls\"\n"
              : "arrangement = \"cartesian\"\n[method]\nshape = \"bspline2\"\n";
  text += "time_integration = \"central_difference\"\n";
  if (kind == Ring::wls_fit_transpose) text += "point_values = \"fit\"\nvelocity_gradient = \"transpose\"\n";
  return load_config_string(text, "bench_wls.toml", {});
}

void run_ring(benchmark::State& state, Ring kind) { bench::run_steps<2>(state, ring_config(kind)); }

void BM_WlsStep_Ring(benchmark::State& state) { run_ring(state, Ring::wls); }
void BM_WlsStepFitTranspose_Ring(benchmark::State& state) { run_ring(state, Ring::wls_fit_transpose); }
void BM_WlsReference_Ring_BSpline2(benchmark::State& state) { run_ring(state, Ring::bspline2); }

BENCHMARK(BM_WlsStep_Ring)->Arg(1)->Arg(omp_get_num_procs())->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WlsStepFitTranspose_Ring)->Arg(1)->Arg(omp_get_num_procs())->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WlsReference_Ring_BSpline2)->Arg(1)->Arg(omp_get_num_procs())->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cairn
