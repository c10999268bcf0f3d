// Adaptive thread count: run with all threads or with one, whichever the measured step times say
// is faster right now (docs/performance.md, "Threads on a shared machine").
//
// On a machine shared with other busy processes a team of threads loses time at every barrier
// waiting for a member that lost its core; on an idle machine it runs nearly twice as fast on
// two cores. Neither can be known before the run, and the load changes during it, so the run
// loop times its steps: it holds the current choice for a while, then runs a short probe with
// the other count and keeps whichever was faster per step (a probe of the full team ends after
// its first step when that is already slower than one thread). The hold grows while the
// choice stays the same (the probes cost less and less of the run) and shrinks again when it
// changes.
// Results do not depend on the thread count (transfer/transfer.hpp), so switching between steps
// changes nothing but the speed.
#pragma once

#include <omp.h>

#include <algorithm>
#include <array>

namespace cairn {

class ThreadTuner {
 public:
  /// Steps of a probe of the full team not timed (its first step moves the particles' data to
  /// the other cores' caches; before_step has woken the threads, untimed; a probe of one thread
  /// needs no such step), steps timed at the end of a hold and of a probe (their median counts),
  /// and the hold lengths.
  static constexpr int warm_steps = 1, timed_steps = 3;
  static constexpr long long first_hold = 16, longest_hold = 1024, hold_growth = 4;
  /// A probe slower than the choice by more than this factor confirms the choice beyond the
  /// noise of a few steps: the hold then grows by sure_growth instead of hold_growth, so that
  /// the probes of a clear winner cost less (docs/performance.md, "Threads").
  static constexpr double sure_margin = 1.25;
  static constexpr long long sure_growth = 16;
  /// A step of the full team that takes longer than this is not probed with one thread: its
  /// parallel regions are long enough that waiting at barriers costs little (docs/performance.md).
  static constexpr double long_step = 0.02;

  /// max_threads: the team size the run was given; tuning is off for 1 thread or !enabled.
  ThreadTuner(int max_threads, bool enabled) : max_(max_threads), enabled_(enabled && max_threads > 1) {
    chosen_ = current_ = max_;
    hold_ = warm_steps + timed_steps;  // the first hold only measures the full team
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
    if (probing_ && current_ != 1 && in_phase_ == warm_steps && seconds > chosen_time_) {
      // The full team's first step (its threads woken beforehand, untimed) is already slower
      // than the choice: a busy machine. The probe ends here; its timed steps would cost the
      // most exactly then (docs/performance.md, "Threads").
      end_probe(seconds);
      return;
    }
    const long long length = probing_ ? probe_length() : hold_;
    if (in_phase_ > length - timed_steps) timed_[n_timed_++] = seconds;
    if (in_phase_ < length) return;
    const double per_step = median_timed();
    in_phase_ = 0;
    n_timed_ = 0;
    if (!probing_) {
      // End of a hold: time per step of the choice, then a probe of the other count.
      chosen_time_ = per_step;
      if (chosen_ == max_ && per_step > long_step) {
        hold_ = longest_hold;
        return;
      }
      current_ = chosen_ == 1 ? max_ : 1;
      probing_ = true;
      return;
    }
    end_probe(per_step);
  }

  /// Gives OpenMP back the full team (for what runs after the loop).
  void finish() const {
    if (enabled_) omp_set_num_threads(max_);
  }

 private:
  /// Ends the probe now running, whose steps took per_step each: keeps the faster count.
  void end_probe(double per_step) {
    in_phase_ = 0;
    n_timed_ = 0;
    probing_ = false;
    if (per_step < chosen_time_) {
      chosen_ = current_;
      hold_ = first_hold;
    } else {
      const long long growth = per_step > sure_margin * chosen_time_ ? sure_growth : hold_growth;
      hold_ = std::min(longest_hold, std::max(first_hold, hold_ * growth));
    }
    current_ = chosen_;
  }

  /// Steps of the probe now running (current_ is the probed count).
  [[nodiscard]] long long probe_length() const { return current_ == 1 ? timed_steps : warm_steps + timed_steps; }

  int max_ = 1;
  bool enabled_ = false;
  int chosen_ = 1, current_ = 1;
  int woken_ = 0;  ///< the thread count before_step last set
  bool probing_ = false;
  long long hold_ = 1, in_phase_ = 0;
  /// The median of the timed steps of the phase: a pause of the virtual machine in one step
  /// does not decide, nor does one lucky step of a team beside a busy neighbour.
  [[nodiscard]] double median_timed() const {
    static_assert(timed_steps == 3, "the median below is of three steps");
    const auto& t = timed_;
    return std::max(std::min(t[0], t[1]), std::min(std::max(t[0], t[1]), t[2]));
  }

  std::array<double, timed_steps> timed_{};
  int n_timed_ = 0;
  double chosen_time_ = 0.0;
  long long steps_ = 0, single_steps_ = 0;
};

}  // namespace cairn
