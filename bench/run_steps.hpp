// The shared timing loop of the whole-step benchmarks: builds a Simulation, warms it up, steps it
// under Google Benchmark and reports particle-steps per second (in all and per core).
#pragma once

#include <benchmark/benchmark.h>
#include <omp.h>

#include "cairn/sim/simulation.hpp"

namespace cairn::bench {

template <int D>
void run_steps(benchmark::State& state, const Config& cfg) {
  const int threads = static_cast<int>(state.range(0));
  omp_set_num_threads(threads);
  Simulation<D> sim(cfg);
  const double dt = sim.next_dt();
  for (int i = 0; i < 3; ++i) sim.step(dt);  // warm up: the first stencil build sizes the cache
  for (auto _ : state) sim.step(dt);
  // Every particle counts (WLS surface particles, of zero volume, included: they are fitted).
  const double n = static_cast<double>(sim.particles().n());
  state.counters["particles"] = n;
  state.counters["threads"] = threads;
  state.counters["particle_steps_per_s"] =
      benchmark::Counter(n * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["particle_steps_per_s_per_core"] = benchmark::Counter(
      n * static_cast<double>(state.iterations()) / threads, benchmark::Counter::kIsRate);
}

}  // namespace cairn::bench
