// The machine's 2-thread ceiling: what a perfectly parallel, compute-bound OpenMP program gains
// from a second thread here and now. Each thread works on its own 16 KiB (in L1; no data shared,
// no memory traffic), the threads meet at a barrier about every 30 us and in a new parallel
// region about every 300 us, the cadence of a Cairn step's stages (docs/performance.md,
// "Threads on a shared machine"). On an idle 2-core machine 2 threads take half the time of one;
// on a virtual machine whose cores another guest slows, they do not, and bench/thread_scaling.py
// --ceiling runs this beside Cairn to tell the two apart.
//
//   cairn_ceiling THREADS [REGIONS]   prints "seconds THREADS checksum"
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: cairn_ceiling THREADS [REGIONS]\n");
    return 2;
  }
  const int threads = std::atoi(argv[1]);
  const int regions = argc > 2 ? std::atoi(argv[2]) : 400;
  constexpr int n = 2048, per_barrier = 512, repeats = 16, barriers = 10;
  // Two work items whatever the team size: one thread does both, two do one each.
  std::vector<std::vector<double>> data(2, std::vector<double>(n));
  for (auto& d : data)
    for (int i = 0; i < n; ++i) d[i] = 1.0 + 1e-4 * i;
  double sum = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (int r = 0; r < regions; ++r) {
#pragma omp parallel num_threads(threads) reduction(+ : sum)
    for (int b = 0; b < barriers; ++b) {
      for (int item = omp_get_thread_num(); item < 2; item += omp_get_num_threads()) {
        double* x = data[item].data();
        for (int rep = 0; rep < repeats; ++rep)
          for (int i = 0; i < per_barrier; ++i) {
            double v = x[i];
            v = std::exp(-v) * 1.7 + std::sqrt(v) + 1.0 / (v + 1.0);
            x[i] = 0.5 * v + 0.5;
            sum += v;
          }
      }
#pragma omp barrier
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%.6f %d %.17g\n", seconds, threads, sum);
  return 0;
}
