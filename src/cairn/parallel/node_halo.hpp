// The node halo of a distributed run (docs/parallel.md, "Node halo"): each rank scatters its own
// particles only, into a window of the grid one stencil (plus a cell) wider than its box, and the
// nodes that several ranks' windows share are summed across those ranks.
//
// One symmetric exchange per sum: every rank sends each neighbour its partial values at the
// nodes their two windows share and receives the neighbour's. The total at a shared node is
// then formed on every rank that holds it in the same order, over the ranks holding it in
// increasing rank (0 + p_r0 + p_r1 + ...), so all copies of a node are the same bits and a run is
// repeatable for a given rank count and partition. The ranks holding a node are pairwise
// neighbours (their windows all contain it), so every rank sees the same set of partials. Against
// the serial run the sums differ only in the order of their terms: round-off.
//
// This replaces the reverse (halo to owner) and forward (owner to halo) exchanges of the usual
// scheme by one exchange of the shared layers each way: the same bytes, one message latency.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/parallel/decomposition.hpp"

namespace cairn {

/// The window of `whole` a rank with box `box` stores: its nodes and `margin` nodes beyond.
template <int D>
[[nodiscard]] Grid<D> box_window(const Grid<D>& whole, const CellBox<D>& box, int margin) {
  IVec<D> first, count;
  for (int a = 0; a < D; ++a) {
    first[a] = box.lo[a] - margin;
    count[a] = box.hi[a] - box.lo[a] + 1 + 2 * margin;
  }
  return whole.window(first, count, box.lo, box.hi);
}

template <int D>
class NodeHalo {
 public:
  NodeHalo() = default;

  /// The nodes this rank's window (box_window of its box) shares with the windows of the other
  /// ranks, all of margin `margin` around their boxes of `decomposition` on the grid `whole`;
  /// `partitions` labels the decomposition (every rank builds with the same arguments).
  void build(const Comm& comm, const Decomposition<D>& decomposition, const Grid<D>& whole, int margin,
             int partitions);
  /// The nodes the windows (box_window, `margin`) of boxes `a` and `b` both hold, as the whole
  /// grid's node indices in increasing order (the order both sides pack them in).
  [[nodiscard]] static std::vector<std::int32_t> shared_nodes(const CellBox<D>& a, const CellBox<D>& b,
                                                              const Grid<D>& whole, int margin);
  /// Whether build() has been called with these arguments' geometry (same boxes, same margin).
  [[nodiscard]] bool built_for(int margin, int partitions) const {
    return margin == margin_ && partitions == partitions_;
  }

  /// Sum every array (n_fields x n_nodes entries each, field-major, window storage) over the
  /// ranks sharing each node, in one exchange; afterwards every copy of a shared node holds
  /// the same total.
  template <class... T>
  void sum(int n_fields, std::vector<T>&... arrays) const {
    if (neighbours_.empty()) return;
    // (Values travel as bytes: doubles and fixed-size Eigen vectors, plain data both.)
    const std::size_t row = (sizeof(T) + ... + 0) * static_cast<std::size_t>(n_fields);
    const std::size_t k_max = neighbours_.size();
    Comm::Buffers send(k_max), recv(k_max);
    for (std::size_t k = 0; k < k_max; ++k) {
      send[k].resize(shared_[k].size() * row);
      recv[k].resize(shared_[k].size() * row);
      char* out = send[k].data();
      for (std::int32_t node : shared_[k])
        for (int f = 0; f < n_fields; ++f) {
          const std::size_t at = static_cast<std::size_t>(f) * n_nodes_ + static_cast<std::size_t>(node);
          ((std::memcpy(out, static_cast<const void*>(&arrays[at]), sizeof(T)), out += sizeof(T)), ...);
        }
    }
    comm_.exchange_sized(neighbours_, send, recv);
    bytes_sent_ += static_cast<std::int64_t>(send_bytes(send));
    // The totals, in increasing rank over the holders of each node.
    std::size_t offset = 0;
    ((combine(arrays, n_fields, recv, row / static_cast<std::size_t>(n_fields), offset), offset += sizeof(T)), ...);
  }

  /// Ranks this one shares nodes with, and how many nodes with each.
  [[nodiscard]] const std::vector<int>& neighbours() const { return neighbours_; }
  [[nodiscard]] std::size_t shared_nodes() const {
    std::size_t n = 0;
    for (const auto& s : shared_) n += s.size();
    return n;
  }
  /// Bytes this rank has sent in sums so far.
  [[nodiscard]] std::int64_t bytes_sent() const { return bytes_sent_; }

 private:
  static std::size_t send_bytes(const Comm::Buffers& b) {
    std::size_t n = 0;
    for (const auto& x : b) n += x.size();
    return n;
  }
  /// values[i] = sum over the holders of node i, in increasing rank, of their partials; the
  /// partial of array T sits at byte `offset` of each field's part (`field_bytes` long) of a
  /// node's row in the buffers.
  template <class T>
  void combine(std::vector<T>& values, int n_fields, const Comm::Buffers& recv, std::size_t field_bytes,
               std::size_t offset) const {
    const std::size_t row = field_bytes * static_cast<std::size_t>(n_fields);
    T zero;
    if constexpr (std::is_arithmetic_v<T>) zero = T(0);
    else zero = T::Zero();
    for (int f = 0; f < n_fields; ++f) {
      const std::size_t base = static_cast<std::size_t>(f) * n_nodes_;
      std::vector<T> total(union_.size(), zero);
      auto add_from = [&](std::size_t k) {
        const char* in = recv[k].data();
        for (std::size_t s = 0; s < shared_[k].size(); ++s) {
          T v;
          std::memcpy(static_cast<void*>(&v), in + s * row + static_cast<std::size_t>(f) * field_bytes + offset, sizeof(T));
          total[slot_[k][s]] += v;
        }
      };
      std::size_t k = 0;
      for (; k < neighbours_.size() && neighbours_[k] < rank_; ++k) add_from(k);
      for (std::size_t u = 0; u < union_.size(); ++u) total[u] += values[base + static_cast<std::size_t>(union_[u])];
      for (; k < neighbours_.size(); ++k) add_from(k);
      for (std::size_t u = 0; u < union_.size(); ++u) values[base + static_cast<std::size_t>(union_[u])] = total[u];
    }
  }
  Comm comm_ = Comm::serial();
  int rank_ = 0;
  int margin_ = -1;
  int partitions_ = -1;
  std::size_t n_nodes_ = 0;
  std::vector<int> neighbours_;                     ///< increasing rank
  std::vector<std::vector<std::int32_t>> shared_;   ///< per neighbour: window nodes, canonical order
  std::vector<std::vector<std::int32_t>> slot_;     ///< per neighbour: their place in union_
  std::vector<std::int32_t> union_;                 ///< every shared node of this window, once
  mutable std::int64_t bytes_sent_ = 0;
};

}  // namespace cairn
