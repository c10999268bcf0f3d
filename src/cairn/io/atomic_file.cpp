#include "cairn/io/atomic_file.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>
#include <system_error>

namespace cairn {

namespace fs = std::filesystem;

fs::path atomic_temp_path(const fs::path& target) {
  fs::path tmp = target;
  tmp += ".tmp." + std::to_string(static_cast<long long>(::getpid()));
  return tmp;
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
  const fs::path tmp = atomic_temp_path(target);
  auto discard_tmp = [&tmp] {
    std::error_code ignored;
    fs::remove(tmp, ignored);
  };
  try {
    writer(tmp);
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

void write_text_atomically(const fs::path& target, const std::string& text) {
  write_file_atomically(target, [&text, &target](const fs::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot open '" + tmp.string() + "' for writing (output file '" + target.string() + "')");
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.close();
    if (!out) throw std::runtime_error("error while writing '" + target.string() + "'");
  });
}

}  // namespace cairn
