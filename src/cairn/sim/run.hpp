// The run loop: time stepping to end_time with the output schedule (history rows, HDF5/XDMF
// snapshots, checkpoints), a progress line, failure handling and restart from a checkpoint.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "cairn/io/config.hpp"

namespace cairn {

struct RunOptions {
  bool quiet = false;  ///< no progress line and no summary
};

struct RunSummary {
  long long steps = 0;      ///< steps taken by this invocation
  double end_time = 0.0;    ///< simulated time reached
  double wall_seconds = 0.0;
  double particle_steps_per_second = 0.0;
  std::size_t n_particles = 0;  ///< over all ranks
  std::string item = "particle";          ///< what n_particles counts ("element" for FEM runs)
  std::string xdmf = "particles.xdmf";    ///< the snapshot index in output_directory
  int ranks = 1;                ///< MPI ranks the run was distributed over
  int partitions = 0;           ///< domain partitions (start-up and repartitions), several ranks
  long long migrated = 0;       ///< particles that moved between ranks
  double max_imbalance = 1.0;   ///< largest particle imbalance seen at a step's start
  std::filesystem::path output_directory;
  std::filesystem::path last_checkpoint;
  /// Wall seconds per pipeline stage of Simulation::step (stencils, particles_to_grid, ...).
  std::vector<std::pair<std::string, double>> stage_seconds;
  /// Whether the thread count adapted to measured step times (sim/thread_tuner.hpp), and the
  /// steps it ran on one thread.
  bool adaptive_threads = false;
  long long single_thread_steps = 0;
  long long particle_sorts = 0;  ///< sorts into cell-block order (simulation.sort_particles)
  /// Multimaterial runs: seconds in contact preparation (of which normal/separation fits) and
  /// corrections (inside the stages above), and contact nodes summed over the steps.
  double contact_prepare_seconds = 0.0, contact_fit_seconds = 0.0, contact_correct_seconds = 0.0;
  long long contact_node_steps = 0;
  /// Bodies filled from surface meshes: particle volume beside mesh volume (geometry::volume_note).
  std::vector<std::string> body_notes;
};

/// A run stopped by a SimulationFailure, with the step and time at which it happened. The last
/// good history, snapshots and checkpoints are on disk, plus a `failure` snapshot of the state
/// that failed.
class RunFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run stopped by SIGINT or SIGTERM after its current step; the message says where the
/// checkpoint-autosave.h5 it wrote lies (unless output.checkpoints is false) and how to restart.
class RunInterrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Run a validated config from t = 0 (dispatches on simulation.dimension).
RunSummary run(const Config& config, const RunOptions& options);

/// A note for runs whose time step is likely too large for their update: FMPM(k) replaces the
/// lumped mass by a k-term expansion of the full mass matrix, which lowers the critical time step
/// by up to sqrt(k) on GIMP and B-spline grids (docs/update-schemes.md, measured limits). Empty
/// when the CFL rule with simulation.cfl * sqrt(k) <= 0.6 is used, or for other updates.
std::string time_step_note(const Config& config);

/// The keys `cairn restart --set` honours: when the run stops and how long, threads and memory
/// guards, what is written and where. Any other key (a material, the grid, the method, a body,
/// a boundary condition) made the state the checkpoint holds, so a new value would not reach
/// it: restart() refuses it.
const std::vector<std::string>& restart_keys();

/// Continue from a checkpoint written by run(); `overrides` (`--set`, only restart_keys()) apply
/// to the stored input; any other key throws InputError (exit 2), and so does a checkpoint that
/// already reached simulation.end_time (the message says how to go on).
/// The output goes to the checkpoint's folder unless an override sets output.directory; there
/// history.csv and the XDMF files are first cut back to the checkpoint's time (later snapshot
/// files of the series are deleted). A restart without overrides ends bit-identical to the run
/// that never stopped.
RunSummary restart(const std::filesystem::path& checkpoint, const std::vector<std::string>& overrides,
                   const RunOptions& options);

}  // namespace cairn
