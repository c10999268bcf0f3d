// The MPM engine (and the WLS method, which runs on the same state): a Simulation<D> with its
// outputs, stepped by run/engine.hpp's drive() or the Python module.
#include <fmt/format.h>
#include <omp.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <exception>
#include <regex>

#include "cairn/bc/expression.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/io/checkpoint.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/io/history.hpp"
#include "cairn/input/input.hpp"
#include "cairn/io/output_schedule.hpp"
#include "cairn/io/snapshot.hpp"
#include "cairn/parallel/agree.hpp"
#include "cairn/run/engine.hpp"
#include "cairn/run/mpm_check.hpp"
#include "cairn/sim/resources.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/sim/thread_tuner.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/wls/fields.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn {
namespace {

using Clock = std::chrono::steady_clock;

/// Remove temporaries `<name>.tmp.<pid>[.<n>]` (atomic_file.hpp) that a killed run left in
/// `folder`: only regular files whose writing process no longer exists.
void remove_orphan_temporaries(const std::filesystem::path& folder) {
  static const std::regex pattern(R"(.+\.tmp\.([0-9]{1,10})(\.[0-9]+)?)");
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) return;
  std::vector<std::filesystem::path> orphans;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    std::smatch m;
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file(ec) || entry.is_symlink(ec) || !std::regex_match(name, m, pattern)) continue;
    const long long pid = std::stoll(m[1].str());
    const bool alive = pid > 0 && pid <= 0x7fffffff && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
    if (!alive || pid == static_cast<long long>(::getpid())) orphans.push_back(entry.path());
  }
  for (const auto& p : orphans) std::filesystem::remove(p, ec);
}

/// The files of Cairn's numbered outputs in a run folder (docs/output.md): snapshot files,
/// checkpoints, failure snapshots and the XDMF indexes of those series. An earlier run's are
/// removed before a new run writes there (output.existing), so that a script that globs the
/// folder sees one run; history.csv is rewritten anyway.
std::vector<std::filesystem::path> earlier_outputs(const std::filesystem::path& folder) {
  static const std::regex top(R"((checkpoint-([0-9]{4,}|autosave)\.h5|(particles|grid|wls_cells|failure)\.xdmf))");
  static const std::regex numbered(R"((particles|wls_cells|failure)-[0-9]{6}\.h5)");
  std::vector<std::filesystem::path> found;
  std::error_code ec;
  for (const auto& [where, pattern] : {std::pair{folder, &top}, std::pair{folder / "snapshots", &numbered}}) {
    if (!std::filesystem::is_directory(where, ec)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(where, ec))
      if (entry.is_regular_file(ec) && std::regex_match(entry.path().filename().string(), *pattern))
        found.push_back(entry.path());
  }
  std::sort(found.begin(), found.end());
  return found;
}

const std::vector<std::string> history_columns = {
    "kinetic_energy", "strain_energy", "external_work", "total_energy", "energy_error",
    "dissipated_energy", "momentum_x", "momentum_y", "momentum_z", "mean_temperature",
    "max_pressure"};

/// The run sums the WLS energy budget (method.energy_budget; docs/wls.md, "Energy budget").
template <int D>
bool has_energy_budget(const Simulation<D>& sim) {
  return sim.wls() != nullptr && sim.wls()->options().energy_budget;
}

/// The columns of history.csv: the fixed ones, then per [[velocity]]/[[wall]] its reaction force
/// reaction_<name>_<axis> (seed 000 Sec. 2.4, summed over its nodes, from the last step), then per
/// wall its position wall_<name>_position; in multimaterial mode contact_nodes (nodes seeing two or
/// more fields), contact_active (nodes corrected by the last momentum-update pass) and per field
/// pair the contact force on the first from the second, contact_<a>_<b>_<axis> (seed 004 Eq. 33).
template <int D>
std::vector<std::string> history_columns_of(const Simulation<D>& sim) {
  std::vector<std::string> columns = history_columns;
  for (const auto& name : sim.velocity_conditions().names())
    for (int a = 0; a < D; ++a) columns.push_back(fmt::format("reaction_{}_{}", name, "xyz"[a]));
  for (const auto& wall : sim.velocity_conditions().walls())
    columns.push_back(fmt::format("wall_{}_position", wall.name()));
  if (!sim.config().output.exact_displacement.empty()) {
    columns.push_back("displacement_error");
    columns.push_back("displacement_error_max");
  }
  if (has_energy_budget(sim)) {  // the WLS step's kinetic-energy budget (docs/wls.md, "Energy budget")
    columns.push_back("wls_grid_work");
    columns.push_back("wls_transfer_energy");
  }
  if (const auto* c = sim.contact()) {
    columns.push_back("contact_nodes");
    columns.push_back("contact_active");
    columns.push_back("contact_dissipated_energy");
    for (const auto& [a, b] : c->pairs())
      for (int k = 0; k < D; ++k)
        columns.push_back(fmt::format("contact_{}_{}_{}", c->field_names()[a], c->field_names()[b], "xyz"[k]));
  }
  // Runs on several ranks, last: the particle imbalance (largest count of a rank / mean count)
  // at the start of the last step; the other columns are those of a serial run, bit for bit.
  if (sim.comm().parallel()) columns.push_back("imbalance");
  return columns;
}

