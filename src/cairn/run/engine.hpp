// Engines: one run of one method (MPM, WLS or the reference FEM) behind one small interface,
// chosen by a registry from the input or from the engine a checkpoint names. `cairn run`,
// `cairn restart` and the Python module drive every engine the same way: start, step until
// finished, finish (docs/architecture.md, "Engines").
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/run/summary.hpp"

namespace cairn {

template <int D>
class Simulation;
class Comm;
namespace fem {
class Solver;
}

/// What an engine steps: the Simulation<D> of an MPM or WLS run, the FEM's solver.
using EngineState = std::variant<std::monostate, Simulation<1>*, Simulation<2>*, Simulation<3>*, fem::Solver*>;

/// One run of one engine with its outputs (history.csv, snapshots, checkpoints on the schedule of
/// [output]). Collective on several MPI ranks: every rank calls the same members in order.
class Engine {
 public:
  virtual ~Engine() = default;
  [[nodiscard]] virtual std::string name() const = 0;  ///< the registry's name: mpm, wls, fem
  [[nodiscard]] virtual const Config& config() const = 0;
  [[nodiscard]] virtual const Comm& comm() const = 0;
  [[nodiscard]] virtual double time() const = 0;
  [[nodiscard]] virtual long long step_count() const = 0;
  /// Particles (MPM, WLS; over every rank) or elements (FEM) the run advances.
  [[nodiscard]] virtual std::int64_t items() const = 0;
  /// simulation.end_time reached, or simulation.max_steps taken.
  [[nodiscard]] bool finished() const;
  /// A new run's initial outputs (history row and snapshot at t = 0); nothing after a restore.
  /// step() calls it first when it was not called.
  virtual void start() = 0;
  /// One time step and the outputs its time asks for. A failing step throws RunFailure (after
  /// writing the failed state); a stop asked for by request_stop() (any rank) throws
  /// RunInterrupted after writing checkpoint-autosave.h5.
  virtual void step() = 0;
  /// The final outputs (history, snapshot, checkpoint unless output.checkpoints is false) and
  /// the figures of the run.
  virtual RunSummary finish() = 0;
  /// A checkpoint now: the next checkpoint-NNNN.h5, or checkpoint-autosave.h5. Returns its path.
  virtual std::filesystem::path write_checkpoint(bool autosave = false) = 0;
  /// history.csv up to date on disk.
  virtual void flush() = 0;
  [[nodiscard]] virtual EngineState state() = 0;
};

/// Ask a running engine to stop after its current step (async-signal-safe: the CLI's SIGINT and
/// SIGTERM handlers call it), and whether a stop was asked for (0: no; else the signal number).
void request_stop(int signal_number);
[[nodiscard]] int requested_stop();
void clear_stop_request();

/// One registered engine (CAIRN_REGISTER_ENGINE).
struct EngineKind {
  std::string doc;
  /// Whether this engine runs `config` (exactly one registered engine says yes).
  std::function<bool(const Config&)> selects;
  std::function<std::unique_ptr<Engine>(const Config&, const RunOptions&)> create;
  /// Continue from a checkpoint this engine wrote; `overrides` (`--set`, already checked against
  /// restart_keys()) apply to the input stored in it.
  std::function<std::unique_ptr<Engine>(const std::filesystem::path&, const std::vector<std::string>&,
                                        const RunOptions&)>
      restore;
  /// `cairn check`: what the set-up gives (grid, particles or mesh, time step, estimates).
  std::function<void(const Config&)> describe;
};

class EngineRegistry {
 public:
  static EngineRegistry& instance();
  bool add(const std::string& name, EngineKind kind);
  [[nodiscard]] const EngineKind& at(const std::string& name) const;
  /// The engine that runs `config`.
  [[nodiscard]] std::string name_for(const Config& config) const;
  [[nodiscard]] std::vector<std::string> names() const;

 private:
  std::vector<std::pair<std::string, EngineKind>> kinds_;
};

#define CAIRN_REGISTER_ENGINE(id, name, ...) \
  static const bool cairn_engine_registration_##id = ::cairn::EngineRegistry::instance().add(name, __VA_ARGS__)

/// The engine `config` asks for, set up (collective on several ranks).
std::unique_ptr<Engine> make_engine(const Config& config, const RunOptions& options);

/// The keys `cairn restart --set` honours: when the run stops and how long, threads and memory
/// guards, what is written and where. Any other key (a material, the grid, the method, a body,
/// a boundary condition) made the state the checkpoint holds, so a new value would not reach
/// it: restore_engine() refuses it.
const std::vector<std::string>& restart_keys();

/// The engine a checkpoint names, continuing from it; `overrides` (`--set`, only restart_keys())
/// apply to the stored input; any other key throws InputError (exit 2), and so does a checkpoint
/// that already reached simulation.end_time (the message says how to go on). The output goes to
/// the checkpoint's folder unless an override sets output.directory; there history.csv and the
/// XDMF files are first cut back to the checkpoint's time. A restart without overrides ends
/// bit-identical to the run that never stopped.
std::unique_ptr<Engine> restore_engine(const std::filesystem::path& checkpoint,
                                       const std::vector<std::string>& overrides, const RunOptions& options);

/// `cairn run`: step `engine` to its end with SIGINT/SIGTERM stopping it cleanly and (unless
/// quiet, rank 0) a progress line on stderr; returns finish()'s summary.
RunSummary drive(Engine& engine, const RunOptions& options);

/// make_engine + drive, and restore_engine + drive.
RunSummary run(const Config& config, const RunOptions& options);
RunSummary restart(const std::filesystem::path& checkpoint, const std::vector<std::string>& overrides,
                   const RunOptions& options);

/// The engine's report for `cairn check` (EngineKind::describe).
void describe(const Config& config);

/// A note for runs whose time step is likely too large for their update: FMPM(k) replaces the
/// lumped mass by a k-term expansion of the full mass matrix, which lowers the critical time step
/// by up to sqrt(k) on GIMP and B-spline grids (docs/update-schemes.md, measured limits). Empty
/// when the CFL rule with simulation.cfl * sqrt(k) <= 0.6 is used, or for other updates.
std::string time_step_note(const Config& config);

}  // namespace cairn
