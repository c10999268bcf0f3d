#include "cairn/util/parallel.hpp"

#include <omp.h>

#include <tuple>

namespace cairn {

namespace {
/// Chunks per thread's share: a claim is a compare-and-swap on the thread's own cache line,
/// some 20 ns against a chunk's microseconds of particle work.
constexpr std::int64_t chunks_per_thread = 64;

std::uint64_t pack(std::int64_t front, std::int64_t back) {
  return static_cast<std::uint64_t>(front) | (static_cast<std::uint64_t>(back) << 32);
}
}  // namespace

StealingShare::StealingShare(std::int64_t n) : n_(n), team_(omp_get_max_threads()) {
  // Serial, a team beyond the slots, or a range too long to pack: static ranges.
  stealing_ = team_ >= 2 && team_ <= max_team && n < (std::int64_t{1} << 32);
  if (!stealing_) return;
  chunk_ = std::clamp<std::int64_t>(n / (team_ * chunks_per_thread), 16, 1024);
  for (int t = 0; t < team_; ++t) {
    const auto [first, last] = static_range(n, t, team_);
    slots_[t].range.store(pack(first, last), std::memory_order_relaxed);
  }
}

StealingShare::Cursor StealingShare::cursor() {
  Cursor c;
  c.t_ = omp_get_thread_num();
  c.T_ = omp_get_num_threads();
  if (c.T_ == team_ && stealing_) {
    c.share_ = this;
  } else {
    std::tie(c.first_, c.last_) = static_range(n_, c.t_, c.T_);
  }
  return c;
}

bool StealingShare::Cursor::next(std::int64_t& first, std::int64_t& last) {
  if (!share_) {  // static: the one range, once
    first = first_, last = last_;
    first_ = last_;
    return first < last;
  }
  for (; k_ < T_; ++k_) {  // own range (k = 0) from the front, then the others' from the back
    const auto [f, l] = share_->take((t_ + k_) % T_, k_ == 0);
    if (f < l) {
      first = f, last = l;
      return true;
    }
  }
  return false;
}

std::pair<std::int64_t, std::int64_t> StealingShare::take(int u, bool front) {
  std::atomic<std::uint64_t>& range = slots_[u].range;
  std::uint64_t now = range.load(std::memory_order_relaxed);
  for (;;) {
    const auto f = static_cast<std::int64_t>(now & 0xffffffffu), b = static_cast<std::int64_t>(now >> 32);
    if (f >= b) return {0, 0};
    const std::int64_t f2 = front ? std::min(b, f + chunk_) : f, b2 = front ? b : std::max(f, b - chunk_);
    if (range.compare_exchange_weak(now, pack(f2, b2), std::memory_order_acq_rel, std::memory_order_relaxed))
      return front ? std::pair{f, f2} : std::pair{b2, b};
  }
}

}  // namespace cairn
