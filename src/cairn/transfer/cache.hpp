// The per-step transfer cache: for each particle its stencil (node index, S_pi, grad S_pi),
// filled once per step by the shape family and reused by every transfer of that step, plus the
// cell-block colouring that makes particle-to-grid scatters race-free without atomics.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cairn/math/types.hpp"

namespace cairn {

template <int D>
struct TransferCache {
  int stride = 0;                    ///< stencil slots per particle (the family's maximum)
  std::vector<std::int32_t> node;    ///< n*stride node indices (storage numbering)
  /// Multimaterial mode only: node + field * n_nodes of each entry, the index into per-field
  /// node arrays (contact/contact.hpp); empty otherwise.
  std::vector<std::int32_t> slot;
  std::vector<double> weight;        ///< S_pi
  std::vector<Vec<D>> gradient;      ///< G_pi = grad S_pi (physical units)
  std::vector<std::uint16_t> count;  ///< number of used slots per particle
  std::vector<IVec<D>> cell;         ///< cell holding each particle (for colouring)

  /// Stencil reach in cells beyond the particle's cell, per axis: nodes from cell - reach_lo
  /// to cell + 1 + reach_hi. Reported by the family so that colouring blocks are wide enough.
  IVec<D> reach_lo = IVec<D>::Zero();
  IVec<D> reach_hi = IVec<D>::Zero();

  // Colouring: particles sorted by block; blocks of one colour share no node.
  std::vector<std::int32_t> order;          ///< particle indices grouped by block
  std::vector<std::int32_t> block_begin;    ///< n_blocks + 1 offsets into order
  std::vector<std::vector<std::int32_t>> colour_blocks;  ///< blocks of each colour
  std::vector<std::int32_t> block_of;       ///< scratch: block of each particle
  std::vector<std::int32_t> cursor;         ///< scratch for the counting sort

  /// Make room for n particles with `slots` stencil entries each (no-op when already sized).
  void reserve(std::size_t n, int slots) {
    if (stride == slots && count.size() == n) return;
    stride = slots;
    node.assign(n * slots, -1);
    weight.assign(n * slots, 0.0);
    gradient.assign(n * slots, Vec<D>::Zero());
    count.assign(n, 0);
    cell.assign(n, IVec<D>::Zero());
    block_of.assign(n, 0);
    order.assign(n, 0);
  }
};

}  // namespace cairn
