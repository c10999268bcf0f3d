// Reading a file from outside in a child process: a third-party reader that crashes or hangs on a
// damaged file (Gmsh 4.8 on an element with an undefined node, HDF5 1.10 on a corrupt global
// heap) ends the child, not the run, and the caller reports an input error
// (docs/robustness.md, "Files from outside").
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <string>

namespace cairn {

/// How a child process ended.
struct ChildResult {
  bool timed_out = false;  ///< killed after the time limit
  int signal = 0;          ///< the signal that ended it (0: it exited)
  int exit_code = 0;       ///< its exit code when it exited
  std::string output;      ///< what `work` put in its `out`
  /// What the child wrote to its standard error (its last child_errors_kept bytes): a crash
  /// inside a library prints there ("free(): invalid next size (fast)" from glibc when Gmsh
  /// corrupts its heap on a damaged mesh), and the caller's message, not that line, is what the
  /// user should see first. Empty in sanitizer builds, whose children keep the standard error
  /// so that their reports stay visible.
  std::string errors;
};

/// How much of a child's standard error ChildResult::errors keeps (the end of it).
inline constexpr std::size_t child_errors_kept = 4096;

/// Whether run_in_child keeps its children's standard error in ChildResult::errors (false in
/// sanitizer builds, whose children write to the process's standard error).
bool child_errors_captured();

/// Run `work` in a forked child and wait for it at most `timeout_seconds`: the child's exit code
/// is what `work` returns (an exception leaving it: 125), and `out` comes back as output. Only
/// the calling thread runs in the child, with the default action for SIGSEGV, SIGBUS, SIGFPE,
/// SIGILL and SIGABRT, and leaves by _exit (no atexit handlers, no leak check). A sanitizer may
/// still catch a fault and exit with its own code: callers treat any exit code but the ones
/// `work` returns as a crash. Throws std::runtime_error when no process can be started.
ChildResult run_in_child(const std::function<int(std::string& out)>& work, int timeout_seconds);

/// The time a child reading a file of `bytes` bytes with HDF5 may take: 5 s and 1 s per 10 MB.
/// A reading is linear in the file's size, and far faster than that (a 1 MB checkpoint is read
/// and hashed in milliseconds); HDF5 1.10 loops without end on some damaged global heaps (found
/// by cairn_fuzz_checkpoint), and such a file is refused in seconds rather than minutes.
inline int hdf5_reading_seconds(double bytes) {
  return 5 + static_cast<int>(std::min(std::max(bytes, 0.0), 1.0e12) / 1.0e7);
}

/// How a child that failed ended, for a message: "it did not finish in T s", "signal S" or
/// "exit code E", followed by child_said.
std::string child_ending(const ChildResult& result, int timeout_seconds);

/// The last line the child wrote to its standard error, as `; it printed "..."` (at most 200
/// characters of it), or nothing when it wrote none.
std::string child_said(const ChildResult& result);

/// A child's answer as packed binary values: the child appends them (put), the parent reads
/// them back in the same order (take).
inline void put_bytes(std::string& out, const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); }

class AnswerReader {
 public:
  explicit AnswerReader(const std::string& answer, std::size_t at = 0) : answer_(answer), at_(at) {}
  /// Copies the next n bytes to p; false (nothing copied) when fewer are left.
  [[nodiscard]] bool take(void* p, std::size_t n);
  /// The answer from the current position on.
  [[nodiscard]] std::string rest() const { return answer_.substr(at_); }

 private:
  const std::string& answer_;
  std::size_t at_;
};

/// In a child: at most `bytes` more address space than the process has now (RLIMIT_AS), so that
/// an allocation sized by a damaged count fails (std::bad_alloc) instead of taking the machine's
/// memory. Under AddressSanitizer, whose own reservations are far larger, it does nothing (the
/// sanitizer reports such allocations itself).
void limit_address_space(double bytes);

}  // namespace cairn
