// Crash-safe file writing: every file Cairn's output layer produces is first written to a
// temporary file next to the target and then renamed over it, so a run that is interrupted
// (signal, time limit, exception) never leaves a half-written output file behind. The rename is
// atomic on POSIX file systems; no fsync is done, so a power loss may still lose recent data.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace cairn {

/// Name of the temporary file used while writing `target`: `<target>.tmp.<pid>` in the same
/// directory (the same file system, so the final rename is atomic).
[[nodiscard]] std::filesystem::path atomic_temp_path(const std::filesystem::path& target);

/// Call `writer(tmp)` to produce the file at `tmp`, then rename `tmp` over `target`. Creates the
/// parent directory of `target` if it is missing. If `writer` throws, or the rename fails, the
/// temporary file is removed, `target` is left as it was, and the exception propagates.
void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& tmp)>& writer);

/// Write `text` verbatim (binary mode, no newline translation) to `target` atomically.
/// Throws std::runtime_error naming the file if it cannot be written.
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

}  // namespace cairn
