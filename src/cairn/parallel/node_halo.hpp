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

#include <chrono>
#include <cstdint>
#include <cstring>
#include <span>
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
  /// the same total. The message buffers are kept between calls (no allocation in a step once
  /// the largest sum has run).
  template <class... T>
  void sum(int n_fields, std::vector<T>&... arrays) {
    if (neighbours_.empty()) return;
    const auto started = std::chrono::steady_clock::now();
    // (Values travel as bytes: doubles and fixed-size Eigen vectors, plain data both.)
    const std::size_t row = (sizeof(T) + ... + 0) * static_cast<std::size_t>(n_fields);
    for (std::size_t k = 0; k < neighbours_.size(); ++k) {
      send_[k].resize(shared_[k].size() * row);
      recv_[k].resize(shared_[k].size() * row);
      char* out = send_[k].data();
      for (std::int32_t node : shared_[k])
        for (int f = 0; f < n_fields; ++f) {
          const std::size_t at = static_cast<std::size_t>(f) * n_nodes_ + static_cast<std::size_t>(node);
          ((std::memcpy(out, static_cast<const void*>(&arrays[at]), sizeof(T)), out += sizeof(T)), ...);
        }
      bytes_sent_ += static_cast<std::int64_t>(send_[k].size());
    }
    const auto packed = std::chrono::steady_clock::now();
    comm_.exchange_sized(neighbours_, send_, recv_);
    wait_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - packed).count();
    std::size_t offset = 0;
    ((combine(arrays, n_fields, row / static_cast<std::size_t>(n_fields), offset), offset += sizeof(T)), ...);
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  }

  /// Where a neighbour's partial of a shared node arrives: neighbour k, row s of its message.
  struct Holder {
    std::size_t k, s;
  };
  /// The other ranks holding window node `node`, as (neighbour k, row s of shared_with(k)), in
  /// increasing rank; empty for a node no other window holds.
  [[nodiscard]] std::span<const Holder> holders_of(std::int32_t node) const {
    if (union_of_.empty()) return {};
    const std::int32_t u = union_of_[static_cast<std::size_t>(node)];
    if (u < 0) return {};
    return {holders_.data() + holder_start_[static_cast<std::size_t>(u)],
            holder_start_[static_cast<std::size_t>(u) + 1] - holder_start_[static_cast<std::size_t>(u)]};
  }
  /// Neighbour k's rank (increasing in k) and the window nodes this window shares with it, in the
  /// order both sides list them.
  [[nodiscard]] std::size_t n_neighbours() const { return neighbours_.size(); }
  [[nodiscard]] int neighbour(std::size_t k) const { return neighbours_[k]; }
  [[nodiscard]] const std::vector<std::int32_t>& shared_with(std::size_t k) const { return shared_[k]; }
  /// Messages of sizes the receivers do not know (send[k] to neighbour k; Comm::exchange, a size
  /// round first): e.g. the particles of contact nodes (contact/contact.cpp). Counted in
  /// bytes_sent() and seconds(), and apart in message_bytes_sent().
  [[nodiscard]] Comm::Buffers exchange(const Comm::Buffers& send) {
    const auto started = std::chrono::steady_clock::now();
    for (const auto& b : send) message_bytes_ += static_cast<std::int64_t>(b.size());
    Comm::Buffers recv = comm_.exchange(neighbours_, send);
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    wait_seconds_ += took;
    seconds_ += took;
    return recv;
  }

  /// Bytes this rank has sent in sums and exchange() so far.
  [[nodiscard]] std::int64_t bytes_sent() const { return bytes_sent_ + message_bytes_; }
  /// Of them, the bytes of exchange() messages.
  [[nodiscard]] std::int64_t message_bytes_sent() const { return message_bytes_; }
  /// Seconds this rank has spent in sums so far (packing, exchange, totals).
  [[nodiscard]] double seconds() const { return seconds_; }
  /// Of those, the seconds in the exchange itself (waiting for the neighbours' messages): the
  /// most that overlapping the exchange with other work could hide.
  [[nodiscard]] double wait_seconds() const { return wait_seconds_; }

 private:
  /// values[i] = the sum over the holders of node i, in increasing rank, of their partials
  /// (0 + p_r0 + p_r1 + ..., this rank's own in its place); the partial of array T sits at byte
  /// `offset` of each field's part (`field_bytes` long) of a node's row in the buffers.
  template <class T>
  void combine(std::vector<T>& values, int n_fields, std::size_t field_bytes, std::size_t offset) const {
    const std::size_t row = field_bytes * static_cast<std::size_t>(n_fields);
    T zero;
    if constexpr (std::is_arithmetic_v<T>) zero = T(0);
    else zero = T::Zero();
    auto partial = [&](const Holder& h, std::size_t f) {
      T v;
      std::memcpy(static_cast<void*>(&v), recv_[h.k].data() + h.s * row + f * field_bytes + offset, sizeof(T));
      return v;
    };
    for (std::size_t f = 0; f < static_cast<std::size_t>(n_fields); ++f) {
      T* field = values.data() + f * n_nodes_;
      for (std::size_t u = 0; u < union_.size(); ++u) {
        T total = zero;
        const std::size_t first = holder_start_[u], mine = first + lower_[u], last = holder_start_[u + 1];
        for (std::size_t h = first; h < mine; ++h) total += partial(holders_[h], f);
        T& own = field[union_[u]];
        total += own;
        for (std::size_t h = mine; h < last; ++h) total += partial(holders_[h], f);
        own = total;
      }
    }
  }
  Comm comm_ = Comm::serial();
  int rank_ = 0;
  int margin_ = -1;
  int partitions_ = -1;
  std::size_t n_nodes_ = 0;
  std::vector<int> neighbours_;                     ///< increasing rank
  std::vector<std::vector<std::int32_t>> shared_;   ///< per neighbour: window nodes, canonical order
  std::vector<std::int32_t> union_;                 ///< every shared node of this window, once
  std::vector<std::int32_t> union_of_;              ///< per window node: index into union_ or -1
  std::vector<std::size_t> holder_start_;           ///< per union_ node: its holders_ (CSR)
  std::vector<Holder> holders_;                     ///< the other holders of each, increasing rank
  std::vector<std::size_t> lower_;                  ///< per union_ node: holders below this rank
  Comm::Buffers send_, recv_;                       ///< per neighbour, kept between sums
  std::int64_t bytes_sent_ = 0, message_bytes_ = 0;
  double seconds_ = 0.0, wait_seconds_ = 0.0;
};

}  // namespace cairn
