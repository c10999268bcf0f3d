// When a loop is worth a parallel region.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <utility>

namespace cairn {

/// Loops of simple per-item work (grid conditions, per-particle bookkeeping) shorter than this run on
/// the calling thread: handing a few microseconds of work to a team costs more than it saves,
/// above all on a shared machine where a sleeping thread takes tens of microseconds to wake
/// (docs/performance.md, "Threads on a shared machine"). Such loops have no order-dependent
/// sums, so the results are the same either way.
inline constexpr std::int64_t parallel_min_items = 32768;

/// Loops over every node of the grid (transfer.hpp, for_each_node) run in parallel from this many
/// nodes. They sit between particle loops whose team is still spinning, so the region costs
/// about a microsecond, and a serial node loop of a few thousand nodes kept the other thread
/// idle for 10-20 us of every step (problem (a) of issue 13: 2 threads 1.02x faster with 4096
/// than with parallel_min_items; docs/performance.md, "Threads").
inline constexpr std::int64_t node_loop_min = 4096;

/// A range [first, last) of node slots (storage indices) for a node loop (transfer.hpp,
/// for_each_node).
struct SlotRange {
  std::int32_t first = 0, last = 0;
};

/// Particle affinity. Every particle stage of a step (stencil build, gathers, scatters) gives a
/// particle to the same thread while the particles are few enough for their data to stay in the
/// cores' caches: thread t of T takes the particles of static_range(n, t, T) in the loops over
/// particles, and in a scatter the blocks around its share of each colour's particles, the
/// blocks taken in particle order (transfer/transfer.hpp).
/// Data one core wrote and another reads next moves between the cores' caches, which on the
/// development VM made the CPDI stencil build 25 % slower per particle on 2 threads than on one
/// (docs/performance.md, "Threads"). Beyond this count the data streams from memory anyway and
/// the loops hand out work dynamically, which keeps a team going when one of its cores is busy
/// with another process.
inline constexpr std::int64_t affinity_max_particles = 1 << 18;

/// Per-particle loops outside the transfers (block binning, the time-step maxima) run in
/// parallel from this many particles, each thread over its static_range: on one thread they
/// would read every particle's data, half of which the other cores have just written.
inline constexpr std::int64_t particle_loop_min = 4096;

/// Thread t's contiguous share [first, second) of [0, n) among T threads (the first n % T threads
/// take one more).
inline std::pair<std::int64_t, std::int64_t> static_range(std::int64_t n, int t, int T) {
  const std::int64_t q = n / T, r = n % T;
  const std::int64_t begin = t * q + std::min<std::int64_t>(t, r);
  return {begin, begin + q + (t < r ? 1 : 0)};
}

/// Particle affinity with stealing. Each thread works through its static_range in chunks from the
/// front; a thread that has finished its own range takes chunks from the back of the others'
/// unfinished ranges. A thread keeps nearly all of its particles, and the team still finishes
/// together when one core is slowed (the development VM's cores are, often for seconds;
/// docs/performance.md, "Threads"). Which thread does an item never changes a result: the loops
/// that use it work particle by particle and reduce with max, min or exact sums.
/// Made before the parallel region (for a team of omp_get_max_threads() threads, at most
/// max_team; larger teams take plain static ranges); every thread of the region takes its
/// cursor(). It lives on the caller's stack: a loop allocates nothing. Out of line
/// (util/parallel.cpp): inlined, its code tipped GCC's inlining budget in the particle update,
/// which then ran 9 % slower on one thread.
class StealingShare {
 public:
  explicit StealingShare(std::int64_t n);

  /// One thread's walk through the items: next() gives its next range [first, last) until it
  /// returns false. The ranges of all threads are disjoint and together cover [0, n).
  class Cursor {
   public:
    bool next(std::int64_t& first, std::int64_t& last);

   private:
    friend class StealingShare;
    StealingShare* share_ = nullptr;  // null: a static range
    int t_ = 0, T_ = 1, k_ = 0;
    std::int64_t first_ = 0, last_ = 0;
  };

  /// The calling thread's cursor (inside the region). A team other than the one made for (nested,
  /// or an if clause) gets the static ranges.
  Cursor cursor();

 private:
  struct alignas(64) Slot {
    std::atomic<std::uint64_t> range{0};  // [front, back) of what is left, packed
  };
  /// A chunk from the front (the owner) or the back (a thief) of thread u's range; empty when
  /// nothing is left.
  std::pair<std::int64_t, std::int64_t> take(int u, bool front);

  static constexpr int max_team = 64;
  std::int64_t n_;
  int team_;
  bool stealing_ = false;  // a team of 2 .. max_team and n below 2^32
  std::int64_t chunk_ = 0;
  std::array<Slot, max_team> slots_;
};

}  // namespace cairn
