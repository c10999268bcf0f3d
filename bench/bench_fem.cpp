// FEM throughput in element-steps per second per core (docs/performance.md, FEM): the ring of
// seed 001 Sec. 5.1 (structured annulus, neo-Hookean Eq. 31-32, plane strain) spun and
// breathing, with and without a body force expression (the manufactured-solution runs evaluate
// one per node and step). Run: build/release/bench/cairn_bench --benchmark_filter=Fem
#include <benchmark/benchmark.h>
#include <omp.h>

#include "cairn/fem/solver.hpp"
#include "cairn/input/input.hpp"

namespace cairn {
namespace {

Config ring_config(bool body_force) {
  std::string text = R"(
[simulation]
dimension = 2
end_time = 1.0
cfl = 0.3
[[material]]
name = "m"
model = "neo_hookean"
density = 1.0
youngs_modulus = 1.0e4
poissons_ratio = 0.0
[fem]
material = "m"
shape = { annulus = { center = [0.0, 0.0], inner_radius = 0.5, outer_radius = 1.0 } }
size = 0.005
mesher = "structured"
velocity = ["0.5*X - 0.3*Y", "0.5*Y + 0.3*X"]
)";
  if (body_force) text += "[body_force]\nexpression = [\"0.1*sqrt(X^2+Y^2)*cos(100*t)*X\", \"0.1*sqrt(X^2+Y^2)*cos(100*t)*Y\"]\n";
  return load_config_string(text, "bench_fem.toml", {});
}

void run_fem(benchmark::State& state, bool body_force) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  fem::Solver s(ring_config(body_force));
  const double dt = s.next_dt();
  for (int i = 0; i < 3; ++i) s.step(dt);
  for (auto _ : state) s.step(dt);
  const double n = static_cast<double>(s.mesh().n_elements());
  state.counters["elements"] = n;
  state.counters["threads"] = threads;
  state.counters["element_steps_per_s"] = benchmark::Counter(n * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["element_steps_per_s_per_core"] =
      benchmark::Counter(n * static_cast<double>(state.iterations()) / threads, benchmark::Counter::kIsRate);
}

void BM_FemStep_Ring_NeoHookean(benchmark::State& state) { run_fem(state, false); }
void BM_FemStep_Ring_NeoHookean_BodyForce(benchmark::State& state) { run_fem(state, true); }

BENCHMARK(BM_FemStep_Ring_NeoHookean)->Arg(1)->Arg(omp_get_num_procs())->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FemStep_Ring_NeoHookean_BodyForce)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cairn
