// Pieces of Simulation<D> that its source files share (sim/simulation.cpp, step.cpp,
// full_mass.cpp, particle_update.cpp): not for other folders.
#pragma once

#include <omp.h>

#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "cairn/parallel/exact_sum.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn::detail {

/// The clock of the per-stage wall times (Simulation::stage_times).
using StageClock = std::chrono::steady_clock;

/// Node position relative to the particle, taking the periodic wrap into account.
template <int D>
Vec<D> node_offset(const Grid<D>& grid, std::int32_t node, const Vec<D>& x) {
  Vec<D> d = grid.node_position(node) - x;
  for (int a = 0; a < D; ++a) {
    if (!grid.periodic(a)) continue;
    const double L = grid.n_cells()[a] * grid.cell_size()[a];
    d[a] -= L * std::round(d[a] / L);
  }
  return d;
}

}  // namespace cairn::detail

namespace cairn {

template <int D>
template <class Fn>
void Simulation<D>::collectively(Fn&& fn) {
  if (!distributed()) {
    fn();
    return;
  }
  const Comm& comm = distribution_.comm();
  constexpr std::int64_t none = std::numeric_limits<std::int64_t>::max();
  std::int64_t key = none;
  std::string message, quantity;
  try {
    fn();
  } catch (const SimulationFailure& f) {
    const SimulationFailure named = named_by_id(f);
    key = named.particle();
    message = named.what();
    quantity = named.quantity();
  }
  const std::int64_t first = comm.min(key);
  if (first == none) return;
  const auto root = static_cast<int>(comm.min(key == first ? std::int64_t{comm.rank()} : std::int64_t{comm.size()}));
  comm.broadcast(message, root);
  comm.broadcast(quantity, root);
  distribution_.drop_ghosts(particles_);
  throw SimulationFailure(first, quantity, message);
}

}  // namespace cairn
