// The reference FEM of seed 001 Appendix A as an engine: its solver with the output schedule of
// the MPM runs (history.csv, snapshots, checkpoints) and the same failure handling.
#include <fmt/format.h>

#include <chrono>
#include <csignal>
#include <cstdio>

#include "cairn/config/errors.hpp"
#include "cairn/fem/output.hpp"
#include "cairn/fem/solver.hpp"
#include "cairn/io/history.hpp"
#include "cairn/input/input.hpp"
#include "cairn/io/output_schedule.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/run/engine.hpp"
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

class FemEngine final : public Engine {
 public:
  explicit FemEngine(const Config& config)
      : config_(config), solver_(config), dir_(config.output.directory),
        history_writer_(dir_ / "history.csv", columns(config)), snapshots_(dir_),
        schedule_(config.output, config.simulation.end_time) {
    std::filesystem::create_directories(dir_);
  }

  void restore(const Checkpoint& c) {
    try {
      solver_.restore(c.state);
    } catch (const std::invalid_argument& e) {  // arrays of another mesh
      throw InputError(config_.source_file, 0, "/x", "the nodes and elements of the mesh its stored input makes",
                       std::string(e.what()) + " (a damaged or edited checkpoint)");
    }
    initial_energy_ = c.scalars.at("initial_energy");
    schedule_.restore(c.scalars, c.scalars.at("time"));
    checkpoint_index_ = static_cast<int>(c.scalars.at("checkpoint_index"));
    last_dt_ = c.scalars.at("previous_dt");
    try {
      history_writer_.set_rows(c.history_rows);
    } catch (const std::invalid_argument& e) {  // rows of other columns than the stored input's run writes
      throw InputError(config_.source_file, 0, "/history_rows", "rows of the history columns the stored input's run writes",
                       std::string(e.what()) + " (a damaged or edited checkpoint)");
    }
    snapshots_.set_entries(c.snapshots);
    restarted_ = true;
  }

  [[nodiscard]] std::string name() const override { return "fem"; }
  [[nodiscard]] const Config& config() const override { return config_; }
  [[nodiscard]] const Comm& comm() const override { return comm_; }
  [[nodiscard]] double time() const override { return solver_.time(); }
  [[nodiscard]] long long step_count() const override { return solver_.step_count(); }
  [[nodiscard]] std::int64_t items() const override { return static_cast<std::int64_t>(solver_.mesh().n_elements()); }
  [[nodiscard]] EngineState state() override { return &solver_; }
  void flush() override { history_writer_.flush(); }

  void start() override {
    if (started_) return;
    started_ = true;
    start_ = Clock::now();
    first_step_ = solver_.step_count();
    if (!restarted_) {
      const FemTotals t = solver_.totals();
      initial_energy_ = t.kinetic_energy + t.strain_energy;
      write_history_row();
      write_snapshot();
    }
  }

  void step() override {
    start();
    const double dt = solver_.next_dt();
    try {
      solver_.step(dt);
    } catch (const SimulationFailure& f) {
      fail(f);
    }
    last_dt_ = dt;
    schedule_.after_step(
        solver_.time(), [&] { write_history_row(); }, [&] { write_snapshot(); }, [&] { write_checkpoint(); });
    if (const int signo = requested_stop(); signo != 0) stop_after_step(signo, dir_);
  }

  RunSummary finish() override {
    start();
    schedule_.at_end([&] { write_history_row(); }, [&] { write_snapshot(); });
    history_writer_.flush();
    if (config_.output.checkpoints) write_checkpoint();

    RunSummary summary;
    summary.steps = solver_.step_count() - first_step_;
    summary.end_time = solver_.time();
    summary.wall_seconds = std::chrono::duration<double>(Clock::now() - start_).count();
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

  std::filesystem::path write_checkpoint(bool autosave = false) override {
    Checkpoint c;
    c.config_toml = config_.resolved_toml;
    c.state = solver_.state();
    const int next_index = autosave ? checkpoint_index_ : checkpoint_index_ + 1;
    c.scalars = {{"initial_energy", initial_energy_},
                 {"checkpoint_index", static_cast<double>(next_index)},
                 {"previous_dt", last_dt_}};
    schedule_.save(c.scalars);
    c.history_columns = history_writer_.columns();
    c.history_rows = history_writer_.rows();
    c.snapshots = snapshots_.entries();
    last_checkpoint_ = autosave ? dir_ / "checkpoint-autosave.h5"
                                : dir_ / fmt::format("checkpoint-{:04d}.h5", checkpoint_index_++);
    fem::write_checkpoint(last_checkpoint_, c);
    return last_checkpoint_;
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
  Comm comm_ = Comm::serial();  // the FEM runs on one rank (docs/fem.md)
  Solver solver_;
  std::filesystem::path dir_;
  HistoryWriter history_writer_;
  SnapshotWriter snapshots_;
  OutputSchedule schedule_;
  double initial_energy_ = 0.0, last_dt_ = 0.0;
  int checkpoint_index_ = 0, rows_since_flush_ = 0;
  bool restarted_ = false, started_ = false;
  Clock::time_point start_{};
  long long first_step_ = 0;
  std::filesystem::path last_checkpoint_;
};


std::unique_ptr<Engine> restore(const std::filesystem::path& checkpoint, const std::vector<std::string>& overrides,
                                const RunOptions&) {
  if (Comm::world().parallel())
    throw std::invalid_argument(checkpoint.string() + ": [fem] runs on one MPI rank only (docs/parallel.md)");
  const Checkpoint data = read_checkpoint(checkpoint);
  const Config config = load_config_string(data.config_toml, checkpoint.string(), overrides);
  if (!config.fem.enabled)
    throw InputError(checkpoint.string(), 0, "engine", "an input of the fem engine ([fem]), as an FEM checkpoint holds",
                     fmt::format("an input of the '{}' engine (a damaged or edited checkpoint)",
                                 EngineRegistry::instance().name_for(config)));
  auto engine = std::make_unique<FemEngine>(config);
  engine->restore(data);
  return engine;
}

std::unique_ptr<Engine> create(const Config& config, const RunOptions&) {
  if (Comm::world().parallel())
    throw std::invalid_argument(config.source_file + ": [fem] runs on one MPI rank only (docs/parallel.md); run "
                                "it without mpirun");
  return std::make_unique<FemEngine>(config);
}

void describe(const Config& config) {
  const Solver solver(config);
  fmt::print("# fem mesh ({}): {} nodes, {} triangles\n", solver.mesh().source, solver.mesh().n_nodes(),
             solver.mesh().n_elements());
  fmt::print("# first time step: {:.6g}\n", solver.next_dt());
}

}  // namespace

CAIRN_REGISTER_ENGINE(fem, "fem",
                      {"the reference explicit FEM of seed 001 Appendix A ([fem])",
                       [](const Config& c) { return c.fem.enabled; }, create, restore, describe});

}  // namespace cairn::fem
