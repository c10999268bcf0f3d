#include "cairn/run/watchdog.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <thread>
#include <vector>

#include "cairn/parallel/comm.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double unix_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

/// One rank's file: its last completed step, when its watchdog last wrote (alive), and when that
/// step completed.
struct RankBeat {
  bool found = false;
  long long step = 0;
  double alive = 0.0, stepped = 0.0;
};

RankBeat read_beat(const fs::path& file) {
  RankBeat b;
  std::ifstream in(file);
  b.found = static_cast<bool>(in >> b.step >> b.alive >> b.stepped);
  return b;
}

/// "1", "1 and 3", "1, 3 and 4".
std::string rank_list(const std::vector<int>& ranks) {
  if (ranks.size() == 1) return fmt::format("rank {}", ranks[0]);
  return fmt::format("ranks {} and {}", fmt::join(ranks.begin(), ranks.end() - 1, ", "), ranks.back());
}

/// A file not rewritten for this long belongs to a rank whose process does not run (its
/// watchdog writes every `period` seconds); clocks of different nodes may differ by a little.
double stale_after(double period) { return 3.0 * period + 2.0; }

}  // namespace

StallWatchdog::StallWatchdog(const Comm& comm, double timeout_s, fs::path output_directory)
    : rank_(comm.rank()), size_(comm.size()), timeout_(timeout_s), folder_(std::move(output_directory) / ".ranks") {
  if (!comm.parallel() || timeout_s <= 0.0) return;
  std::error_code ec;
  fs::create_directories(folder_, ec);
  last_beat_ = steady_seconds();
  write_own_file(0, unix_seconds());
  thread_ = std::thread([this] { watch(); });
}

StallWatchdog::~StallWatchdog() {
  if (!thread_.joinable()) return;
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
  std::error_code ec;
  fs::remove(folder_ / fmt::format("rank-{}", rank_), ec);
  fs::remove(folder_, ec);  // only the last rank to finish finds it empty
}

void StallWatchdog::beat(long long step) {
  if (!thread_.joinable()) return;
  const std::lock_guard lock(mutex_);
  step_ = step;
  last_beat_ = steady_seconds();
}

void StallWatchdog::write_own_file(long long step, double stepped_unix) const {
  // Written whole and renamed, so that a reader never sees half a line.
  const fs::path file = folder_ / fmt::format("rank-{}", rank_);
  const fs::path tmp = folder_ / fmt::format(".rank-{}.tmp", rank_);
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << fmt::format("{} {:.3f} {:.3f}\n", step, unix_seconds(), stepped_unix);
    if (!out) return;  // a full or read-only disk: the watchdog still stops the run, unnamed
  }
  std::error_code ec;
  fs::rename(tmp, file, ec);
}

double StallWatchdog::write_period() const {
  // Once a second, a quarter of the timeout when that is shorter; beyond 100 ranks less often,
  // so that the files cost a shared file system's metadata server at most ~100 writes a second.
  return std::clamp(timeout_ / 4.0, 0.05, std::max(1.0, size_ / 100.0));
}

void StallWatchdog::watch() {
  const double period = write_period();
  std::unique_lock lock(mutex_);
  while (!stop_) {
    wake_.wait_for(lock, std::chrono::duration<double>(period));
    if (stop_) break;
    const long long step = step_;
    const double waited = steady_seconds() - last_beat_;
    lock.unlock();
    write_own_file(step, unix_seconds() - waited);
    if (waited > timeout_) {
      const std::string message = diagnosis(step, waited);
      if (!message.empty()) {
        std::fputs(message.c_str(), stderr);
        std::fflush(stderr);
      }
      // The main thread is blocked in an exchange: end the process; the launcher stops the rest.
      std::_Exit(1);
    }
    lock.lock();
  }
}