template <int D>
class MpmEngine final : public Engine {
 public:
  MpmEngine(const Config& config, std::string name)
      : name_(std::move(name)),
        config_(config),
        sim_(config, Comm::world()),
        comm_(sim_.comm()),
        dir_(config.output.directory),
        meta_(output_metadata(config)),
        schedule_(config.output, config.simulation.end_time),
        snapshots_(dir_, "particles", meta_, comm_) {
    const auto& out = config_.output;
    if (comm_.is_root()) {  // rank 0 alone manages the folder (docs/parallel.md)
      std::filesystem::create_directories(dir_);
      // WLS (one rank only, refused on several): the integration regions (cut cells) beside
      // every particle snapshot, wls_cells.xdmf.
      if (sim_.wls()) cells_ = std::make_unique<SnapshotWriter<D>>(dir_, "wls_cells");
      remove_orphan_temporaries(dir_);
      remove_orphan_temporaries(dir_ / "snapshots");
    }
    comm_.barrier();
    if (!out.exact_displacement.empty())
      for (int t = 0; t < omp_get_max_threads(); ++t)
        exact_.push_back(std::make_unique<ExpressionVector<D>>(out.exact_displacement, config_.constants));
    n_particles_ = sim_.total_particles();
  }

  /// An exception leaving the run (a full disk, a failed output) still leaves the history rows
  /// computed so far in history.csv.
  ~MpmEngine() override {
    if (std::uncaught_exceptions() == 0) return;
    try {
      flush_history();
    } catch (const std::exception&) {
      // the exception in flight says what went wrong
    }
  }
  MpmEngine(const MpmEngine&) = delete;
  MpmEngine& operator=(const MpmEngine&) = delete;

