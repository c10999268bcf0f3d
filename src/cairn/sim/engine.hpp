// One run of one engine (MPM or WLS), driven step by step: the interface `cairn run` and the
// Python module (python/, docs/python.md) share, so that both take the same code path and write
// the same outputs to the bit.
//
// TEMPORARY (branch python): the shape of the engine interface of the architecture issue (33),
// implemented over the MPM/WLS Runner of sim/run.cpp until that version lands; the FEM
// is not behind it yet. Replaced wholesale by the lead's engine.hpp on merge.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "cairn/sim/run.hpp"

namespace cairn {

template <int D>
class Simulation;
namespace fem {
class Solver;
}

/// The state an engine advances: the Simulation<D> of an MPM or WLS run, or the FEM solver.
using EngineState = std::variant<std::monostate, Simulation<1>*, Simulation<2>*, Simulation<3>*, fem::Solver*>;

class Engine {
 public:
  virtual ~Engine() = default;
  [[nodiscard]] virtual std::string name() const = 0;  ///< "mpm", "wls", "fem"
  [[nodiscard]] virtual int dimension() const = 0;
  [[nodiscard]] virtual const Config& config() const = 0;
  [[nodiscard]] virtual double time() const = 0;
  [[nodiscard]] virtual long long step_count() const = 0;
  [[nodiscard]] virtual double end_time() const = 0;
  /// simulation.end_time or simulation.max_steps reached.
  [[nodiscard]] virtual bool finished() const = 0;
  /// The initial outputs of a new run (step() calls it when not yet called).
  virtual void start() = 0;
  /// One step and the outputs the schedule asks for; throws RunFailure.
  virtual void step() = 0;
  /// The final outputs and checkpoint; the summary of the run.
  virtual RunSummary finish() = 0;
  virtual std::filesystem::path write_checkpoint(bool autosave = false) = 0;
  virtual void flush() = 0;  ///< history.csv to disk
  virtual EngineState state() = 0;
  [[nodiscard]] virtual std::int64_t items() const = 0;  ///< particles or elements
};

/// A new run of a validated config (simulation.dimension picks the instantiation).
std::unique_ptr<Engine> make_engine(const Config& config, const RunOptions& options);

/// The run a checkpoint holds, continuing from it (as `cairn restart`: `overrides` only of
/// restart_keys(), the output beside the checkpoint unless output.directory is given).
std::unique_ptr<Engine> restore_engine(const std::filesystem::path& checkpoint,
                                       const std::vector<std::string>& overrides, const RunOptions& options);

}  // namespace cairn
