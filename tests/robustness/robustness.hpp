// Shared pieces of the hostile-input tests (docs/robustness.md): a small valid input, a fresh
// folder per case and a way to run the `cairn` command and keep its exit code and output.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace cairn::robustness {

namespace fs = std::filesystem;

/// A fresh, empty folder for one case.
inline fs::path case_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("cairn_robustness_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

/// A small valid 2D input: a 10 x 10 grid of 0.1 m cells, one elastic block (line 17 is its
/// [[body]]), about ten steps. Line numbers matter to the tests: append, do not insert.
inline std::string base_input() {
  return "[simulation]\n"                                       // 1
         "dimension = 2\n"                                      // 2
         "end_time = 1e-2\n"                                    // 3
         "\n"                                                   // 4
         "[grid]\n"                                             // 5
         "origin = [0.0, 0.0]\n"                                // 6
         "extent = [1.0, 1.0]\n"                                // 7
         "cell_size = 0.1\n"                                    // 8
         "\n"                                                   // 9
         "[[material]]\n"                                       // 10
         "name = \"steel\"\n"                                   // 11
         "model = \"linear_elastic\"\n"                         // 12
         "density = 1000.0\n"                                   // 13
         "youngs_modulus = 1e6\n"                               // 14
         "poissons_ratio = 0.3\n"                               // 15
         "\n"                                                   // 16
         "[[body]]\n"                                           // 17
         "name = \"block\"\n"                                   // 18
         "material = \"steel\"\n"                               // 19
         "shape = { box = { min = [0.3, 0.3], max = [0.7, 0.7] } }\n"  // 20
         "\n";                                                  // 21
}

struct CliResult {
  int code = -1;       ///< exit status; 128 + N when killed by signal N
  std::string output;  ///< stdout and stderr together
};

/// Run `[env] cairn <args>` in `dir` with one OpenMP thread; output goes to dir/log.txt.
inline CliResult cairn(const std::string& args, const fs::path& dir, const std::string& env = "") {
  const fs::path log = dir / "log.txt";
  const std::string cmd = "cd '" + dir.string() + "' && OMP_NUM_THREADS=1 " + env + " '" +
                          std::string(CAIRN_BINARY) + "' " + args + " > '" + log.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.output = read_text(log);
  return r;
}

/// Write `text` as dir/case.toml and run `cairn <command> case.toml <extra>`.
inline CliResult cairn_on(const std::string& command, const std::string& text, const fs::path& dir,
                          const std::string& extra = "", const std::string& env = "") {
  write_text(dir / "case.toml", text);
  return cairn(command + " case.toml " + extra, dir, env);
}

/// An input error: exit 2, and the message names `where` ("case.toml:20"), `key`, what was
/// expected and what was found.
inline ::testing::AssertionResult input_error(const CliResult& r, const std::string& where, const std::string& key) {
  if (r.code != 2) return ::testing::AssertionFailure() << "exit " << r.code << ", output:\n" << r.output;
  if (r.output.find(where) == std::string::npos)
    return ::testing::AssertionFailure() << "no '" << where << "' in:\n" << r.output;
  if (r.output.find("key '" + key + "'") == std::string::npos)
    return ::testing::AssertionFailure() << "no key '" << key << "' in:\n" << r.output;
  if (r.output.find("expected") == std::string::npos || r.output.find("found") == std::string::npos)
    return ::testing::AssertionFailure() << "no 'expected ...; found ...' in:\n" << r.output;
  return ::testing::AssertionSuccess();
}

}  // namespace cairn::robustness
