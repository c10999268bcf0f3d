#include "cairn/fem/run.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cstdio>

#include "cairn/fem/output.hpp"
#include "cairn/io/history.hpp"
#include "cairn/io/input.hpp"
#include "cairn/io/output_schedule.hpp"
#include "cairn/util/failure.hpp"

namespace cairn::fem {
namespace {

using Clock = std::chrono::steady_clock;


/// history.csv columns: the MPM run's columns that mean something for the FEM, then one
/// reaction_<name>_<axis> per named [[velocity]] condition.
std::vector<std::string> columns(const Config& config) {
  std::vector<std::string> c = {"kinetic_energy", "strain_energy", "external_work", "total_energy",
                                "energy_error",   "momentum_x",    "momentum_y",    "momentum_z",
                                "max_pressure"};
  if (!config.fem.exact_displacement.empty()) c.insert(c.end(), {"displacement_error", "displacement_error_max"});
  for (const auto& v : config.velocity_conditions)
    for (const char* axis : {"x", "y"}) c.push_back(fmt::format("reaction_{}_{}", v.name, axis));
  return c;
}

class Runner {
 public:
  Runner(const Config& config, const RunOptions& options)
      : config_(config), options_(options), solver_(config), dir_(config.output.directory),
        history_writer_(dir_ / "history.csv", columns(config)), snapshots_(dir_),
        schedule_(config.output, config.simulation.end_time) {
    std::filesystem::create_directories(dir_);
  }

  void restore(const Checkpoint& c) {
    solver_.restore(c.state);
    initial_energy_ = c.scalars.at("initial_energy");
    schedule_.restore(c.scalars, c.scalars.at("time"));
    checkpoint_index_ = static_cast<int>(c.scalars.at("checkpoint_index"));
    last_dt_ = c.scalars.at("previous_dt");
    history_writer_.set_rows(c.history_rows);
    snapshots_.set_entries(c.snapshots);
    restarted_ = true;
  }

  RunSummary run() {
    const auto start = Clock::now();
    const long long first_step = solver_.step_count();
    const auto& s = config_.simulation;
    if (!restarted_) {
      const FemTotals t = solver_.totals();
      initial_energy_ = t.kinetic_energy + t.strain_energy;
      write_history_row();
      write_snapshot();
    }
    int last_decile = 0;
    while (solver_.time() < s.end_time * (1.0 - 1e-12) && (s.max_steps == 0 || solver_.step_count() < s.max_steps)) {
      const double dt = solver_.next_dt();
      try {
        solver_.step(dt);
      } catch (const SimulationFailure& f) {
        fail(f);
      }
      last_dt_ = dt;
      const double t = solver_.time();
      schedule_.after_step(
          t, [&] { write_history_row(); }, [&] { write_snapshot(); }, [&] { write_checkpoint_file(); });
      const int decile = static_cast<int>(10.0 * std::min(1.0, t / s.end_time));
      if (!options_.quiet && decile > last_decile) {
        last_decile = decile;
        std::fprintf(stderr, "  step %lld  t = %.6g  (%d%%)\n", solver_.step_count(), t, 10 * decile);
      }
    }
    schedule_.at_end([&] { write_history_row(); }, [&] { write_snapshot(); });
    history_writer_.flush();
    if (config_.output.checkpoints) write_checkpoint_file();

    RunSummary summary;
    summary.steps = solver_.step_count() - first_step;
    summary.end_time = solver_.time();
    summary.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    // For the FEM the "particles" of the summary are the elements (element-steps per second).
    summary.n_particles = solver_.mesh().n_elements();
    summary.item = "element";
    summary.xdmf = "fem.xdmf";
    summary.particle_steps_per_second =
        summary.wall_seconds > 0 ? static_cast<double>(summary.steps) * summary.n_particles / summary.wall_seconds : 0.0;
    summary.output_directory = dir_;
    summary.last_checkpoint = last_checkpoint_;
    return summary;
  }

 private:
  void write_history_row() {
    const FemTotals t = solver_.totals();
    const double total = t.kinetic_energy + t.strain_energy;
    std::vector<double> row{t.kinetic_energy, t.strain_energy, solver_.external_work(), total,
                            total - initial_energy_ - solver_.external_work(), t.momentum[0], t.momentum[1],
                            t.momentum[2], t.max_pressure};
    if (solver_.has_exact_displacement())
      row.insert(row.end(), {solver_.displacement_error(), solver_.displacement_error_max()});
    for (const auto& r : solver_.reactions()) row.insert(row.end(), {r[0], r[1]});
    history_writer_.add_row(solver_.time(), solver_.step_count(), last_dt_, row);
    if (++rows_since_flush_ >= 20) {
      history_writer_.flush();
      rows_since_flush_ = 0;
    }
  }

  void write_snapshot() {
    if (!config_.output.snapshots) return;
    history_writer_.flush();
    snapshots_.write(solver_);
  }

  void write_checkpoint_file() {
    Checkpoint c;
    c.config_toml = config_.resolved_toml;
    c.state = solver_.state();
    c.scalars = {{"initial_energy", initial_energy_},
                 {"checkpoint_index", static_cast<double>(checkpoint_index_ + 1)},
                 {"previous_dt", last_dt_}};
    schedule_.save(c.scalars);
    c.history_columns = history_writer_.columns();
    c.history_rows = history_writer_.rows();
    c.snapshots = snapshots_.entries();
    last_checkpoint_ = dir_ / fmt::format("checkpoint-{:04d}.h5", checkpoint_index_++);
    write_checkpoint(last_checkpoint_, c);
  }

  [[noreturn]] void fail(const SimulationFailure& f) {
    history_writer_.flush();
    std::string saved;
    try {
      SnapshotWriter failure(dir_, "failure");
      failure.write(solver_);
      saved = "; the failed state is in " + (dir_ / "failure.xdmf").string();
    } catch (const std::exception&) {
      saved = "; the failed state could not be written";
    }
    throw RunFailure(fmt::format("simulation failed at step {} (t = {:.6g}): {}{}; the last good output is in {}",
                                 solver_.step_count() + 1, solver_.time(), f.what(), saved, dir_.string()));
  }

  Config config_;
  RunOptions options_;
  Solver solver_;
  std::filesystem::path dir_;
  HistoryWriter history_writer_;
  SnapshotWriter snapshots_;
  OutputSchedule schedule_;
  double initial_energy_ = 0.0, last_dt_ = 0.0;
  int checkpoint_index_ = 0, rows_since_flush_ = 0;
  bool restarted_ = false;
  std::filesystem::path last_checkpoint_;
};

}  // namespace

RunSummary run(const Config& config, const RunOptions& options) {
  Runner runner(config, options);
  return runner.run();
}

RunSummary restart(const std::filesystem::path& checkpoint, const std::vector<std::string>& overrides,
                   const RunOptions& options) {
  const Checkpoint data = read_checkpoint(checkpoint);
  const Config config = load_config_string(data.config_toml, checkpoint.string(), overrides);
  if (!config.fem.enabled) throw std::invalid_argument("--set cannot turn an FEM checkpoint into an MPM run");
  Runner runner(config, options);
  runner.restore(data);
  return runner.run();
}

}  // namespace cairn::fem
