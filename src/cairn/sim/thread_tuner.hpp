// Adaptive thread count: run with all threads or with one, whichever the measured step times say
// is faster right now (docs/performance.md, "Threads on a shared machine").
//
// On a machine shared with other busy processes a team of threads loses time at every barrier
// waiting for a member that lost its core; on an idle machine it runs nearly twice as fast on
// two cores. Neither can be known before the run, and the load changes during it, so the run
// loop times its steps: it holds the current choice for a while, then runs a short probe with
// the other count and keeps whichever was faster per step (a probe of the full team ends as
// soon as its steps so far are slower than one thread's). A switch is checked by the hold that
// follows it, whose many steps see what a short probe can miss: beside a busy process most team
// steps run at full speed but every few steps one waits for a neighbour's time slice (a team so
// confirmed needs no probe of one thread right after). The hold grows while the choice stays
// the same (the probes cost less and less of the run) and shrinks again when it changes, and
// a hold of one thread stays short when nothing else on the machine wants a processor (a
// virtual machine's host can slow a team for a moment without any neighbour in sight).
// Results do not depend on the thread count (transfer/transfer.hpp), so switching between steps
// changes nothing but the speed.
#pragma once

#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace cairn {

class ThreadTuner {
 public:
  /// Steps of a probe of the full team not timed (its first step moves the particles' data to
  /// the other cores' caches; before_step has woken the threads, untimed; a probe of one thread
  /// needs no such step), steps timed in a probe, and the hold lengths. A hold's time is the
  /// slower of the mean of its steps but the first (the step after a change of count) and the
  /// mean of its last hold_window steps: enough steps to see a neighbour's time slices, few
  /// enough to follow a change of load within one hold. The run
  /// starts with a short measure of the team (warm + timed steps) and a probe of one thread; the
  /// hold of whichever was faster then checks that first choice as it checks every switch.
  static constexpr int warm_steps = 1, timed_steps = 3;
  static constexpr long long first_hold = 16, longest_hold = 1024, hold_growth = 4;
  static constexpr long long hold_window = first_hold - 1;
  /// A probe slower than the choice by more than this factor confirms the choice beyond the
  /// noise of a few steps: the hold then grows by sure_growth instead of hold_growth, so that
  /// the probes of a clear winner cost less (docs/performance.md, "Threads"). A team's step
  /// times are heavy-tailed beside a busy process (most at idle speed, some waiting a time
  /// slice), so a few lucky team steps can look like a clear win: the team's margin is wider,
  /// and a probe of the team that ended early (its first steps were slower) grows the hold of
  /// one thread by hold_growth only.
  static constexpr double sure_margin = 1.25, sure_margin_team = 1.6;
  static constexpr long long sure_growth = 16;
  /// A step of the full team that takes longer than this is not probed with one thread: its
  /// parallel regions are long enough that waiting at barriers costs little (docs/performance.md).
  static constexpr double long_step = 0.02;
  /// Runnable tasks on the machine other than the caller, or -1 when not known.
  using OtherTasks = int (*)();
  /// Steps at the end of a hold of one thread that ask other_tasks, and the longest hold of one
  /// thread when none of them saw another runnable task: then nothing competes for the cores
  /// inside the machine, and a team that lost its probes was slowed by something that passes
  /// (a virtual machine's host running other guests on its processors). Beside a busy process
  /// the holds grow as before (docs/performance.md, "Threads").
  static constexpr int alone_samples = 3;
  static constexpr long long alone_single_hold = 64;

  /// Other runnable tasks from /proc/loadavg (its fourth field counts the runnable tasks, the
  /// caller included); -1 where it cannot be read. Asked at the end of a hold of one thread,
  /// when the team's other threads are parked: with a wait policy that keeps them spinning
  /// (OMP_WAIT_POLICY=ACTIVE) they count as other tasks, and the holds grow as before.
  static int runnable_others() {
    std::FILE* f = std::fopen("/proc/loadavg", "r");
    if (!f) return -1;
    int running = 0, total = 0;
    const bool ok = std::fscanf(f, "%*f %*f %*f %d/%d", &running, &total) == 2;
    std::fclose(f);
    return ok && running >= 1 ? running - 1 : -1;
  }

