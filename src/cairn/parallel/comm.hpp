// The ranks a run is distributed over (docs/parallel.md): a thin layer over the few MPI calls
// Cairn makes, with a serial fallback so that the rest of the code calls it unconditionally.
//
// Built without MPI (CMake CAIRN_MPI=OFF), or with MPI when MPI has not been initialised (the
// unit tests, library users), every Comm is one rank: reductions return their argument and
// exchanges return nothing. Comm is a small value type; it owns no MPI resource (it refers to
// MPI_COMM_WORLD), so copies are free and no global state is kept.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#ifdef CAIRN_HAVE_MPI
#include <mpi.h>
#endif

namespace cairn {

class Comm {
 public:
  /// All ranks of the run: MPI_COMM_WORLD when MPI is initialised, else a single rank.
  static Comm world();
  /// A single rank (serial code paths, tests).
  static Comm serial() { return Comm(); }

  [[nodiscard]] int rank() const { return rank_; }
  [[nodiscard]] int size() const { return size_; }
  [[nodiscard]] bool parallel() const { return size_ > 1; }
  [[nodiscard]] bool is_root() const { return rank_ == 0; }

  void barrier() const;
  /// Element-wise reductions over all ranks, in place (every rank gets the result).
  void sum(std::int64_t* values, int n) const;
  void max(double* values, int n) const;
  void max(std::int64_t* values, int n) const;
  void min(std::int64_t* values, int n) const;
  [[nodiscard]] std::int64_t sum(std::int64_t v) const {
    sum(&v, 1);
    return v;
  }
  [[nodiscard]] double max(double v) const {
    max(&v, 1);
    return v;
  }
  [[nodiscard]] std::int64_t max(std::int64_t v) const {
    max(&v, 1);
    return v;
  }
  [[nodiscard]] std::int64_t min(std::int64_t v) const {
    min(&v, 1);
    return v;
  }
  /// True on every rank when `v` is true on any rank.
  [[nodiscard]] bool any(bool v) const { return max(static_cast<std::int64_t>(v)) != 0; }
  /// Sum of `v` over the ranks below this one.
  [[nodiscard]] std::int64_t exclusive_prefix(std::int64_t v) const;
  /// `v` of every rank, indexed by rank.
  [[nodiscard]] std::vector<std::int64_t> all_gather(std::int64_t v) const;
  /// Copy `bytes` bytes at `data` from rank `root` to every rank.
  void broadcast(void* data, std::size_t bytes, int root) const;
  void broadcast(std::string& text, int root) const;

  /// Byte buffers to send: one per destination.
  using Buffers = std::vector<std::vector<char>>;
  /// Point-to-point exchange with a symmetric neighbour list (b is in a's list iff a is in b's):
  /// send[k] goes to neighbours[k]; returns what neighbours[k] sent, in the same order.
  [[nodiscard]] Buffers exchange(const std::vector<int>& neighbours, const Buffers& send) const;
  /// The same with sizes both sides know: recv[k] arrives sized for what neighbours[k] sends
  /// (one round of messages, no size exchange).
  void exchange_sized(const std::vector<int>& neighbours, const Buffers& send, Buffers& recv) const;
  /// Every rank to every rank: send[r] goes to rank r (size() buffers); returns recv[r] from r.
  [[nodiscard]] Buffers all_to_all(const Buffers& send) const;

  /// Stop every rank with exit code `code` (an error that cannot be handled collectively).
  [[noreturn]] void abort(int code) const;

#ifdef CAIRN_HAVE_MPI
  /// The MPI communicator (MPI_COMM_NULL for a serial Comm); for parallel HDF5.
  [[nodiscard]] MPI_Comm handle() const { return parallel() ? MPI_COMM_WORLD : MPI_COMM_NULL; }
#endif

 private:
  Comm() = default;
  int rank_ = 0;
  int size_ = 1;
};

/// Whether this build can distribute runs (CMake CAIRN_MPI).
[[nodiscard]] bool built_with_mpi();

/// MPI for the lifetime of the object (the `cairn` command): initialises MPI (threads funnelled
/// to the main thread, OpenMP runs inside each rank) and finalises it on destruction. A no-op
/// without MPI.
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

}  // namespace cairn
