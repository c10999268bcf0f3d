// An empty scratch directory for a test's run output, named after the test and the process.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace cairn::test {

/// <temp>/cairn_test_<name>_<pid>, removed if it exists (the run creates it).
inline std::filesystem::path fresh_dir(const std::string& name) {
  std::filesystem::path d =
      std::filesystem::temp_directory_path() / ("cairn_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  return d;
}

}  // namespace cairn::test