  void restore(const CheckpointData<D>& data) {
    const std::string& file = config_.source_file;  // the checkpoint (restore_dim)
    const Particles<D>& ps = data.particles;
    const Particles<D>& setup = sim_.particles();  // what the stored input makes
    auto refuse = [&](const std::string& object, const std::string& expected, const std::string& found) {
      throw InputError(file, 0, object, expected, found + " (a damaged or edited checkpoint, or one of another input)");
    };
    // The particle layout the stored input's materials, update and conduction use (an APIC run
    // may continue from a checkpoint without affine velocities: the step starts them at zero).
    if (ps.n_state_per_particle != setup.n_state_per_particle)
      refuse("/particles (attribute n_state_per_particle)",
             fmt::format("{} state variables per particle, as the stored input's materials keep", setup.n_state_per_particle),
             fmt::format("{}", ps.n_state_per_particle));
    if (ps.has_temperature != setup.has_temperature)
      refuse("/particles/temperature", setup.has_temperature ? "temperatures (the stored input conducts heat)" : "none (the stored input conducts no heat)",
             ps.has_temperature ? "a dataset" : "none");
    if (ps.has_affine && !setup.has_affine)
      refuse("/particles/affine_velocity", "none (the stored input's update is not APIC)", "a dataset");
    // The run-loop scalars this engine restores, before any of them is taken.
    for (const char* name : {"external_work", "dissipated_energy", "next_full_mass_time", "initial_energy"})
      (void)stored_scalar(data.scalars, name, file);
    for (std::size_t w = 0; w < sim_.velocity_conditions().walls().size(); ++w)
      (void)stored_scalar(data.scalars, fmt::format("wall_position_{}", w), file);
    if (!exact_.empty()) (void)stored_scalar(data.scalars, "displacement_error_max", file);
    for (const char* name : {"snapshots_done", "history_done", "checkpoints_done"}) (void)stored_count(data.scalars, name, file);
    if (stored_count(data.scalars, "checkpoint_index", file) > 1000000000)
      refuse("/scalars/values (checkpoint_index)", "a checkpoint index 0..1e9", "a larger one");
    // The contact record (release = "separation"): keys of this grid's nodes and field pairs.
    if (!data.contact_record.empty()) {
      const std::int64_t end = sim_.contact() ? sim_.contact()->record_key_end() : 0;
      for (std::int64_t key : data.contact_record)
        if (key < 0 || key >= end)
          refuse("/contact/in_contact",
                 end > 0 ? fmt::format("keys 0..{} of the stored grid's nodes and contact fields", end - 1)
                         : std::string("none (the stored input has no contact)"),
                 fmt::format("the key {}", key));
    }
    // Particle sizes: the stored input makes particles no larger than its largest (a larger
    // stored one would widen a GIMP or CPDI stencil past its limit in the first step).
    double largest[D] = {};
    for (std::size_t p = 0; p < setup.n(); ++p)
      for (int a = 0; a < D; ++a) largest[a] = std::max(largest[a], setup.size0[p][a]);
    comm_.max(largest, D);
    // Each rank checks its share of the rows; a bad row stops every rank with the same message.
    std::string problem;
    try {
      check_positions_in_grid<D>(sim_.grid(), data.particles, config_.source_file);
      for (std::size_t p = 0; p < ps.n(); ++p)
        for (int a = 0; a < D; ++a)
          if (ps.size0[p][a] > largest[a] * (1.0 + 1e-9))
            refuse(fmt::format("/particles/size0[{}]", p),
                   fmt::format("a particle size up to {:.6g}, the largest the stored input makes", largest[a]),
                   fmt::format("{:.6g}", ps.size0[p][a]));
      for (std::size_t p = 0; p < ps.n(); ++p) {
        if (static_cast<std::size_t>(ps.material[p]) >= config_.materials.size())
          refuse(fmt::format("/particles/material[{}]", p),
                 fmt::format("a material index below {}, the stored input's materials", config_.materials.size()),
                 fmt::format("{}", ps.material[p]));
        if (static_cast<std::size_t>(ps.body[p]) >= config_.bodies.size())
          refuse(fmt::format("/particles/body[{}]", p),
                 fmt::format("a body index below {}, the stored input's bodies", config_.bodies.size()),
                 fmt::format("{}", ps.body[p]));
      }
    } catch (const InputError& e) {
      if (!comm_.parallel()) throw;
      problem = e.what();
    }
    const std::int64_t first_bad = comm_.min(problem.empty() ? std::int64_t{comm_.size()} : std::int64_t{comm_.rank()});
    if (first_bad < comm_.size()) {
      comm_.broadcast(problem, static_cast<int>(first_bad));
      throw std::invalid_argument(problem);
    }
    sim_.set_particles(data.particles);
    n_particles_ = sim_.total_particles();
    if (sim_.contact()) sim_.contact()->restore_record(data.contact_record);
    // contact_dissipated_energy: absent from checkpoints written before issue 38 (counted as 0).
    const auto contact_part = data.scalars.find("contact_dissipated_energy");
    sim_.restore_counters(data.time, data.step, data.scalars.at("external_work"),
                          data.scalars.at("dissipated_energy"),
                          contact_part == data.scalars.end() ? 0.0 : contact_part->second,
                          data.scalars.at("next_full_mass_time"));
    auto& walls = sim_.velocity_conditions().walls();
    for (std::size_t w = 0; w < walls.size(); ++w)
      walls[w].set_position(data.scalars.at(fmt::format("wall_position_{}", w)));
    if (has_energy_budget(sim_)) {  // absent from checkpoints of runs without it: 0
      const auto scalar = [&](const char* key) {
        const auto it = data.scalars.find(key);
        return it == data.scalars.end() ? 0.0 : it->second;
      };
      sim_.restore_wls_energy_budget(scalar("wls_grid_work"), scalar("wls_transfer_energy"));
    }
    initial_energy_ = data.scalars.at("initial_energy");
    if (!exact_.empty()) error_max_ = data.scalars.at("displacement_error_max");
    schedule_.restore(data.scalars, data.time);
    checkpoint_index_ = static_cast<int>(data.scalars.at("checkpoint_index"));
    last_dt_ = data.previous_dt;
    try {
      history_writer_.set_rows(rows_for_columns(data));
    } catch (const std::invalid_argument& e) {  // rows of other columns than the stored input's run writes
      refuse("/history/rows", "rows of the history columns the stored input's run writes", e.what());
    }
    // Every output ends where the checkpoint stands, before the first new step.
    flush_history();
    snapshots_.restore(data.snapshot_entries, data.snapshot_next_index);
    if (cells_) {
      // The region files are written in step with the particle files: same index, other stem.
      auto entries = data.snapshot_entries;
      for (auto& [time, file] : entries)
        if (file.rfind("particles-", 0) == 0) file = "wls_cells-" + file.substr(10);
      cells_->restore(entries, data.snapshot_next_index);
    }
    restarted_ = true;
  }

