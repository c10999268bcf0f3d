// What the standalone drivers of the file fuzz targets share (fuzz_checkpoint.cpp,
// fuzz_geometry.cpp): a scratch folder, file helpers, the input in flight for the crash handler,
// and the timed loop over mutated inputs that saves each different finding.
#pragma once

#include <algorithm>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <unistd.h>

namespace fuzz {

namespace fs = std::filesystem;

inline fs::path scratch;         // this process's folder: the file under test, the findings
inline std::string crash_path;   // scratch/crash.bin, for the signal handler
inline std::string current;      // the input in flight
inline const char* driver = "fuzz";

inline std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void spill(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// Create the scratch folder /tmp/cairn-<name>-XXXXXX.
inline void make_scratch(const char* name) {
  driver = name;
  std::string tmpl = (fs::temp_directory_path() / (std::string("cairn-") + name + "-XXXXXX")).string();
  if (::mkdtemp(tmpl.data()) == nullptr) {
    std::perror("mkdtemp");
    std::exit(2);
  }
  scratch = tmpl;
  crash_path = (scratch / "crash.bin").string();
}

/// At most `bytes` of address space for this process (not under AddressSanitizer, which reserves
/// far more for its shadow memory): a reader that sizes its arrays by a damaged count then gets
/// std::bad_alloc at once instead of taking the machine's memory.
#if defined(__SANITIZE_ADDRESS__)
#define CAIRN_FUZZ_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CAIRN_FUZZ_ASAN 1
#endif
#endif
inline void limit_memory(std::size_t bytes) {
#ifndef CAIRN_FUZZ_ASAN
  const rlimit limit{bytes, bytes};
  ::setrlimit(RLIMIT_AS, &limit);
#else
  (void)bytes;
#endif
}

/// Whether an input error's text says that the reader ran out of memory: an allocation the
/// file's size does not justify (a damaged count) is a finding even when the reader turns it
/// into an input error.
inline bool out_of_memory(const std::string& text) {
  // Outside the quoted parts: a message quotes the file's own text, which may say anything.
  std::string own;
  bool quoted = false;
  for (char c : text) {
    if (c == '\'') quoted = !quoted;
    else if (!quoted) own += c;
  }
  return own.find("std::bad_alloc") != std::string::npos || own.find("bad_array_new_length") != std::string::npos ||
         own.find("vector::_M_default_append") != std::string::npos ||
         own.find("cannot create std::vector larger than max_size()") != std::string::npos;
}

/// A finding's message without its numbers and quoted names, to tell different findings apart.
inline std::string kind_of(const std::string& what) {
  std::string k;
  bool quoted = false;
  for (char c : what) {
    if (c == '\'') quoted = !quoted;
    else if (!quoted && !std::isdigit(static_cast<unsigned char>(c))) k += c;
  }
  return k.substr(0, 120);
}

extern "C" inline void on_crash(int sig) {
  const int fd = ::open(crash_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd >= 0) {
    ssize_t ignored = ::write(fd, current.data(), current.size());
    (void)ignored;
    ::close(fd);
  }
  const char head[] = "\ncrashed (signal); the input is in ";
  ssize_t ignored = ::write(2, driver, std::char_traits<char>::length(driver));
  ignored = ::write(2, head, sizeof head - 1);
  ignored = ::write(2, crash_path.data(), crash_path.size());
  ignored = ::write(2, "\n", 1);
  (void)ignored;
  ::_exit(128 + sig);
}

/// A crash saves the input in flight as scratch/crash.bin.
inline void catch_crashes() {
  for (int sig : {SIGSEGV, SIGABRT, SIGFPE, SIGBUS, SIGILL}) std::signal(sig, on_crash);
}

/// Saves findings as scratch/finding-<n>.bin and says so.
struct Findings {
  long long count = 0;
  void report(const std::string& name, const std::string& what) {
    const fs::path saved = scratch / ("finding-" + std::to_string(count++) + ".bin");
    spill(saved, current);
    std::fprintf(stderr, "%s: %s gives %s\n  (the input is in %s)\n", driver, name.c_str(), what.c_str(), saved.c_str());
  }
};

struct Campaign {
  long long inputs = 0, accepted = 0, slowest_ms = 0;
  double seconds = 0.0;
  int findings = 0;  // different ones
};

/// Exercise next() for `max_inputs` inputs (negative: no limit) or `seconds`, whichever ends
/// first: `exercise` returns 1 (accepted), 0 (refused cleanly) or -1 (a finding, described in
/// `what`); an input over 10 s is a hang. Stops at the first finding, or with keep_going > 0
/// after that many different ones. ctest gives a number of inputs (and a time far beyond it), so
/// that every machine runs the same inputs and a finding the campaign can reach shows on all of
/// them, not only on a fast one.
inline Campaign run_campaign(double seconds, long long max_inputs, int keep_going, std::uint64_t seed,
                             const std::function<std::string()>& next,
                             const std::function<int(const std::string&, std::string&)>& exercise, Findings& findings) {
  Campaign c;
  std::set<std::string> kinds;
  std::string what;
  const auto start = std::chrono::steady_clock::now();
  for (;; ++c.inputs) {
    if (max_inputs >= 0 && c.inputs >= max_inputs) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > seconds) break;
    current = next();
    const auto t0 = std::chrono::steady_clock::now();
    const int outcome = exercise(current, what);
    c.accepted += outcome == 1;
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count();
    if (outcome >= 0 && ms > 10000) {
      if (outcome == 1) --c.accepted;
      what = "a hang: " + std::to_string(ms) + " ms";
    }
    if (outcome < 0 || ms > 10000) {
      if (kinds.insert(kind_of(what)).second)
        findings.report("input " + std::to_string(c.inputs) + " (seed " + std::to_string(seed) + ")", what);
      if (static_cast<int>(kinds.size()) > keep_going) break;
      continue;
    }
    c.slowest_ms = std::max<long long>(c.slowest_ms, ms);
  }
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  c.findings = static_cast<int>(kinds.size());
  return c;
}

}  // namespace fuzz