  /// max_threads: the team size the run was given; tuning is off for 1 thread or !enabled.
  /// other_tasks: how many other tasks are runnable (runnable_others in a run; null: not
  /// known, the holds of one thread grow like the team's).
  ThreadTuner(int max_threads, bool enabled, OtherTasks other_tasks = nullptr)
      : max_(max_threads), enabled_(enabled && max_threads > 1), other_tasks_(other_tasks) {
    chosen_ = current_ = max_;
    hold_ = warm_steps + timed_steps;  // the first measure of the team
  }

  [[nodiscard]] bool enabled() const { return enabled_; }
  [[nodiscard]] int threads() const { return current_; }
  /// Steps taken with one thread while tuning (0 when tuning is off).
  [[nodiscard]] long long single_thread_steps() const { return single_steps_; }
  [[nodiscard]] long long steps() const { return steps_; }

  /// Sets OpenMP's thread count for the next step. Going from one thread to the full team, it
  /// first wakes the parked threads with an empty parallel region, outside the step's timing, so
  /// that the team's first step is timed as a team step and not as a wake-up (which on a virtual
  /// machine means waking a halted virtual CPU).
  void before_step() {
    if (!enabled_) return;
    omp_set_num_threads(current_);
    if (current_ != 1 && woken_ != current_) {
#pragma omp parallel
      {
      }
    }
    woken_ = current_;
  }

  /// Records the wall seconds of the step just taken and picks the count for the next one.
  void after_step(double seconds) {
    if (!enabled_) return;
    ++steps_;
    if (current_ == 1) ++single_steps_;
    ++in_phase_;
    if (probing_) {
      probe_seconds_ += seconds;
      if (current_ != 1 && probe_seconds_ > static_cast<double>(in_phase_) * chosen_time_) {
        // The team's steps so far (its threads woken beforehand, untimed) are already slower
        // than the choice: a busy machine, where a team step now and then waits a neighbour's
        // time slice for one of its threads. The probe ends here; its further steps would cost
        // the most exactly then (docs/performance.md, "Threads").
        ended_early_ = true;
        end_probe(probe_seconds_ / static_cast<double>(in_phase_));
        return;
      }
      if (in_phase_ > probe_length() - timed_steps) recent_.add(seconds);
      if (in_phase_ == probe_length()) end_probe(recent_.mean());
      return;
    }
    if (in_phase_ > 1) {
      whole_.add(seconds);
      if (in_phase_ > hold_ - hold_window) recent_.add(seconds);
    }
    if (current_ == 1 && other_tasks_ && in_phase_ > hold_ - alone_samples) {
      ++asked_;
      others_seen_ |= other_tasks_() != 0;
    }
    // The slower of the whole hold (every neighbour's time slice in it) and its last steps (a
    // change of load during the hold).
    if (in_phase_ == hold_) end_hold(std::max(whole_.mean(), recent_.mean()));
  }

  /// Gives OpenMP back the full team (for what runs after the loop).
  void finish() const {
    if (enabled_) omp_set_num_threads(max_);
  }

 private:
  /// Step times of a phase and their mean; in a window of a few steps (a probe, the first
  /// measure) without the slowest step, so that a pause of the virtual machine in one step does
  /// not decide. A longer window keeps every step: the team steps that wait for a neighbour's
  /// time slice, one in a few beside a busy process, are what its mean must see (a median of a
  /// few steps misses them), and one pause weighs little there.
  struct Window {
    double sum = 0.0, slowest = 0.0;
    long long n = 0;
    void add(double t) {
      sum += t;
      slowest = std::max(slowest, t);
      ++n;
    }
    [[nodiscard]] double mean() const {
      if (n <= 1) return sum;
      return n <= timed_steps ? (sum - slowest) / static_cast<double>(n - 1) : sum / static_cast<double>(n);
    }
  };