  /// Bodies filled from surface meshes: the volume of their particles (over every rank; the
  /// zero-volume WLS surface particles not counted) beside the mesh's own volume.
  std::vector<std::string> mesh_volume_notes() const {
    std::vector<std::string> notes;
    const auto& P = sim_.particles();
    for (std::size_t b = 0; b < config_.bodies.size(); ++b) {
      const BodyConfig& body = config_.bodies[b];
      if (!body.shape.mesh) continue;
      std::int64_t n = 0;
      for (std::size_t p = 0; p < P.n(); ++p)  // (outside a step every local particle is owned)
        n += static_cast<std::size_t>(P.body[p]) == b && P.volume0[p] > 0.0;
      double v = 1.0;
      for (int a = 0; a < D; ++a) v *= sim_.grid().cell_size()[a] / body.particles_per_cell[static_cast<std::size_t>(a)];
      notes.push_back(geometry::volume_note(body.name, *body.shape.mesh, comm_.sum(n), v));
    }
    return notes;
  }

  [[nodiscard]] std::string name() const override { return name_; }
  [[nodiscard]] const Config& config() const override { return config_; }
  [[nodiscard]] const Comm& comm() const override { return comm_; }
  [[nodiscard]] double time() const override { return sim_.time(); }
  [[nodiscard]] long long step_count() const override { return sim_.step_count(); }
  [[nodiscard]] std::int64_t items() const override { return n_particles_; }
  [[nodiscard]] EngineState state() override { return &sim_; }
  void flush() override { flush_history(); }

  void start() override {
    if (started_) return;
    started_ = true;
    start_ = last_autosave_ = Clock::now();
    first_step_ = sim_.step_count();
    halo_bytes_start_ = sim_.halo_bytes();
    halo_cloud_bytes_start_ = sim_.halo_cloud_bytes();
    halo_seconds_start_ = {sim_.halo_seconds(), sim_.halo_wait_seconds()};
    if (!restarted_) {
      clear_earlier_outputs();
      if (const std::string note = time_step_note(config_); !note.empty() && comm_.is_root())
        std::fprintf(stderr, "cairn: %s\n", note.c_str());
      initial_energy_ = energy();
      measure_error();
      write_history_row();
      write_snapshot();
    }
    tuner_ = std::make_unique<ThreadTuner>(omp_get_max_threads(), config_.simulation.adapt_threads,
                                           &ThreadTuner::runnable_others);
  }

  void step() override {
    start();
    tuner_->before_step();
    const auto step_start = Clock::now();
    const double dt = sim_.next_dt();
    try {
      sim_.step(dt);
    } catch (const SimulationFailure& f) {
      fail(f, dt);
    }
    tuner_->after_step(std::chrono::duration<double>(Clock::now() - step_start).count());
    last_dt_ = dt;
    max_imbalance_ = std::max(max_imbalance_, sim_.imbalance());
    measure_error();
    for (const auto& note : sim_.take_notes()) std::fprintf(stderr, "cairn: %s\n", note.c_str());  // rank 0's
    schedule_.after_step(
        sim_.time(), [&] { write_history_row(); }, [&] { write_snapshot(); }, [&] { write_checkpoint(); });
    const double wall_interval = config_.output.checkpoint_wall_interval;
    // On several ranks the autosave and the stop are decided together (any rank's clock or
    // signal), so that every rank writes the same checkpoint and stops at the same step.
    std::int64_t decide[2] = {config_.output.checkpoints && wall_interval > 0.0 &&
                                  std::chrono::duration<double>(Clock::now() - last_autosave_).count() >= wall_interval,
                              static_cast<std::int64_t>(requested_stop())};
    comm_.max(decide, 2);
    if (decide[0] != 0) {
      write_checkpoint(true);
      last_autosave_ = Clock::now();
    }
    if (decide[1] != 0) stop_after_step(static_cast<int>(decide[1]), dir_);
  }

