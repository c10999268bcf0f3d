#include "cairn/run/engine.hpp"

#include <fmt/format.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>

#include "cairn/config/errors.hpp"
#include "cairn/io/checkpoint.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/run/watchdog.hpp"

namespace cairn {
namespace {

using Clock = std::chrono::steady_clock;

/// The signal (SIGINT or SIGTERM) that asked the running engine to stop, 0 while none did.
volatile std::sig_atomic_t stop_signal = 0;

extern "C" void on_stop_signal(int signo) { stop_signal = signo; }

/// Installs on_stop_signal for SIGINT and SIGTERM for its lifetime (one-shot: a second signal
/// during the final checkpoint ends the program the default way) and puts the old handlers back.
class StopSignals {
 public:
  StopSignals() {
    stop_signal = 0;
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

/// "1 h 02 min", "3 min 20 s", "42 s".
std::string duration_text(double seconds) {
  const long long s = std::llround(std::max(0.0, seconds));
  if (s >= 3600) return fmt::format("{} h {:02d} min", s / 3600, (s % 3600) / 60);
  if (s >= 60) return fmt::format("{} min {:02d} s", s / 60, s % 60);
  return fmt::format("{} s", s);
}

/// On a terminal: a bar with percentage, step, time, throughput and an ETA from the simulated
/// time per wall second smoothed over about 10 s (redrawn at most 4 times a second; `final`
/// draws the finished state). Elsewhere: one line per 10 %. Silent when quiet.
class Progress {
 public:
  Progress(const Engine& engine, bool quiet)
      : engine_(engine), quiet_(quiet), start_(Clock::now()), first_step_(engine.step_count()),
        items_(static_cast<double>(engine.items())) {}
  ~Progress() { end_line(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void update(bool final = false) {
    if (quiet_) return;
    const auto now = Clock::now();
    const double end = engine_.config().simulation.end_time;
    const double time = engine_.time();
    const long long step = engine_.step_count();
    const double frac = final ? 1.0 : std::clamp(time / end, 0.0, 1.0);
    if (!isatty(fileno(stderr))) {
      const int decile = static_cast<int>(10.0 * frac);
      if (decile > last_decile_) {
        last_decile_ = decile;
        std::fprintf(stderr, "  step %lld  t = %.6g  (%d%%)\n", step, time, 10 * decile);
      }
      return;
    }
    if (!final && now - last_ < std::chrono::milliseconds(250)) return;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (last_ != Clock::time_point{}) {
      const double dwall = std::chrono::duration<double>(now - last_).count();
      const double speed = dwall > 0.0 ? (time - last_time_) / dwall : 0.0;
      const double weight = 1.0 - std::exp(-dwall / 10.0);
      smoothed_speed_ = smoothed_speed_ > 0.0 ? smoothed_speed_ + weight * (speed - smoothed_speed_) : speed;
    }
    last_ = now;
    last_time_ = time;
    const double rate = elapsed > 0 ? static_cast<double>(step - first_step_) * items_ / elapsed : 0.0;
    const std::string eta = final ? "done in " + duration_text(elapsed)
                            : smoothed_speed_ > 0.0 ? "ETA " + duration_text((end - time) / smoothed_speed_)
                                                    : "ETA ...";
    const std::string tail =
        fmt::format(" {:5.1f}%  step {}  t = {:.4g}  {}  {:.3g} p-steps/s", 100.0 * frac, step, time, eta, rate);
    struct winsize ws {};
    const int columns = ioctl(fileno(stderr), TIOCGWINSZ, &ws) == 0 && ws.ws_col > 0 ? ws.ws_col : 80;
    const int width = std::clamp(columns - 3 - static_cast<int>(tail.size()) - 1, 0, 40);
    const int filled = static_cast<int>(std::floor(frac * width));
    std::string line = width >= 10 ? "[" + std::string(filled, '#') + std::string(width - filled, '-') + "]" : "";
    line += tail;
    if (static_cast<int>(line.size()) > columns - 1) line.resize(static_cast<std::size_t>(std::max(columns - 1, 0)));
    std::fprintf(stderr, "\r%s\033[K", line.c_str());
    shown_ = true;
  }

  /// Ends a bar line (before a message or the summary).
  void end_line() {
    if (shown_) std::fprintf(stderr, "\n");
    shown_ = false;
  }

 private:
  const Engine& engine_;
  bool quiet_;
  Clock::time_point start_;
  long long first_step_;
  double items_;
  Clock::time_point last_{};
  double last_time_ = 0.0;
  double smoothed_speed_ = 0.0;  ///< simulated time per wall second, smoothed
  int last_decile_ = 0;
  bool shown_ = false;
};

}  // namespace

bool Engine::finished() const {
  const auto& s = config().simulation;
  return !(time() < s.end_time * (1.0 - 1e-12) && (s.max_steps == 0 || step_count() < s.max_steps));
}

void Engine::stop_after_step(int signal_number, const std::filesystem::path& folder) {
  flush();
  const char* name = signal_number == SIGINT    ? "SIGINT"
                     : signal_number == SIGTERM ? "SIGTERM"
                                                : "a signal";
  std::string saved = "no checkpoint written (output.checkpoints = false)";
  if (config().output.checkpoints) {
    const std::filesystem::path checkpoint = write_checkpoint(true);
    saved = fmt::format("state saved in {0}; continue with: cairn restart {0}", checkpoint.string());
  }
  throw RunInterrupted(fmt::format("interrupted by {} at step {} (t = {:.6g}); {}; output in {}", name, step_count(),
                                   time(), saved, folder.string()));
}

void request_stop(int signal_number) { stop_signal = signal_number; }
int requested_stop() { return stop_signal; }
void clear_stop_request() { stop_signal = 0; }

EngineRegistry& EngineRegistry::instance() {
  static EngineRegistry registry;
  return registry;
}

bool EngineRegistry::add(const std::string& name, EngineKind kind) {
  kinds_.emplace_back(name, std::move(kind));
  return true;
}

const EngineKind& EngineRegistry::at(const std::string& name) const {
  for (const auto& [n, kind] : kinds_)
    if (n == name) return kind;
  std::string list;
  for (const auto& n : names()) list += (list.empty() ? "" : ", ") + n;
  throw std::invalid_argument(fmt::format("no engine '{}' in this build of Cairn (engines: {})", name, list));
}

std::string EngineRegistry::name_for(const Config& config) const {
  for (const auto& [n, kind] : kinds_)
    if (kind.selects(config)) return n;
  throw std::logic_error("no registered engine runs this input");
}

std::vector<std::string> EngineRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [n, kind] : kinds_) out.push_back(n);
  std::sort(out.begin(), out.end());
  return out;
}

std::unique_ptr<Engine> make_engine(const Config& config, const RunOptions& options) {
  const auto& registry = EngineRegistry::instance();
  return registry.at(registry.name_for(config)).create(config, options);
}

void describe(const Config& config) {
  const auto& registry = EngineRegistry::instance();
  registry.at(registry.name_for(config)).describe(config);
}

const std::vector<std::string>& restart_keys() {
  static const std::vector<std::string> keys{
      "simulation.end_time",        "simulation.max_steps",       "simulation.threads",
      "simulation.adapt_threads",   "simulation.sort_particles",  "simulation.rebalance_threshold",
      "simulation.memory_limit",    "simulation.max_estimated_steps", "simulation.mpi_timeout",
      "parallel.halo",              "parallel.balance",
      "output.directory",           "output.every",               "output.history_every",
      "output.checkpoint_every",    "output.checkpoint_wall_interval", "output.checkpoints",
      "output.snapshots",           "output.grid_snapshots",      "output.compression"};
  return keys;
}

std::unique_ptr<Engine> restore_engine(const std::filesystem::path& checkpoint,
                                       const std::vector<std::string>& overrides, const RunOptions& options) {
  // The checkpoint holds the particles (masses, positions, material state), the grid and the
  // counters the first input made; keys that made them would only half apply (the stored input
  // would say one thing, the state another), so only the keys that steer the continuation do.
  for (const auto& o : overrides) {
    std::string key = o.substr(0, o.find('='));
    key.erase(0, key.find_first_not_of(" \t"));
    key.erase(key.find_last_not_of(" \t") + 1);
    const auto& honoured = restart_keys();
    if (std::find(honoured.begin(), honoured.end(), key) != honoured.end() || o.find('=') == std::string::npos)
      continue;  // (a malformed --set is reported by the reading, as for cairn run)
    std::string list;
    for (const auto& k : honoured) list += (list.empty() ? "" : ", ") + k;
    throw InputError("--set " + o, 0, key, "one of the keys a restart honours: " + list,
                     "a key that made the stored state: the checkpoint's particles (masses, positions, "
                     "material state) and grid came from the original input and would not follow a "
                     "new value; change it in the input file and start again with cairn run");
  }
  // The restarted run writes next to the checkpoint it was given (not into the folder stored in
  // it, which may belong to another run or machine), unless --set output.directory says where.
  std::vector<std::string> all = overrides;
  bool directory_given = false;
  for (const auto& o : overrides) {
    const std::string key = o.substr(0, o.find('='));
    directory_given = directory_given || key.find("output.directory") != std::string::npos;
  }
  if (!directory_given) {
    const std::string folder = checkpoint.parent_path().empty() ? std::string(".") : checkpoint.parent_path().string();
    std::string quoted = "\"";
    for (char c : folder) quoted += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
    all.push_back("output.directory=" + quoted + "\"");
  }
  const std::string engine = checkpoint_engine(checkpoint, Comm::world());
  const auto names = EngineRegistry::instance().names();
  if (std::find(names.begin(), names.end(), engine) == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    throw InputError(checkpoint.string(), 0, "engine", "the engine that wrote it, one of " + list,
                     "'" + engine + "' (a damaged or edited checkpoint, or one of another build of Cairn)");
  }
  return EngineRegistry::instance().at(engine).restore(checkpoint, all, options);
}

RunSummary drive(Engine& engine, const RunOptions& options) {
  const StopSignals signals;
  Progress progress(engine, options.quiet || !engine.comm().is_root());  // (ends its line however this ends)
  engine.start();
  {
    StallWatchdog watchdog(engine.comm(), engine.config().simulation.mpi_timeout, engine.config().output.directory);
    const FaultInjection fault(engine.comm());
    while (!engine.finished()) {
      engine.step();
      fault.after_step(engine.step_count());
      watchdog.beat(engine.step_count());
      progress.update();
    }
  }
  RunSummary summary = engine.finish();
  progress.update(true);
  return summary;
}

RunSummary run(const Config& config, const RunOptions& options) {
  const auto engine = make_engine(config, options);
  return drive(*engine, options);
}

RunSummary restart(const std::filesystem::path& checkpoint, const std::vector<std::string>& overrides,
                   const RunOptions& options) {
  const auto engine = restore_engine(checkpoint, overrides, options);
  return drive(*engine, options);
}

}  // namespace cairn
