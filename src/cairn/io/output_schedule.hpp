#pragma once
// When a run writes its outputs: history rows, snapshots and checkpoints on the intervals of
// [output] (docs/output.md). Shared by the MPM run loop (run/mpm_engine.cpp) and the reference FEM's
// (fem/run.cpp), so that both write at the same times and restart the same way.

#include <algorithm>
#include <map>
#include <string>

#include "cairn/config/config.hpp"

namespace cairn {

/// One output clock as an integer counter, so output times do not drift with round-off.
struct Schedule {
  double interval = 0.0;  ///< 0 = never (except the outputs a run writes at its ends)
  long long done = 0;     ///< outputs written at t > 0
  [[nodiscard]] bool due(double t) const {
    return interval > 0.0 && t >= static_cast<double>(done + 1) * interval * (1.0 - 1e-12);
  }
  /// Counts every output due by t. A time far past the last output (a restored time, a long
  /// step) goes straight to about its count, and the test itself settles the last one or two:
  /// one increment per interval took 2e13 turns for a damaged checkpoint's t = 2^31 at an interval
  /// of 1e-4 (found by cairn_fuzz_checkpoint). A count beyond any run's is held there.
  void advance(double t) {
    if (!due(t)) return;
    const double reached = t / (interval * (1.0 - 1e-12));
    constexpr long long most = 4'000'000'000'000'000'000LL;
    if (!(reached < static_cast<double>(most))) {
      done = most;
      return;
    }
    done = std::max(done, static_cast<long long>(reached) - 2);
    while (due(t)) ++done;
  }
};

/// The three clocks of a run. History defaults to the snapshot interval, or to end_time / 100.
class OutputSchedule {
 public:
  OutputSchedule(const OutputConfig& out, double end_time) {
    snapshot_.interval = out.every;
    history_.interval = out.history_every > 0.0 ? out.history_every : (out.every > 0.0 ? out.every : end_time / 100.0);
    checkpoint_.interval = out.checkpoint_every;
  }

  /// After a step that reached time t: writes what is due, in the order history row, snapshot,
  /// checkpoint. The callables take no arguments.
  template <class History, class Snapshot, class Checkpoint>
  void after_step(double t, History&& write_history_row, Snapshot&& write_snapshot, Checkpoint&& write_checkpoint) {
    wrote_history_ = wrote_snapshot_ = false;
    if (history_.due(t)) {
      history_.advance(t);
      write_history_row();
      wrote_history_ = true;
    }
    if (snapshot_.due(t)) {
      snapshot_.advance(t);
      write_snapshot();
      wrote_snapshot_ = true;
    }
    if (checkpoint_.due(t)) {
      checkpoint_.advance(t);
      write_checkpoint();
    }
  }

  /// At the end of the run: the final state always gets a history row and a snapshot.
  template <class History, class Snapshot>
  void at_end(History&& write_history_row, Snapshot&& write_snapshot) const {
    if (!wrote_history_) write_history_row();
    if (!wrote_snapshot_) write_snapshot();
  }

  /// The counters and intervals a checkpoint stores (and restore() reads back).
  void save(std::map<std::string, double>& scalars) const {
    scalars["snapshots_done"] = static_cast<double>(snapshot_.done);
    scalars["history_done"] = static_cast<double>(history_.done);
    scalars["checkpoints_done"] = static_cast<double>(checkpoint_.done);
    scalars["snapshot_interval"] = snapshot_.interval;
    scalars["history_interval"] = history_.interval;
    scalars["checkpoint_interval"] = checkpoint_.interval;
  }
  /// From a checkpoint at time t. A clock whose interval `cairn restart --set` changed counts
  /// its outputs again as if it had always had the new one, so the next falls on a multiple of
  /// it (checkpoints written before the intervals were stored keep their counters).
  void restore(const std::map<std::string, double>& scalars, double t) {
    restore_one(snapshot_, scalars, "snapshots_done", "snapshot_interval", t);
    restore_one(history_, scalars, "history_done", "history_interval", t);
    restore_one(checkpoint_, scalars, "checkpoints_done", "checkpoint_interval", t);
  }

 private:
  static void restore_one(Schedule& clock, const std::map<std::string, double>& scalars, const char* done,
                          const char* interval, double t) {
    clock.done = static_cast<long long>(scalars.at(done));
    const auto stored = scalars.find(interval);
    if (stored == scalars.end() || stored->second == clock.interval) return;
    clock.done = 0;  // the outputs a new interval has due by t
    clock.advance(t);
  }

  Schedule history_, snapshot_, checkpoint_;
  bool wrote_history_ = true, wrote_snapshot_ = true;  ///< at start-up the initial outputs are written
};

}  // namespace cairn
