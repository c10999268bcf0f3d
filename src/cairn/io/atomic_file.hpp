// Crash-safe file writing: every file Cairn's output layer produces is first written to a
// temporary file next to the target and then renamed over it, so a run that is interrupted
// (signal, time limit, exception) never leaves a half-written output file behind. The rename is
// atomic on POSIX file systems; no fsync is done, so a power loss may still lose recent data.
//
// The temporary file is created with O_CREAT | O_EXCL | O_NOFOLLOW under a name with a random
// part, so a symbolic link planted in the output directory cannot redirect the write, and the
// rename replaces a link at the target itself rather than the file it points to. A write that
// fails because the file system is full says "no space left on device".
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "cairn/parallel/comm.hpp"

namespace cairn {

/// Create a new, empty temporary file `<target>.tmp.<pid>.<random>` next to `target` (the same
/// file system, so the final rename is atomic), never following or reusing an existing entry.
/// Throws std::runtime_error naming the directory if it cannot.
[[nodiscard]] std::filesystem::path create_atomic_temp(const std::filesystem::path& target);

/// Call `writer(tmp)` to produce the file at `tmp` (created empty by create_atomic_temp), then
/// rename `tmp` over `target`. Creates the parent directory of `target` if it is missing. If
/// `writer` throws, or the rename fails, the temporary file is removed, `target` is left as it
/// was, and the exception propagates (as a std::runtime_error saying "no space left on device"
/// when the file system is full).
void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& tmp)>& writer);

/// The same for a file written collectively by the ranks of `comm` (parallel HDF5): rank 0
/// creates the temporary file, every rank calls `writer(tmp)`, then rank 0 calls `finish(tmp)`
/// (when given; e.g. a checksum read back from the closed file) and renames it. An error on any
/// rank is thrown on every rank. With one rank: writer then finish, as above.
void write_file_atomically(const std::filesystem::path& target, const Comm& comm,
                           const std::function<void(const std::filesystem::path& tmp)>& writer,
                           const std::function<void(const std::filesystem::path& tmp)>& finish = {});
/// Write `text` verbatim (binary mode, no newline translation) to `target` atomically.
/// Throws std::runtime_error naming the file and the system's reason if it cannot be written.
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

}  // namespace cairn
