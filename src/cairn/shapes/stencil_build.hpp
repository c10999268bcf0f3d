// What every stencil build of shapes/ shares: the particle loop on the threads that later gather
// and scatter the same particles (with stealing, util/parallel.hpp), the reach of the stencils it
// merges from the threads, and the failure of a particle whose stencil left the stored grid.
#pragma once

#include <omp.h>

#include <algorithm>
#include <climits>
#include <cstdint>
#include <string>

#include "cairn/particles/particles.hpp"
#include "cairn/transfer/cache.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/util/parallel.hpp"

namespace cairn {

/// Nodes a step's stencils reach below and above their particles' cells, and the lowest
/// particle whose stencil left the stored grid (INT64_MAX: none).
template <int D>
struct StencilReach {
  IVec<D> lo = IVec<D>::Zero(), hi = IVec<D>::Zero();
  std::int64_t first_bad = INT64_MAX;

  void bad(std::int64_t p) { first_bad = std::min(first_bad, p); }
  void merge(const StencilReach& other) {
    lo = lo.cwiseMax(other.lo);
    hi = hi.cwiseMax(other.hi);
    first_bad = std::min(first_bad, other.first_bad);
  }
};

/// build(p, reach) for every particle p < n, each thread with its own reach (merged into `reach`),
/// each thread taking the particles it later gathers and scatters and helping a slower one.
template <int D, class Build>
void for_each_stencil(std::int64_t n, StencilReach<D>& reach, Build&& build) {
  StealingShare share(n);
#pragma omp parallel
  {
    StencilReach<D> local;
    auto cursor = share.cursor();
    for (std::int64_t first_p, last_p; cursor.next(first_p, last_p);)
      for (std::int64_t p = first_p; p < last_p; ++p) build(p, local);
#pragma omp critical(cairn_stencil_reach)
    reach.merge(local);
  }
}

/// Store the reach in the cache; a particle whose stencil left the grid stops the step with its
/// position (`what`: what reached beyond the ghost nodes, e.g. "its stencil").
template <int D>
void finish_stencils(const StencilReach<D>& reach, const Particles<D>& particles, TransferCache<D>& cache,
                     const char* what) {
  cache.reach_lo = reach.lo;
  cache.reach_hi = reach.hi;
  if (reach.first_bad == INT64_MAX) return;
  const Vec<D>& x = particles.position[reach.first_bad];
  std::string where;
  for (int a = 0; a < D; ++a) where += (a ? ", " : "") + failure_number(x[a]);
  throw SimulationFailure(reach.first_bad, "position",
                          "particle " + std::to_string(reach.first_bad) + " left the grid at (" + where + "): " +
                              what + " reaches beyond the ghost nodes");
}

}  // namespace cairn