  RunSummary finish() override {
    start();
    tuner_->finish();
    schedule_.at_end([&] { write_history_row(); }, [&] { write_snapshot(); });
    flush_history();
    if (config_.output.checkpoints) write_checkpoint();

    RunSummary summary;
    summary.steps = sim_.step_count() - first_step_;
    summary.end_time = sim_.time();
    summary.wall_seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    summary.n_particles = static_cast<std::size_t>(n_particles_);
    summary.body_notes = mesh_volume_notes();
    summary.ranks = comm_.size();
    summary.partitions = sim_.distribution().partitions();
    summary.halo = sim_.halo();
    {
      std::int64_t bytes[2] = {sim_.halo_bytes() - halo_bytes_start_, sim_.halo_cloud_bytes() - halo_cloud_bytes_start_};
      comm_.sum(bytes, 2);
      auto per_step = [&](std::int64_t b) {
        return summary.steps > 0 ? static_cast<double>(b) / comm_.size() / static_cast<double>(summary.steps) : 0.0;
      };
      summary.halo_bytes_per_step = per_step(bytes[0]);
      summary.halo_cloud_bytes_per_step = per_step(bytes[1]);
      summary.halo_seconds = comm_.max(sim_.halo_seconds() - halo_seconds_start_[0]);
      summary.halo_wait_seconds = comm_.max(sim_.halo_wait_seconds() - halo_seconds_start_[1]);
    }
    summary.migrated = comm_.sum(sim_.distribution().received());
    summary.max_imbalance = max_imbalance_;
    summary.balance = sim_.config().parallel.balance;
    summary.repartitions = sim_.distribution().repartitions();
    summary.repartition_moved = sim_.distribution().repartition_moved();
    summary.repartition_most_moved = sim_.distribution().repartition_most_moved();
    summary.particle_steps_per_second =
        summary.wall_seconds > 0 ? static_cast<double>(summary.steps) * summary.n_particles / summary.wall_seconds : 0.0;
    summary.output_directory = dir_;
    summary.last_checkpoint = last_checkpoint_;
    summary.stage_seconds = sim_.stage_times();
    summary.adaptive_threads = tuner_->enabled();
    summary.single_thread_steps = tuner_->single_thread_steps();
    summary.particle_sorts = sim_.particle_sorts();
    if (const auto* c = sim_.contact()) {
      summary.contact_prepare_seconds = c->prepare_seconds();
      summary.contact_fit_seconds = c->fit_seconds();
      summary.contact_correct_seconds = c->correct_seconds();
      summary.contact_node_steps = c->node_steps();
    }
    return summary;
  }

  /// A numbered checkpoint-NNNN.h5, or (autosave: wall-clock interval, signals) the one
  /// checkpoint-autosave.h5 that each autosave replaces.
  std::filesystem::path write_checkpoint(bool autosave = false) override {
    const std::filesystem::path path =
        autosave ? dir_ / "checkpoint-autosave.h5" : dir_ / fmt::format("checkpoint-{:04d}.h5", checkpoint_index_++);
    CheckpointData<D> data;
    data.engine = name_;
    data.config_toml = config_.resolved_toml;
    data.time = sim_.time();
    data.step = sim_.step_count();
    data.previous_dt = last_dt_;
    data.scalars = {{"external_work", sim_.external_work()},
                    {"dissipated_energy", sim_.update_dissipated_energy()},
                    {"contact_dissipated_energy", sim_.contact_dissipated_energy()},
                    {"next_full_mass_time", sim_.next_full_mass_time()},
                    {"initial_energy", initial_energy_},
                    {"checkpoint_index", static_cast<double>(checkpoint_index_)}};
    schedule_.save(data.scalars);
    const auto& walls = sim_.velocity_conditions().walls();
    for (std::size_t w = 0; w < walls.size(); ++w) data.scalars[fmt::format("wall_position_{}", w)] = walls[w].position();
    if (!exact_.empty()) data.scalars["displacement_error_max"] = error_max_;
    if (has_energy_budget(sim_)) {
      data.scalars["wls_grid_work"] = sim_.wls_grid_work();
      data.scalars["wls_transfer_energy"] = sim_.wls_transfer_energy();
    }
    data.history_columns = history_writer_.columns();
    data.history_rows = history_writer_.rows();
    data.snapshot_entries = snapshots_.entries();
    data.snapshot_next_index = snapshots_.next_index();
    data.metadata = meta_;
    if (sim_.contact()) data.contact_record = sim_.contact()->record();
    cairn::write_checkpoint<D>(path, data, sim_.particles(), comm_);  // no copy of the particles
    last_checkpoint_ = path;
    return path;
  }