  /// Ends the hold of the choice, whose steps took per_step each.
  void end_hold(double per_step) {
    if (chosen_ == 1 && other_tasks_) alone_ = asked_ > 0 && !others_seen_;
    start_phase();
    chosen_time_ = per_step;
    if (verifying_) {
      verifying_ = false;
      if (per_step > other_time_) {
        // The hold after a switch is slower than the count before it: the probe that won was
        // lucky (a few team steps between a neighbour's time slices). Back to the count before,
        // as if the probe had lost.
        std::swap(chosen_time_, other_time_);
        chosen_ = current_ = (chosen_ == 1 ? max_ : 1);
        hold_ = grown(previous_hold_, other_time_);
        return;
      }
      if (chosen_ == max_) {
        // The team confirmed against one thread, whose steady steps were timed just before the
        // switch: a probe now would time them again; the hold grows as after a lost probe. (A
        // confirmed single thread still probes the team: the team's earlier time may be a
        // passing state, such as both threads on one core at the start of the run.)
        hold_ = grown(hold_, other_time_);
        return;
      }
    }
    if (chosen_ == max_ && per_step > long_step) {
      hold_ = longest_hold;
      return;
    }
    current_ = chosen_ == 1 ? max_ : 1;
    probing_ = true;
    ended_early_ = false;
  }

  /// Ends the probe now running, whose steps took per_step each: keeps the faster count. A
  /// switch is verified by the hold that follows it (end_hold).
  void end_probe(double per_step) {
    start_phase();
    probing_ = false;
    if (first_probe_) {
      // The first choice stands on a few steps of each count: its hold checks it.
      first_probe_ = false;
      other_time_ = std::max(per_step, chosen_time_);
      if (per_step < chosen_time_) {
        chosen_time_ = per_step;
        chosen_ = current_;
      }
      current_ = chosen_;
      previous_hold_ = hold_ = first_hold;
      verifying_ = true;
      return;
    }
    if (per_step < chosen_time_) {
      other_time_ = chosen_time_;
      chosen_ = current_;
      previous_hold_ = hold_;
      hold_ = first_hold;
      verifying_ = true;
    } else {
      other_time_ = per_step;
      hold_ = grown(hold_, per_step);
    }
    current_ = chosen_;
  }

  /// The next hold of a choice confirmed against a count whose steps took loser_time each.
  [[nodiscard]] long long grown(long long hold, double loser_time) const {
    const double margin = chosen_ == 1 ? sure_margin : sure_margin_team;
    const bool sure = !ended_early_ && loser_time > margin * chosen_time_;
    const long long growth = sure ? sure_growth : hold_growth;
    const long long cap = chosen_ == 1 && alone_ ? alone_single_hold : longest_hold;
    return std::min(cap, std::max(first_hold, hold * growth));
  }

  void start_phase() {
    in_phase_ = 0;
    whole_ = recent_ = {};
    probe_seconds_ = 0.0;
    asked_ = 0;
    others_seen_ = false;
  }

  /// Steps of the probe now running (current_ is the probed count).
  [[nodiscard]] long long probe_length() const { return current_ == 1 ? timed_steps : warm_steps + timed_steps; }

  int max_ = 1;
  bool enabled_ = false;
  int chosen_ = 1, current_ = 1;
  int woken_ = 0;  ///< the thread count before_step last set
  bool probing_ = false;
  bool verifying_ = false;   ///< this hold follows a switch (or the first probe): it may undo it
  bool first_probe_ = true;  ///< the probe now running or next is the run's first
  long long hold_ = 1, previous_hold_ = 1, in_phase_ = 0;
  Window whole_, recent_;  ///< a hold's steps but its first, and its (or a probe's) last ones
  double probe_seconds_ = 0.0;  ///< all of a probe's steps so far, warm ones included
  bool ended_early_ = false;    ///< the probe that just ended was a team's, ended early
  double chosen_time_ = 0.0;    ///< seconds per step of the choice, at the end of its last hold
  double other_time_ = 0.0;     ///< seconds per step of the other count, when last measured
  long long steps_ = 0, single_steps_ = 0;
  OtherTasks other_tasks_ = nullptr;
  int asked_ = 0;             ///< other_tasks asked in this phase
  bool others_seen_ = false;  ///< ... and one answer was not 0
  bool alone_ = false;        ///< the last hold of one thread saw no other runnable task
};

}  // namespace cairn
