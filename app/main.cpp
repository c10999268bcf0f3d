// The `cairn` command: run, check, keys, restart.
//
// Exit codes: 0 success (also --help, --version); 2 bad input (file, line, key, expected vs.
// found) or a bad command line (no or unknown subcommand, unknown option: a usage line follows);
// 3 the simulation failed (which particle, step, time and quantity), after writing its last good
// output; 1 anything else (an I/O failure such as a full disk, an internal error, or SIGINT/SIGTERM, after writing
// checkpoint-autosave.h5).
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <omp.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <new>
#include <sstream>
#include <vector>

#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/input/plausibility.hpp"
#include "cairn/config/units.hpp"
#include "cairn/input/schema.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/run/engine.hpp"
#include "cairn/util/cpu_quota.hpp"
#include "cairn/util/registry.hpp"

namespace {

void print_summary(const cairn::RunSummary& s) {
  const int threads = omp_get_max_threads();
  const std::string workers =
      s.ranks > 1 ? fmt::format("{} MPI ranks x {} thread{}", s.ranks, threads, threads == 1 ? "" : "s")
                  : fmt::format("{} threads", threads);
  fmt::print("cairn: {} steps to t = {:.6g} in {:.2f} s ({:.3g} {}-steps/s with {}, "
             "{} {}s)\n",
             s.steps, s.end_time, s.wall_seconds, s.particle_steps_per_second, s.item, workers,
             s.n_particles, s.item);
  if (s.adaptive_threads)
    fmt::print("cairn: adaptive threads: {} of {} steps on 1 thread (simulation.adapt_threads)\n",
               s.single_thread_steps, s.steps);
  if (s.particle_sorts > 0)
    fmt::print("cairn: particles sorted into cell-block order {} time{} (simulation.sort_particles)\n",
               s.particle_sorts, s.particle_sorts == 1 ? "" : "s");
  if (s.ranks > 1) {
    fmt::print("cairn: {} domain partitions, {} particles moved between ranks, largest imbalance {:.3f} (of {}, "
               "parallel.balance)\n",
               s.partitions, s.migrated, s.max_imbalance, s.balance == "cost" ? "cost" : "particle counts");
    if (s.repartitions > 0)
      fmt::print("cairn: {} repartition{} moved {} particles, at most {} in one\n", s.repartitions,
                 s.repartitions == 1 ? "" : "s", s.repartition_moved, s.repartition_most_moved);
    fmt::print("cairn: halo of {} (parallel.halo), {:.0f} bytes sent per rank and step{}\n", s.halo,
               s.halo_bytes_per_step,
               s.halo_cloud_bytes_per_step > 0.0
                   ? fmt::format(" ({:.0f} of them particles of contact nodes)", s.halo_cloud_bytes_per_step)
                   : std::string());
    if (s.halo == "nodes")
      fmt::print("cairn: node-halo sums took at most {:.3f} s on a rank ({:.1f}% of the run), {:.3f} s of it in "
                 "the exchange (the most an overlap with the scatter could hide)\n",
                 s.halo_seconds, s.wall_seconds > 0.0 ? 100.0 * s.halo_seconds / s.wall_seconds : 0.0,
                 s.halo_wait_seconds);
  }
  for (const auto& note : s.body_notes) fmt::print("cairn: {}\n", note);
  fmt::print("cairn: output in {} (history.csv, {}, snapshots/)\n", s.output_directory.string(), s.xdmf);
  if (!s.last_checkpoint.empty()) fmt::print("cairn: checkpoint {}\n", s.last_checkpoint.string());
  double total = 0.0;
  for (const auto& [name, sec] : s.stage_seconds) total += sec;
  if (total > 0.0) {
    std::string line = "cairn: time per stage:";
    for (const auto& [name, sec] : s.stage_seconds)
      if (sec > 0.0) line += fmt::format(" {} {:.3f} s ({:.0f}%),", name, sec, 100.0 * sec / total);
    line.pop_back();
    fmt::print("{}\n", line);
  }
  if (s.contact_node_steps > 0) {
    const double c = s.contact_prepare_seconds + s.contact_correct_seconds;
    fmt::print("cairn: contact {:.3f} s ({:.0f}% of the stages; normals and separations {:.3f} s, "
               "corrections {:.3f} s) over {} contact-node steps: {:.3g} us per contact node\n",
               c, total > 0.0 ? 100.0 * c / total : 0.0, s.contact_fit_seconds, s.contact_correct_seconds,
               s.contact_node_steps, 1e6 * c / static_cast<double>(s.contact_node_steps));
  }
}

constexpr const char* usage =
    "usage: cairn run INPUT.toml [--set section.key=value]... [-q] [-t THREADS]\n"
    "       cairn check INPUT.toml [--set section.key=value]...\n"
    "       cairn restart CHECKPOINT.h5 [--set section.key=value]... [-q] [-t THREADS]\n"
    "       cairn keys [--markdown]\n"
    "       cairn --help | --version\n";

/// One line per error of the input, then how many there were when more than one.
void print_input_errors(std::ostream& err, const cairn::InputError& e) {
  const auto* all = dynamic_cast<const cairn::InputErrors*>(&e);
  if (!all) {
    err << "cairn: input error: " << e.what() << "\n";
    return;
  }
  for (const auto& one : all->errors()) err << "cairn: input error: " << one.what() << "\n";
  err << fmt::format("cairn: {} input errors{}\n", all->errors().size(),
                     all->truncated() ? " (reading stopped there: there may be more)" : "");
}

void print_warnings(const cairn::Config& config) {
  for (const auto& w : config.warnings) std::cerr << "cairn: warning: " << w << "\n";
}

/// With OMP_PROC_BIND set, libgomp binds the initial thread to the first place when it loads,
/// and the restart below would inherit that one place as the whole process's affinity: every
/// thread of the restarted process on one core (`OMP_PROC_BIND=close OMP_PLACES=cores` ran -t 2
/// at 0.9x one thread). Before the restart the thread gets back every processor of the places
/// the runtime built from the affinity it was started with, so the restarted runtime builds the
/// same places.
void release_initial_binding() {
  const int n_places = omp_get_num_places();
  if (n_places <= 0) return;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (int place = 0; place < n_places; ++place) {
    std::vector<int> ids(static_cast<std::size_t>(omp_get_place_num_procs(place)));
    omp_get_place_proc_ids(place, ids.data());
    for (const int id : ids)
      if (id >= 0 && id < CPU_SETSIZE) CPU_SET(id, &set);
  }
  if (CPU_COUNT(&set) > 0) ::sched_setaffinity(0, sizeof(set), &set);
}

/// -t, for run and restart.
constexpr const char* threads_help =
    "OpenMP threads, 0..1024 (0 or absent: OMP_NUM_THREADS, else all cores up to the CPU limit of the "
    "control group)";

/// Largest -t: as simulation.threads (input/schema.cpp).
constexpr int max_threads = 1024;

/// "rank 2 of 4: " on a distributed run (an error of one rank stops them all), else nothing.
std::string rank_prefix() {
  const auto& world = cairn::Comm::world();
  return world.parallel() ? fmt::format("rank {} of {}: ", world.rank(), world.size()) : std::string();
}

/// The address-space limit (`ulimit -v`) when one is set, for the out-of-memory message.
std::string address_space_note() {
  struct rlimit r {};
  if (::getrlimit(RLIMIT_AS, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return {};
  return fmt::format("; the process's address-space limit (ulimit -v) is {:.3g} GiB",
                     static_cast<double>(r.rlim_cur) / (1024.0 * 1024.0 * 1024.0));
}

}  // namespace

int main(int argc, char** argv) {
  // OpenMP threads that wait at a barrier spin briefly (1000 rounds, about 35 us here) and then
  // sleep, unless the user chose a policy: spinning without bound makes 2 threads many times
  // slower than 1 when another process is busy on the machine, sleeping at once makes every
  // hand-off between the step's parallel regions cost a wake-up (docs/performance.md, "Threads
  // on a shared machine"; the run loop also falls back to one thread when that is faster,
  // sim/thread_tuner.hpp). libgomp reads the setting when it loads, before main, so the process
  // restarts itself once with it set (same pid),
  // before MPI is initialised.
  if (std::getenv("OMP_WAIT_POLICY") == nullptr && std::getenv("GOMP_SPINCOUNT") == nullptr) {
    ::setenv("GOMP_SPINCOUNT", "1000", 1);
    release_initial_binding();
    ::execv("/proc/self/exe", argv);  // returns only on failure: go on with the runtime's default
  }
  // Under mpirun/srun every rank runs this program (docs/parallel.md); rank 0 alone prints.
  // Every rank reads and validates the input itself, so an input error stops them all with the
  // same exit code; a simulation failure is detected collectively (exit 3 everywhere).
  const cairn::MpiSession mpi(&argc, &argv);
  const bool root = cairn::Comm::world().is_root();
  CLI::App app{"Cairn: material point method for dynamic solid mechanics"};
  app.set_version_flag("--version", std::string("cairn ") + CAIRN_VERSION);
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 success; 2 bad input or command line; 3 the simulation failed (last good\n"
      "output kept); 1 any other error, or interrupted by SIGINT/SIGTERM (after writing\n"
      "checkpoint-autosave.h5). A first simulation: docs/tutorial.md; the files: docs/output.md.");

  std::string input;
  std::vector<std::string> overrides;
  bool quiet = false;
  int threads = 0;
  bool markdown = false;

  auto* run = app.add_subcommand("run", "run a simulation from a TOML input file");
  run->add_option("input", input, "input file")->required();
  run->add_option("--set", overrides, "override an input key: section.key=value (repeatable)");
  run->add_flag("-q,--quiet", quiet, "no progress line and no summary");
  run->add_option("-t,--threads", threads, threads_help)
      ->check(CLI::Range(0, max_threads));

  auto* check = app.add_subcommand("check", "validate an input file and print the resolved settings");
  check->add_option("input", input, "input file")->required();
  check->add_option("--set", overrides, "override an input key: section.key=value (repeatable)");

  auto* keys = app.add_subcommand("keys", "print every input key with its type, default and doc");
  keys->add_flag("--markdown", markdown, "print docs/input.md");

  auto* restart = app.add_subcommand("restart", "continue a run from a checkpoint file");
  restart->add_option("checkpoint", input, "checkpoint-NNNN.h5 written by a run")->required();
  std::string honoured;
  for (const auto& k : cairn::restart_keys()) honoured += (honoured.empty() ? "" : ", ") + k;
  restart->add_option("--set", overrides,
                      "override a key of the stored input, one of those a restart honours: " + honoured +
                          " (others made the stored state and are refused)");
  restart->add_flag("-q,--quiet", quiet, "no progress line and no summary");
  restart->add_option("-t,--threads", threads, threads_help)
      ->check(CLI::Range(0, max_threads));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {  // --help, --version
      std::ostringstream out, err;
      const int code = app.exit(e, out, err);
      if (root) {
        std::cout << out.str();
        std::cerr << err.str();
      }
      return code;
    }
    std::string what = e.what();
    if (argc < 2) {
      what = "no command given";
    } else if (app.get_subcommands().empty()) {
      what = fmt::format("unknown command or option '{}'", argv[1]);
    }
    if (root) std::cerr << "cairn: " << what << "\n" << usage;
    return 2;
  }
  // Only rank 0 talks; the others' standard output and error stay quiet.
  std::ostringstream discard;
  std::ostream& err = root ? std::cerr : discard;
  if (threads > 0) {
    omp_set_num_threads(threads);
    // The command line wins over the input file's simulation.threads (docs/robustness.md).
    overrides.push_back(fmt::format("simulation.threads={}", threads));
  } else if (std::getenv("OMP_NUM_THREADS") == nullptr) {
    // Without a thread count from the user, no more threads than the CPU time the control groups
    // allow (a container's CPU limit; util/cpu_quota.hpp). simulation.threads still wins.
    if (const auto cpus = cairn::cgroup_cpu_limit()) {
      const int seen = omp_get_max_threads(), allowed = cairn::threads_for_cpu_limit(*cpus);
      if (allowed < seen) {
        omp_set_num_threads(allowed);
        if (root && !quiet && (*run || *restart))
          std::cerr << fmt::format("cairn: note: the CPU limit of this process's control group is {:.3g} CPUs of "
                                   "the {} it sees: {} thread{} (-t or OMP_NUM_THREADS to choose)\n",
                                   *cpus, seen, allowed, allowed == 1 ? "" : "s");
      }
    }
  }

  try {
    if (*keys) {
      if (root) std::cout << cairn::keys_text(markdown);
      return 0;
    }
    if (*check) {
      const cairn::Config config = cairn::load_config(input, overrides);
      if (!root) return 0;
      print_warnings(config);
      for (const auto& w : cairn::implausible_material_values(config)) std::cerr << "cairn: warning: " << w << "\n";
      std::cout << config.resolved_toml;
      cairn::describe(config);
      return 0;
    }
    cairn::RunOptions options;
    options.quiet = quiet;
    cairn::RunSummary summary;
    if (*run) {
      const cairn::Config config = cairn::load_config(input, overrides);
      if (root) print_warnings(config);
      summary = cairn::run(config, options);
    } else {
      summary = cairn::restart(input, overrides, options);
    }
    if (!quiet && root) print_summary(summary);
    return 0;
  } catch (const cairn::InputError& e) {
    print_input_errors(err, e);
    return 2;
  } catch (const cairn::UnknownName& e) {
    err << "cairn: input error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    err << "cairn: input error: " << e.what() << "\n";
    return 2;
  } catch (const cairn::RunFailure& e) {
    err << "cairn: " << e.what() << "\n";
    return 3;
  } catch (const cairn::RunInterrupted& e) {
    err << "cairn: " << e.what() << "\n";
    return 1;
  } catch (const std::bad_alloc&) {
    // Other ranks may be waiting in a collective call: on several ranks, stop them all.
    std::cerr << "cairn: error: " << rank_prefix()
              << "out of memory (simulation.memory_limit bounds the setup's estimate" << address_space_note()
              << ")\n";
    if (cairn::Comm::world().parallel()) cairn::Comm::world().abort(1);
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "cairn: error: " << rank_prefix() << e.what() << "\n";
    if (cairn::Comm::world().parallel()) cairn::Comm::world().abort(1);
    return 1;
  }
}
