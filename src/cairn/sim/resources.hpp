// Guards that run before a simulation allocates or loops over anything the input sizes: the
// grid's node count against the 32-bit node index, the memory the setup will need against a
// limit, the bounds of every body's shape (particle generation visits only the lattice points
// inside them), the number of steps the run would take, and the positions of a restarted state.
// Each refusal is an InputError naming the key that drives it (docs/robustness.md).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/particles/particles.hpp"

namespace cairn {

struct GreyImage;
template <int D>
class Simulation;

/// The picture of an image shape: the one the loader read, else (a Config built in code) read
/// from `shape.file`; null for other kinds. Throws std::invalid_argument when unreadable.
std::shared_ptr<const GreyImage> body_image(const BodyConfig& body, const Config& config);

/// Axis-aligned bounds of a body's shape: the in-level pixels of an image; lo > hi on some axis
/// when the shape holds nothing (an image without a pixel in its level range).
template <int D>
struct ShapeBounds {
  Vec<D> lo, hi;
  double fill = 1.0;  ///< fraction of the bounds the shape fills (pi/4 for a circle)
  [[nodiscard]] bool empty() const { return (lo.array() > hi.array()).any(); }
};
template <int D>
ShapeBounds<D> shape_bounds(const BodyShapeConfig& shape, const GreyImage* image, const Grid<D>& grid);

/// The body's particle lattice (particles_per_cell per cell, point i of axis a at
/// origin + (i + 1/2) l_a): the index box [lo, hi] (inclusive) of the points inside the grid
/// that the bounds can hold, widened by one point for round-off; empty when hi < lo.
template <int D>
struct LatticeBox {
  std::array<long long, D> lo{}, hi{};
  [[nodiscard]] double count() const {
    double n = 1.0;
    for (int a = 0; a < D; ++a) n *= hi[a] >= lo[a] ? static_cast<double>(hi[a] - lo[a] + 1) : 0.0;
    return n;
  }
};
template <int D>
LatticeBox<D> lattice_box(const ShapeBounds<D>& bounds, const Grid<D>& grid, const Vec<D>& spacing);

/// Refuse a shape that reaches past the grid by half a particle spacing or more (particles would
/// be lost) unless the body says clip = true. `index` is the body's position in the input.
template <int D>
void check_inside_grid(const BodyConfig& body, std::size_t index, const ShapeBounds<D>& bounds,
                       const Grid<D>& grid, const Vec<D>& spacing);

/// Stored nodes (cells + 1 + 2 ghost layers per non-periodic axis), counted in 64 bits, times
/// the velocity fields must fit the 32-bit node index. Throws InputError at grid.cell_size.
void check_node_count(const Config& config, const std::vector<long long>& n_cells,
                      const std::vector<bool>& periodic, int ghost_layers, int n_fields);

/// Number of velocity fields the setup will have: 1, or one per material / body in contact mode.
int velocity_fields(const Config& config);

/// Bytes the limit allows: simulation.memory_limit GiB, else the machine's memory (the cgroup
/// limit when lower, and what the address-space limit `ulimit -v` leaves free when lower still).
double memory_limit_bytes(const Config& config);

/// Estimate the memory of grid, particles and transfer caches before anything is allocated;
/// refuse (InputError at the key that dominates: a body's particles_per_cell or grid.cell_size)
/// when it exceeds memory_limit_bytes(), and more particles than a 32-bit index holds.
/// `stencil_width`: nodes per axis of one particle's stencil. On `ranks` MPI ranks each rank
/// holds about 1/ranks of the particles and nodes (docs/parallel.md, per-rank generation): the
/// limits apply to that share.
template <int D>
void check_memory(const Config& config, const Grid<D>& grid, int n_fields, int n_state,
                  int stencil_width, int ranks = 1);

/// Refuse a run whose end_time / first time step exceeds simulation.max_estimated_steps (unless
/// max_steps bounds it), naming what sets the step: the material with the fastest wave speed,
/// the initial velocity, heat conduction, or simulation.dt.
template <int D>
void check_run_length(const Simulation<D>& sim);

/// Refuse restored particles (from `source`, a checkpoint) whose positions are not finite or lie
/// outside the grid's stored nodes, compared in floating point before any cell index is formed.
template <int D>
void check_positions_in_grid(const Grid<D>& grid, const Particles<D>& particles, const std::string& source);

}  // namespace cairn
