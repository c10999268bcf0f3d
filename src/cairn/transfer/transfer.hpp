// Generic particle<->grid kernels over the transfer cache, written once for every shape family.
//
// Parallel strategy and the guarantee it gives: particles are binned into blocks of cells wide
// enough that two blocks of the same colour never touch a common node. Scatters run colour by
// colour; within a colour, blocks run in parallel and each block adds its particles in storage
// order. Every node therefore receives its contributions in an order that does not depend on
// the number of threads, so results are bit-identical for any OMP_NUM_THREADS.
#pragma once

#include <cstdint>

#include "cairn/grid/grid.hpp"
#include "cairn/transfer/cache.hpp"

namespace cairn {

/// Bin particles into coloured cell blocks using cache.cell and the reach reported by the shape
/// family. Call after every stencil build. Allocation-free once sized.
template <int D>
void colour_blocks(const Grid<D>& grid, TransferCache<D>& cache);

/// Scatter: calls fn(p, slot) for every particle p and stencil slot, race-free as above; fn may
/// add into node arrays indexed by cache.node[slot].
template <int D, class Fn>
void scatter(const TransferCache<D>& cache, Fn&& fn) {
  for (const auto& blocks : cache.colour_blocks) {
    const auto n_blocks = static_cast<std::int64_t>(blocks.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (std::int64_t b = 0; b < n_blocks; ++b) {
      const std::int32_t block = blocks[b];
      for (std::int32_t i = cache.block_begin[block]; i < cache.block_begin[block + 1]; ++i) {
        const std::int32_t p = cache.order[i];
        const std::size_t base = static_cast<std::size_t>(p) * cache.stride;
        for (std::size_t s = base; s < base + cache.count[p]; ++s) fn(p, s);
      }
    }
  }
}

/// Gather: calls fn(p, begin, end) for every particle in parallel with its slot range.
template <int D, class Fn>
void gather(const TransferCache<D>& cache, Fn&& fn) {
  const auto n = static_cast<std::int64_t>(cache.count.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t p = 0; p < n; ++p) {
    const std::size_t base = static_cast<std::size_t>(p) * cache.stride;
    fn(p, base, base + cache.count[p]);
  }
}

/// Parallel loop over nodes.
template <class Fn>
void for_each_node(std::int32_t n_nodes, Fn&& fn) {
#pragma omp parallel for schedule(static)
  for (std::int32_t i = 0; i < n_nodes; ++i) fn(i);
}

}  // namespace cairn
