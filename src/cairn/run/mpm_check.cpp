#include "cairn/run/mpm_check.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "cairn/config/units.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

/// "1 h 02 min", "3 min 20 s", "4.2 s".
std::string wall_text(double seconds) {
  const long long s = std::llround(seconds);
  if (s >= 3600) return fmt::format("{} h {:02d} min", s / 3600, (s % 3600) / 60);
  if (s >= 60) return fmt::format("{} min {:02d} s", s / 60, s % 60);
  return fmt::format("{:.2g} s", seconds);
}

/// What sets the time step: per material its wave speed and the step it alone would allow
/// (dt = cfl h / (c + max|v|), seed 001 Eq. 34), the estimated number of steps, and the wall
/// time they would take, from a few steps timed here (a copy of the state: the check writes
/// nothing). The estimate assumes the first step throughout; the adaptive step follows the
/// deformation and the velocities.
template <int D>
void describe_time_step(Simulation<D>& sim, double dt) {
  const Config& config = sim.config();
  const auto& s = config.simulation;
  const std::string speed = unit_symbol(s.units, Quantity::velocity);
  const std::string time = unit_symbol(s.units, Quantity::time);
  const double h = sim.grid().min_cell_size();
  double v = 0.0;
  std::vector<char> used(sim.materials().size(), 0);
  for (std::size_t p = 0; p < sim.particles().n(); ++p) {
    v = std::max(v, sim.particles().velocity[p].norm());
    used[static_cast<std::size_t>(sim.particles().material[p])] = 1;
  }
  std::vector<double> c(sim.materials().size(), 0.0);
  for (std::size_t m = 0; m < c.size(); ++m) c[m] = sim.materials()[m]->wave_speed(Mat3::Identity());
  std::size_t fastest = c.size();
  for (std::size_t m = 0; m < c.size(); ++m)
    if (used[m] && (fastest == c.size() || c[m] > c[fastest])) fastest = m;
  for (std::size_t m = 0; m < c.size(); ++m) {
    std::string role = !used[m] ? " (no particles)" : "";
    if (m == fastest) role = s.fixed_dt > 0.0 ? " (fastest; simulation.dt sets the step)" : " (fastest: sets the time step)";
    fmt::print("# material '{}': wave speed {:.4g} {}, step limit cfl h / (c + max|v|) = {:.4g} {}{}\n",
               config.materials[m].name, c[m], speed, s.cfl * h / (c[m] + v), time, role);
  }
  if (!(dt > 0.0) || !std::isfinite(dt)) return;
  const double by_time = std::ceil(s.end_time / dt * (1.0 - 1e-12));
  const double steps = s.max_steps > 0 ? std::min(by_time, static_cast<double>(s.max_steps)) : by_time;
  fmt::print("# estimated steps: {:.6g} (end_time {:.6g} / first time step{})\n", steps, s.end_time,
             s.max_steps > 0 && steps < by_time ? ", bounded by simulation.max_steps" : "");
  // Calibration: up to 20 steps or about half a second of wall time.
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  int timed = 0;
  double seconds = 0.0;
  try {
    while (timed < 20 && seconds < 0.5 && timed < steps) {
      sim.step(sim.next_dt());
      ++timed;
      seconds = std::chrono::duration<double>(Clock::now() - start).count();
    }
  } catch (const std::exception& e) {
    fmt::print("# wall time estimate: none (calibration step {} failed: {})\n", timed + 1, e.what());
    return;
  }
  if (timed == 0) return;
  const int threads = omp_get_max_threads();
  fmt::print("# wall time estimate: {} ({:.3g} s per step over {} timed step{}, {} thread{}; cairn run -t N changes it)\n",
             wall_text(seconds / timed * steps), seconds / timed, timed, timed == 1 ? "" : "s", threads,
             threads == 1 ? "" : "s");
}

template <int D>
void describe_setup(const Config& config) {
  Simulation<D> sim(config);
  const auto& g = sim.grid();
  std::string cells;
  for (int a = 0; a < D; ++a) cells += (a ? " x " : "") + std::to_string(g.n_cells()[a]);
  fmt::print("# grid: {} cells, {} stored nodes (ghost layers {})\n", cells, g.n_nodes(), g.ghost_layers());
  std::vector<std::size_t> per_body(config.bodies.size(), 0);
  std::vector<std::size_t> with_volume(config.bodies.size(), 0);  // (not the WLS surface particles)
  for (std::size_t p = 0; p < sim.particles().n(); ++p) {
    ++per_body[sim.particles().body[p]];
    with_volume[sim.particles().body[p]] += sim.particles().volume0[p] > 0.0;
  }
  for (std::size_t b = 0; b < per_body.size(); ++b) {
    const auto& body = config.bodies[b];
    if (!body.shape.mesh) {
      fmt::print("# body '{}': {} particles\n", body.name, per_body[b]);
      continue;
    }
    double v = 1.0;
    for (int a = 0; a < D; ++a) v *= g.cell_size()[a] / body.particles_per_cell[static_cast<std::size_t>(a)];
    fmt::print("# {}\n", geometry::volume_note(body.name, *body.shape.mesh,
                                                      static_cast<long long>(with_volume[b]), v));
  }
  const double dt = sim.next_dt();
  fmt::print("# first time step: {:.6g}\n", dt);
  describe_time_step(sim, dt);
}

}  // namespace

void describe_mpm(const Config& config) {
  switch (config.simulation.dimension) {
    case 1: describe_setup<1>(config); break;
    case 2: describe_setup<2>(config); break;
    default: describe_setup<3>(config); break;
  }
}

}  // namespace cairn
