// When a loop is worth a parallel region.
#pragma once

#include <cstdint>

namespace cairn {

/// Loops of simple per-item work (node loops, per-particle bookkeeping) shorter than this run on
/// the calling thread: handing a few microseconds of work to a team costs more than it saves,
/// above all on a shared machine where a sleeping thread takes tens of microseconds to wake
/// (docs/performance.md, "Threads on a shared machine"). Such loops have no order-dependent
/// sums, so the results are the same either way.
inline constexpr std::int64_t parallel_min_items = 32768;

}  // namespace cairn
