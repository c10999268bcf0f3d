// A STREAM-like measurement of the machine's memory bandwidth (McCalpin's four kernels: copy,
// scale, add, triad) over arrays far larger than the caches, so docs/performance.md can say how
// far each stage of a step is from the bandwidth bound. Bytes counted as STREAM does: every
// array element read or written once (no write-allocate traffic counted).
//
//   build/release/bench/cairn_bench --benchmark_filter=Stream --benchmark_repetitions=5
//
// The "bytes_per_second" column is the bandwidth; threads follow OMP_NUM_THREADS.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {

constexpr std::size_t n_elements = std::size_t{1} << 24;  // 16 Mi doubles = 128 MiB per array

struct Arrays {
  std::vector<double> a, b, c;
  Arrays() : a(n_elements), b(n_elements), c(n_elements) {
    // First touch in parallel, as the kernels run, so pages sit near the threads that use them.
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(n_elements); ++i) {
      a[i] = 1.0;
      b[i] = 2.0;
      c[i] = 0.0;
    }
  }
};

Arrays& arrays() {
  static Arrays arr;
  return arr;
}

template <class Kernel>
void run(benchmark::State& state, int arrays_touched, Kernel kernel) {
  Arrays& arr = arrays();
  const auto n = static_cast<std::int64_t>(n_elements);
  for (auto _ : state) {
    kernel(arr.a.data(), arr.b.data(), arr.c.data(), n);
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(state.iterations() * n * arrays_touched * static_cast<std::int64_t>(sizeof(double)));
  state.counters["threads"] = omp_get_max_threads();
}

void Stream_Copy(benchmark::State& state) {
  run(state, 2, [](double* a, const double*, double* c, std::int64_t n) {
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) c[i] = a[i];
  });
}

void Stream_Scale(benchmark::State& state) {
  run(state, 2, [](const double*, double* b, const double* c, std::int64_t n) {
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) b[i] = 3.0 * c[i];
  });
}

void Stream_Add(benchmark::State& state) {
  run(state, 3, [](const double* a, const double* b, double* c, std::int64_t n) {
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) c[i] = a[i] + b[i];
  });
}

void Stream_Triad(benchmark::State& state) {
  run(state, 3, [](double* a, const double* b, const double* c, std::int64_t n) {
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) a[i] = b[i] + 3.0 * c[i];
  });
}

}  // namespace

BENCHMARK(Stream_Copy)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Stream_Scale)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Stream_Add)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(Stream_Triad)->Unit(benchmark::kMillisecond)->UseRealTime();
