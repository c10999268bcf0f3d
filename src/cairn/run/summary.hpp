// What a run reports and how it ends: the options of a run, its summary, and the two ways it stops
// early (run/engine.hpp runs the engines that fill them).
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

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
  std::string halo;             ///< several ranks: parallel.halo in effect (nodes | particles)
  double halo_seconds = 0.0;         ///< node halo: the most seconds a rank spent in halo sums
  double halo_wait_seconds = 0.0;    ///< of them, the most a rank spent in their exchanges
  double halo_bytes_per_step = 0.0;  ///< several ranks: mean bytes a rank sent per step in halo exchanges
  double halo_cloud_bytes_per_step = 0.0;  ///< of them, particles of contact nodes (node halo with contact)
  int partitions = 0;           ///< domain partitions (start-up and repartitions), several ranks
  long long migrated = 0;       ///< particles that moved between ranks
  double max_imbalance = 1.0;   ///< largest imbalance (of counts or costs) seen at a step's start
  std::string balance;          ///< parallel.balance: what the imbalance measures (count | cost)
  int repartitions = 0;         ///< repartitions during the run (not the start-up partition)
  long long repartition_moved = 0, repartition_most_moved = 0;  ///< particles they moved; most in one
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

}  // namespace cairn
