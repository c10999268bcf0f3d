#include "cairn/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <random>
#include <stdexcept>
#include <system_error>

namespace cairn {

namespace fs = std::filesystem;

namespace {

/// The system's reason for errno `e`, lower-case for a full disk so that messages read
/// "...: no space left on device".
std::string reason(int e) {
  if (e == ENOSPC) return "no space left on device";
  if (e == EDQUOT) return "disk quota exceeded";
  return std::strerror(e);
}

/// True when the file system holding `dir` has no block left for an unprivileged writer.
bool file_system_full(const fs::path& dir) {
  struct statvfs st {};
  return ::statvfs(dir.empty() ? "." : dir.c_str(), &st) == 0 && st.f_bavail == 0;
}

}  // namespace

fs::path create_atomic_temp(const fs::path& target) {
  std::random_device entropy;
  const std::string stem = target.string() + ".tmp." + std::to_string(static_cast<long long>(::getpid())) + ".";
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path tmp = stem + std::to_string(entropy() % 1000000000u);
    // O_EXCL: fails on any existing entry, a symbolic link (even a dangling one) included.
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return tmp;
    }
    if (errno != EEXIST) {
      const int e = errno;
      throw std::runtime_error("cannot create a temporary file next to '" + target.string() + "': " + reason(e));
    }
  }
  throw std::runtime_error("cannot create a temporary file next to '" + target.string() +
                           "': 100 random names were all taken");
}

void write_file_atomically(const fs::path& target,
                           const std::function<void(const fs::path& tmp)>& writer) {
  const fs::path parent = target.parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    fs::create_directories(parent, ec);
    if (ec) {
      throw std::runtime_error("cannot create directory '" + parent.string() +
                               "' for output file '" + target.string() + "': " + ec.message());
    }
  }
  const fs::path tmp = create_atomic_temp(target);
  auto discard_tmp = [&tmp] {
    std::error_code ignored;
    fs::remove(tmp, ignored);
  };
  errno = 0;
  try {
    writer(tmp);
  } catch (const std::runtime_error& e) {
    // Libraries (HDF5) report a failed write without errno; a full disk is worth saying.
    // Besides a full disk, the errors of the device or file system itself are worth saying
    // (other errno values may be left over from a library's harmless probing).
    const int err = errno;
    const bool full = err == ENOSPC || err == EDQUOT || file_system_full(parent);
    const bool device = err == EIO || err == EROFS || err == EFBIG;
    discard_tmp();
    if (!full && !device) throw;
    const std::string why = reason(full ? (err == EDQUOT ? EDQUOT : ENOSPC) : err);
    if (std::string(e.what()).find(why) != std::string::npos) throw;
    throw std::runtime_error("cannot write '" + target.string() + "': " + why + " (" + e.what() + ")");
  } catch (...) {
    discard_tmp();
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    discard_tmp();
    throw std::runtime_error("cannot rename '" + tmp.string() + "' to '" + target.string() +
                             "': " + ec.message());
  }
}

void write_file_atomically(const fs::path& target, const Comm& comm,
                           const std::function<void(const fs::path& tmp)>& writer,
                           const std::function<void(const fs::path& tmp)>& finish) {
  if (!comm.parallel()) {
    write_file_atomically(target, [&](const fs::path& tmp) {
      writer(tmp);
      if (finish) finish(tmp);
    });
    return;
  }
  // Rank 0 names the temporary file; every rank writes its part; rank 0 finishes and renames.
  std::string tmp_name, error;
  if (comm.is_root()) {
    try {
      const fs::path parent = target.parent_path();
      std::error_code ec;
      if (!parent.empty()) fs::create_directories(parent, ec);
      tmp_name = create_atomic_temp(target).string();
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  comm.broadcast(error, 0);
  if (!error.empty()) throw std::runtime_error(error);
  comm.broadcast(tmp_name, 0);
  const fs::path tmp(tmp_name);
  auto agree = [&](const std::string& mine) {
    // The first rank with an error says what it is; every rank throws it.
    const std::int64_t first = comm.min(mine.empty() ? std::int64_t{comm.size()} : std::int64_t{comm.rank()});
    if (first == comm.size()) return;
    std::string message = mine;
    comm.broadcast(message, static_cast<int>(first));
    if (comm.is_root()) {
      std::error_code ignored;
      fs::remove(tmp, ignored);
    }
    throw std::runtime_error(message);
  };
  try {
    writer(tmp);
  } catch (const std::exception& e) {
    error = e.what();
  }
  agree(error);
  if (comm.is_root()) {
    try {
      if (finish) finish(tmp);
      std::error_code ec;
      fs::rename(tmp, target, ec);
      if (ec) error = "cannot rename '" + tmp.string() + "' to '" + target.string() + "': " + ec.message();
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  agree(error);
}

void write_text_atomically(const fs::path& target, const std::string& text) {
  write_file_atomically(target, [&text, &target](const fs::path& tmp) {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_TRUNC | O_NOFOLLOW | O_CLOEXEC);
    if (fd < 0) {
      const int e = errno;
      throw std::runtime_error("cannot open '" + tmp.string() + "' for writing (output file '" +
                               target.string() + "'): " + reason(e));
    }
    const char* data = text.data();
    std::size_t left = text.size();
    while (left > 0) {
      const ssize_t wrote = ::write(fd, data, left);
      if (wrote < 0 && errno == EINTR) continue;
      if (wrote <= 0) {
        const int e = wrote < 0 ? errno : ENOSPC;
        ::close(fd);
        errno = e;
        throw std::runtime_error("error while writing '" + target.string() + "': " + reason(e));
      }
      data += wrote;
      left -= static_cast<std::size_t>(wrote);
    }
    if (::close(fd) != 0) {
      const int e = errno;
      errno = e;
      throw std::runtime_error("error while writing '" + target.string() + "': " + reason(e));
    }
  });
}

}  // namespace cairn
