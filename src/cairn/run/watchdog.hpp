// A distributed run whose ranks stop answering ends instead of hanging (issue 36,
// docs/robustness.md "MPI faults"). A rank killed by a signal or that exits with an error is
// seen by the MPI launcher, which stops the others; a rank that is stopped (SIGSTOP), hung or
// swapped out is not: the others wait in their next exchange for ever. Each rank's watchdog
// thread notes every completed step; when none has completed for simulation.mpi_timeout seconds
// it names the rank that stopped answering and ends its own process with exit code 1, which
// makes the launcher stop the job. To name that rank, each watchdog writes its rank's last
// step and the wall-clock time of its last beat to <output>/.ranks/rank-R once a second (less
// often beyond 100 ranks): a stopped rank's file goes stale.
#pragma once

#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>

namespace cairn {

class Comm;

class StallWatchdog {
 public:
  /// Starts the thread on a distributed run with timeout_s > 0 (else does nothing).
  StallWatchdog(const Comm& comm, double timeout_s, std::filesystem::path output_directory);
  ~StallWatchdog();  ///< stops the thread and removes this rank's file
  StallWatchdog(const StallWatchdog&) = delete;
  StallWatchdog& operator=(const StallWatchdog&) = delete;

  /// A step completed: the step count after it.
  void beat(long long step);

 private:
  void watch();
  [[nodiscard]] double write_period() const;
  void write_own_file(long long step, double unix_time) const;
  [[nodiscard]] std::string diagnosis(long long step, double waited) const;

  int rank_ = 0, size_ = 1;
  double timeout_ = 0.0;
  std::filesystem::path folder_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  long long step_ = 0;
  double last_beat_ = 0.0;  ///< steady-clock seconds of the last beat
  std::thread thread_;
};

/// Test hook for the MPI fault tests (tests/mpi/faults.py): the environment variable
/// CAIRN_FAULT = "throw:R:N" makes rank R throw after step N; "alloc:R:N" makes it allocate
/// memory until allocation fails (run it under a memory limit, `ulimit -v`). Read once per run;
/// unset, it costs one comparison per step.
class FaultInjection {
 public:
  explicit FaultInjection(const Comm& comm);
  void after_step(long long step) const {
    if (step == step_) fire();
  }

 private:
  [[noreturn]] void fire() const;
  std::string kind_;
  long long step_ = -1;
};

}  // namespace cairn