 private:
  /// A new run into a folder where an earlier run left numbered outputs: remove them (saying
  /// how many), keep them or refuse, as output.existing says. Every rank lists the folder (the
  /// same answer on a shared file system), rank 0 alone removes.
  void clear_earlier_outputs() {
    const auto earlier = earlier_outputs(dir_);
    comm_.barrier();
    const std::string& mode = config_.output.existing;
    if (earlier.empty() || mode == "keep") return;
    long long snapshots = 0, checkpoints = 0;
    for (const auto& p : earlier) {
      const std::string name = p.filename().string();
      if (name.rfind("checkpoint-", 0) == 0) ++checkpoints;
      else if (p.extension() == ".h5") ++snapshots;
    }
    const std::string what = fmt::format("{} snapshot file{} and {} checkpoint{} of an earlier run in {}", snapshots,
                                         snapshots == 1 ? "" : "s", checkpoints, checkpoints == 1 ? "" : "s",
                                         dir_.string());
    if (mode == "error")
      throw InputError(config_.source_file, 0, "output.existing",
                       "an output folder without an earlier run's files (output.existing = \"error\")",
                       what + "; remove them, choose another output.directory, or set output.existing = "
                              "\"remove\" or \"keep\"");
    if (comm_.is_root()) {
      std::fprintf(stderr, "cairn: removing %s (output.existing = \"keep\" would keep them)\n", what.c_str());
      std::error_code ec;
      for (const auto& p : earlier) std::filesystem::remove(p, ec);
    }
    comm_.barrier();
  }

  double energy() const {
    const Totals t = sim_.totals();
    return t.kinetic_energy + t.strain_energy;
  }