std::string StallWatchdog::diagnosis(long long step, double waited) const {
  const double period = write_period();
  const double stepped = unix_seconds() - waited;
  const auto file_of = [this](int r) { return folder_ / fmt::format("rank-{}", r); };
  // A rank counts as alive only once its file changes while this one waits: a file that merely
  // looks recent can belong to a rank stopped a moment ago (its stamp is younger than the stale
  // limit when the timeout is short). A rank whose file is already stale, or that stays
  // unchanged for two periods and a second, is silent. Comparing stamps of one rank with each
  // other, not with this node's clock, keeps the test free of clock skew between nodes.
  std::vector<RankBeat> first(static_cast<std::size_t>(size_)), beats(first.size());
  std::vector<char> decided(first.size(), 0);
  const double start = unix_seconds();
  for (int r = 0; r < size_; ++r) {
    if (r == rank_) {
      decided[r] = 1;
      continue;
    }
    first[r] = beats[r] = read_beat(file_of(r));
    if (first[r].found && start - first[r].alive > stale_after(period)) decided[r] = 1;
  }
  const double patience = 2.0 * period + 1.0;
  const double begun = steady_seconds();
  double written = begun;
  while (std::find(decided.begin(), decided.end(), 0) != decided.end() && steady_seconds() - begun < patience) {
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(0.1, period / 4.0)));
    if (steady_seconds() - written >= period) {  // the other ranks wait on this one's file too
      write_own_file(step, stepped);
      written = steady_seconds();
    }
    for (int r = 0; r < size_; ++r) {
      if (decided[r]) continue;
      const RankBeat b = read_beat(file_of(r));
      if (b.found && (!first[r].found || b.alive != first[r].alive)) {
        beats[r] = b;
        decided[r] = 2;  // wrote again: alive
      }
    }
  }
  const double now = unix_seconds();
  std::vector<int> silent, alive;
  for (int r = 0; r < size_; ++r) {
    if (r == rank_) beats[r] = RankBeat{true, step, now, stepped};
    (r == rank_ || decided[r] == 2 ? alive : silent).push_back(r);
  }
  // One message: from the lowest-numbered rank that still runs (the others end quietly).
  if (alive.empty() || alive.front() != rank_) return {};
  const std::string tail =
      fmt::format("rank {} waited {:.0f} s for a step to complete (simulation.mpi_timeout = {:g} s) and stops the run; "
                  "the outputs and checkpoints written so far are complete\n",
                  rank_, waited, timeout_);
  if (!silent.empty()) {
    std::string what;
    for (const int r : silent) {
      what += beats[r].found ? fmt::format("; rank {}: no sign of life for {:.0f} s, last completed step {}", r,
                                           now - beats[r].alive, beats[r].step)
                             : fmt::format("; rank {}: never reported", r);
    }
    return fmt::format("cairn: error: {} stopped answering (stopped by a signal, hung in the system or lost with "
                       "its node){}; {}",
                       rank_list(silent), what, tail);
  }
  long long lowest = std::numeric_limits<long long>::max();
  for (const int r : alive) lowest = std::min(lowest, beats[r].step);
  std::vector<int> behind;
  for (const int r : alive)
    if (beats[r].step == lowest) behind.push_back(r);
  if (behind.size() < alive.size())
    return fmt::format("cairn: error: {} stopped in step {} (the others completed it; hung or in an endless loop); {}",
                       rank_list(behind), lowest + 1, tail);
  return fmt::format("cairn: error: no rank completed step {} for {:.0f} s: every rank still runs, so one is hung "
                     "inside the step (a deadlock or an endless loop); {}",
                     lowest + 1, waited, tail);
}

FaultInjection::FaultInjection(const Comm& comm) {
  const char* spec = std::getenv("CAIRN_FAULT");
  if (spec == nullptr) return;
  char kind[16] = {};
  int rank = -1;
  long long step = -1;
  if (std::sscanf(spec, "%15[a-z]:%d:%lld", kind, &rank, &step) != 3 || rank != comm.rank()) return;
  kind_ = kind;
  step_ = step;
}

void FaultInjection::fire() const {
  if (kind_ == "alloc") {
    std::vector<std::vector<char>> hoard;
    for (;;) hoard.emplace_back(std::size_t{1} << 28, '\1');  // until std::bad_alloc
  }
  throw std::runtime_error(fmt::format("fault injected by CAIRN_FAULT after step {}", step_));
}

}  // namespace cairn