  /// Eq. 38 of seed 001: the largest |x_p - X_p - u(X_p, t)| now, and over every step so far.
  void measure_error() {
    if (exact_.empty()) return;
    const auto& P = sim_.particles();
    const auto n = static_cast<std::int64_t>(P.n());
    const double t = sim_.time();
    double worst = 0.0;
#pragma omp parallel reduction(max : worst)
    {
      auto& u = *exact_[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
      for (std::int64_t p = 0; p < n; ++p) {
        const Vec<D>& X = P.reference_position[p];
        worst = std::max(worst, (P.position[p] - X - u(X, X, t)).norm());
      }
    }
    error_now_ = comm_.max(worst);  // over every rank's owned particles
    error_max_ = std::max(error_max_, error_now_);
  }

  void write_history_row() {
    const Totals t = sim_.totals();
    const double total = t.kinetic_energy + t.strain_energy;
    std::vector<double> row{t.kinetic_energy, t.strain_energy, sim_.external_work(), total,
                            total - initial_energy_ - sim_.external_work(),
                            sim_.dissipated_energy(), t.momentum[0],
                            t.momentum[1], t.momentum[2], t.mean_temperature, t.max_pressure};
    for (const auto& r : sim_.velocity_conditions().reactions())
      for (int a = 0; a < D; ++a) row.push_back(r[a]);
    for (const auto& wall : sim_.velocity_conditions().walls()) row.push_back(wall.position());
    if (!exact_.empty()) {
      row.push_back(error_now_);
      row.push_back(error_max_);
    }
    if (has_energy_budget(sim_)) {
      row.push_back(sim_.wls_grid_work());
      row.push_back(sim_.wls_transfer_energy());
    }
    if (const auto* c = sim_.contact()) {
      row.push_back(static_cast<double>(c->contact_nodes()));
      row.push_back(static_cast<double>(c->active_nodes()));
      row.push_back(c->dissipated());
      for (const auto& f : c->pair_forces())
        for (int a = 0; a < D; ++a) row.push_back(f[a]);
    }
    if (comm_.parallel()) row.push_back(sim_.imbalance());
    // Every rank keeps the rows (they are global sums, the same everywhere; checkpoints hold
    // them), rank 0 alone writes the file.
    history_writer_.add_row(sim_.time(), sim_.step_count(), last_dt_, row);
    ++rows_since_flush_;
    if (rows_since_flush_ >= 20) {
      flush_history();
      rows_since_flush_ = 0;
    }
  }

  /// The checkpoint's history rows in this run's columns: the same columns unless the run that
  /// wrote it had another number of ranks (the column `imbalance` exists on several ranks only;
  /// rows restored onto several ranks from a one-rank checkpoint say 1 there) or without the WLS
  /// energy budget (method.energy_budget set on restart: its columns say 0 there, as its sums
  /// start from 0).
  std::vector<std::vector<double>> rows_for_columns(const CheckpointData<D>& data) const {
    const auto& now = history_writer_.columns();
    if (data.history_columns == now) return data.history_rows;
    std::vector<std::vector<double>> rows;
    for (const auto& stored : data.history_rows) {
      std::vector<double> row;
      for (const auto& name : now) {
        const auto at = std::find(data.history_columns.begin(), data.history_columns.end(), name);
        if (at != data.history_columns.end() && static_cast<std::size_t>(at - data.history_columns.begin()) < stored.size())
          row.push_back(stored[static_cast<std::size_t>(at - data.history_columns.begin())]);
        else if (name == "imbalance")
          row.push_back(1.0);
        else if (name == "wls_grid_work" || name == "wls_transfer_energy")
          row.push_back(0.0);
      }
      rows.push_back(std::move(row));  // a row still short of a column is refused by set_rows
    }
    return rows;
  }

  void flush_history() {
    if (comm_.is_root()) history_writer_.flush();
  }

  void write_snapshot() {
    if (!config_.output.snapshots) return;
    flush_history();
    const std::vector<std::int32_t> order = sim_.output_order();  // id order (sorted runs)
    if (config_.output.grid_snapshots)
    {
      const NodeField<D> nodes = sim_.grid_totals();
      std::vector<Vec3> normals;
      if (sim_.contact()) sim_.contact()->node_normals(normals);
      snapshots_.write(sim_.particles(), sim_.time(), sim_.step_count(), &sim_.grid(), &nodes,
                       sim_.contact() ? &normals : nullptr, order.empty() ? nullptr : &order);
    }
    else
      snapshots_.write(sim_.particles(), sim_.time(), sim_.step_count(), nullptr, nullptr, nullptr,
                       order.empty() ? nullptr : &order);
    // The regions of the last step (none before the first step).
    if (cells_)
      cells_->write(sim_.wls_fields() ? wls::region_points(*sim_.wls_fields()) : wls::region_points(*sim_.wls()),
                    sim_.time(), sim_.step_count());
  }


  /// The step from sim_.time() by dt failed: write its state, stamped with its own step and time.
  [[noreturn]] void fail(const SimulationFailure& f, double dt) {
    flush_history();
    std::string saved;
    try {
      SnapshotWriter<D> failure(dir_, "failure", meta_, comm_);
      const std::vector<std::int32_t> order = sim_.output_order();
      failure.write(sim_.particles(), sim_.time() + dt, sim_.step_count() + 1, nullptr, nullptr, nullptr,
                    order.empty() ? nullptr : &order);
      saved = "; the failed state is in " + (dir_ / "failure.xdmf").string();
    } catch (const std::exception&) {
      saved = "; the failed state could not be written";
    }
    throw RunFailure(fmt::format("simulation failed at step {} (t = {:.6g}): {}{}; the last good "
                                 "output is in {}",
                                 sim_.step_count() + 1, sim_.time(), f.what(), saved, dir_.string()));
  }

  std::string name_;
  Config config_;
  Simulation<D> sim_;
  Comm comm_;
  std::int64_t n_particles_ = 0;
  double max_imbalance_ = 1.0;
  std::filesystem::path dir_;
  OutputMetadata meta_;
  OutputSchedule schedule_;
  HistoryWriter history_writer_{dir_ / "history.csv", history_columns_of(sim_)};
  SnapshotWriter<D> snapshots_;
  std::unique_ptr<SnapshotWriter<D>> cells_;  ///< WLS integration regions
  std::vector<std::unique_ptr<ExpressionVector<D>>> exact_;  ///< [output] exact_displacement, per thread
  double error_now_ = 0.0, error_max_ = 0.0;
  double initial_energy_ = 0.0;
  double last_dt_ = 0.0;
  int checkpoint_index_ = 0;
  int rows_since_flush_ = 0;
  bool restarted_ = false;
  std::filesystem::path last_checkpoint_;
  Clock::time_point start_{}, last_autosave_{};
  long long first_step_ = 0;
  std::int64_t halo_bytes_start_ = 0;  ///< halo bytes sent before this run's first step
  std::int64_t halo_cloud_bytes_start_ = 0;  ///< of them, particles of contact nodes
  std::array<double, 2> halo_seconds_start_{};  ///< seconds in node-halo sums and exchanges before it
  bool started_ = false;
  std::unique_ptr<ThreadTuner> tuner_;
};

}  // namespace

std::string time_step_note(const Config& config) {
  // Largest cfl * sqrt(k) without a note: the measured limits of docs/update-schemes.md (GIMP
  // FMPM(2) bounded at 0.4, FMPM(8) at 0.2) lie on or above it.
  constexpr double limit = 0.6;
  const int k = config.method.order;
  const double cfl = config.simulation.cfl;
  // Only updates that take the full-mass velocity of the updated momenta (FMPM) change the
  // critical time step; XPIC and blends filter with it and keep the lumped grid update.
  const auto scheme = SchemeRegistry<1>::instance().create("update scheme", config.method.update, config.method);
  if (scheme->full_mass() != FullMass::of_updated || k < 2 || config.simulation.fixed_dt > 0.0) return {};
  const double max_cfl = limit / std::sqrt(static_cast<double>(k));
  if (cfl <= max_cfl) return {};
  return fmt::format(
      "note: FMPM({}) lowers the critical time step (by up to sqrt(k) on GIMP and B-spline grids), so "
      "cfl = {} may be unstable; cfl <= {:.2g} keeps cfl * sqrt(k) <= {} (seed 000 uses 0.2; measured "
      "limits in docs/update-schemes.md)",
      k, cfl, max_cfl, limit);
}

namespace {
/// The WLS method of seed 001 keeps its own node fits and integration regions, which have no
/// ghost exchange: refused on several ranks (every rank throws; rank 0 prints; exit 2).
void refuse_wls_on_ranks(const Config& config, const std::string& where) {
  if (config.method.integration == "wls" && Comm::world().parallel())
    throw std::invalid_argument(where + ": method.integration = \"wls\" runs on one MPI rank only "
                                "(docs/parallel.md); run it without mpirun or with -np 1");
}

std::unique_ptr<Engine> create(const Config& config, const std::string& name) {
  refuse_wls_on_ranks(config, config.source_file);
  switch (config.simulation.dimension) {
    case 1: return std::make_unique<MpmEngine<1>>(config, name);
    case 2: return std::make_unique<MpmEngine<2>>(config, name);
    default: return std::make_unique<MpmEngine<3>>(config, name);
  }
}

template <int D>
std::unique_ptr<Engine> restore_dim(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  const CheckpointData<D> data = read_checkpoint<D>(file, Comm::world());
  // Values no run writes stop every rank with the first bad rank's message (each rank read the
  // rows after those of the ranks before it).
  {
    const Comm world = Comm::world();
    const auto first_row = static_cast<std::size_t>(world.exclusive_prefix(static_cast<std::int64_t>(data.particles.n())));
    agree_on_errors(world, [&] { check_checkpoint_values<D>(file, data, first_row); });
  }
  const Config config = load_config_string(data.config_toml, file.string(), overrides);
  // (--set cannot change the dimension or the engine: restore_engine refuses those keys.)
  if (config.simulation.dimension != D)
    throw InputError(file.string(), 0, "dimension",
                     fmt::format("the dimension of the input stored in it, {}D", config.simulation.dimension),
                     fmt::format("{}D in its root attribute 'dimension' (a damaged or edited checkpoint)", D));
  if (const std::string selected = EngineRegistry::instance().name_for(config); data.engine_named && selected != data.engine)
    throw InputError(file.string(), 0, "engine", fmt::format("'{}', the engine its stored input selects", selected),
                     fmt::format("'{}' (a damaged or edited checkpoint)", data.engine));
  const double end = config.simulation.end_time;
  if (data.time >= end * (1.0 - 1e-12))
    throw InputError(file.string(), 0, "simulation.end_time",
                     fmt::format("an end time after the checkpoint's t = {:.6g} to continue to", data.time),
                     fmt::format("{0:.6g}, where this run finished; to go on, raise it: cairn restart {1} --set "
                                 "simulation.end_time=<a time after {0:.6g}>",
                                 end, file.string()));
  refuse_wls_on_ranks(config, file.string());
  // The stored input's load-time warnings (and those of new --set values), as `cairn run` prints
  // them (rank 0 alone on several ranks).
  if (Comm::world().is_root())
    for (const auto& w : config.warnings) std::fprintf(stderr, "cairn: warning: %s\n", w.c_str());
  auto engine = std::make_unique<MpmEngine<D>>(config, data.engine);
  engine->restore(data);
  return engine;
}

std::unique_ptr<Engine> restore(const std::filesystem::path& file, const std::vector<std::string>& overrides,
                                const RunOptions&) {
  switch (checkpoint_dimension(file)) {
    case 1: return restore_dim<1>(file, overrides);
    case 2: return restore_dim<2>(file, overrides);
    default: return restore_dim<3>(file, overrides);
  }
}

bool is_wls(const Config& config) { return config.method.integration == "wls"; }

}  // namespace

// Seed 000-004's MPM, and seed 001's WLS method, which replaces the particle transfers of the
// same engine state (docs/wls.md).
CAIRN_REGISTER_ENGINE(mpm, "mpm",
                      {"the material point method (seeds 000-004)",
                       [](const Config& c) { return !c.fem.enabled && !is_wls(c); },
                       [](const Config& c, const RunOptions&) { return create(c, "mpm"); }, restore,
                       describe_mpm});
CAIRN_REGISTER_ENGINE(wls, "wls",
                      {"the weighted-least-squares PIC method (seed 001)",
                       [](const Config& c) { return !c.fem.enabled && is_wls(c); },
                       [](const Config& c, const RunOptions&) { return create(c, "wls"); }, restore,
                       describe_mpm});

}  // namespace cairn
