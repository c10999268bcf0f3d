// Shared builder for tensor-product families (seed 003 Eq. 18): S_pi = prod_a phi(x_a),
// G_pi[a] = phi'(x_a) prod_{b != a} phi(x_b) / h_a. A family supplies only its 1D kernel:
//
//   struct Kernel {
//     int width(const Particles<D>&) const;      // max nodes per axis for this step
//     // first node and per-axis values at particle p, axis a; xi is the position in cell units
//     int eval(const Particles<D>&, std::size_t p, int a, double xi, double* w, double* dw) const;
//     // optional: grid multi-index along axis a of the kernel's k-th value from `first`
//     // (default first + k); open-knot splines store their extra functions in ghost slots
//     int node_of(int a, int first, int k) const;
//   };
//
// eval() returns the first node's multi-index along the axis and fills width() weights and
// derivatives (derivative with respect to xi, i.e. per cell).
#pragma once

#include <omp.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <stdexcept>
#include <string>

#include "cairn/shapes/grid_functions.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/shapes/stencil_build.hpp"

namespace cairn {

namespace tensor_product_detail {

/// Multi-index of the kernel's k-th node along axis a from `first` (open-knot splines map their
/// extra functions to ghost slots).
template <class Kernel>
int node_along(const Kernel& kernel, int a, int first, int k) {
  if constexpr (requires { kernel.node_of(a, first, k); }) return kernel.node_of(a, first, k);
  return first + k;
}

/// Tensor layout with W nodes per axis: per axis the storage offsets, weights and derivatives.
/// Merges the stencils' reach and the lowest failing particle into `reach`.
template <int W, int D, class Kernel>
void build_factored(const Kernel& kernel, const Grid<D>& grid, const Particles<D>& particles,
                    TransferCache<D>& cache, StencilReach<D>& reach) {
  const auto n = static_cast<std::int64_t>(particles.n());
  const Vec<D> inv_h = grid.cell_size().cwiseInverse();
  for_each_stencil<D>(n, reach, [&](std::int64_t p, StencilReach<D>& local) {
    const Vec<D> xi = grid.to_cell_units(particles.position[p]);
    std::int32_t* node_out = &cache.axis_node[static_cast<std::size_t>(p) * D * W];
    double* value_out = &cache.axis_value[static_cast<std::size_t>(p) * D * 2 * W];
    if (!Grid<D>::indexable(xi)) {  // far outside (or NaN): no cell index to form
      local.bad(p);
      std::fill(node_out, node_out + D * W, 0);
      std::fill(value_out, value_out + D * 2 * W, 0.0);
      return;
    }
    for (int a = 0; a < D; ++a) {
      double w[W] = {}, dw[W] = {};  // a kernel may leave them unset outside its domain
      const int first = kernel.eval(particles, p, a, xi[a], w, dw);
      const int cell = static_cast<int>(std::floor(xi[a]));
      std::int32_t offset[W];
      std::int32_t stored = -1;
      for (int k = 0; k < W; ++k) {
        const int j = node_along(kernel, a, first, k);
        offset[k] = grid.axis_index(a, j);
        if (offset[k] >= 0) stored = offset[k];
        // Every entry is visited by the transfers, so the reach is the full width.
        local.lo[a] = std::max(local.lo[a], cell - j);
        local.hi[a] = std::max(local.hi[a], j - cell - 1);
      }
      // A node beyond the ghost layers is an error where the particle has weight there; where
      // it has none (phi = dphi = 0) the entry is kept with a stored neighbour's offset, so
      // the transfers add zeros to a node of the stencil.
      for (int k = 0; k < W; ++k) {
        if (offset[k] < 0) {
          if (w[k] != 0.0 || dw[k] != 0.0 || stored < 0) local.bad(p);
          offset[k] = std::max(stored, 0);
        }
        node_out[a * W + k] = offset[k];
        value_out[a * 2 * W + k] = w[k];
        value_out[a * 2 * W + W + k] = dw[k] * inv_h[a];
      }
    }
  });
}

/// List layout: the expanded entries (S, G) with S != 0 or G != 0, for any width.
template <int D, class Kernel>
void build_expanded(const Kernel& kernel, int width, const Grid<D>& grid, const Particles<D>& particles,
                    TransferCache<D>& cache, StencilReach<D>& reach) {
  constexpr int max_width = 8;
  int slots = 1;
  for (int a = 0; a < D; ++a) slots *= width;
  const auto n = static_cast<std::int64_t>(particles.n());
  const Vec<D> inv_h = grid.cell_size().cwiseInverse();
  for_each_stencil<D>(n, reach, [&](std::int64_t p, StencilReach<D>& local) {
    std::array<std::array<double, max_width>, D> w{}, dw{};
    IVec<D> first;
    const Vec<D> xi = grid.to_cell_units(particles.position[p]);
    if (!Grid<D>::indexable(xi)) {  // far outside (or NaN): no cell index to form
      local.bad(p);
      cache.count[p] = 0;
      return;
    }
    IVec<D> cell;
    for (int a = 0; a < D; ++a) {
      cell[a] = static_cast<int>(std::floor(xi[a]));
      first[a] = kernel.eval(particles, p, a, xi[a], w[a].data(), dw[a].data());
    }
    // Per-axis storage offsets of the stencil nodes (-1: beyond the ghost layers).
    std::array<std::array<std::int32_t, max_width>, D> offset{};
    for (int a = 0; a < D; ++a)
      for (int k = 0; k < width; ++k) {
        const int j = node_along(kernel, a, first[a], k);
        offset[a][k] = grid.axis_index(a, j);
        if (w[a][k] == 0.0 && dw[a][k] == 0.0) continue;  // outside the support: no reach
        local.lo[a] = std::max(local.lo[a], cell[a] - j);
        local.hi[a] = std::max(local.hi[a], j - cell[a] - 1);
      }
    const std::size_t base = static_cast<std::size_t>(p) * slots;
    int used = 0;
    std::array<int, D> k{};  // odometer over the width^D box, axis 0 fastest
    for (int s = 0; s < slots; ++s) {
      double S = 1.0;
      Vec<D> G = Vec<D>::Ones();
      std::int32_t idx = 0;
      bool outside = false;
      for (int a = 0; a < D; ++a) {
        S *= w[a][k[a]];
        for (int b = 0; b < D; ++b) G[b] *= (a == b) ? dw[a][k[a]] * inv_h[a] : w[a][k[a]];
        outside |= offset[a][k[a]] < 0;
        idx += offset[a][k[a]];
      }
      for (int a = 0; a < D; ++a) {
        if (++k[a] < width) break;
        k[a] = 0;
      }
      if (S == 0.0 && G.isZero(0.0)) continue;  // outside the support
      if (outside) {
        local.bad(p);
        continue;
      }
      cache.node[base + used] = idx;
      cache.weight[base + used] = S;
      cache.gradient[base + used] = G;
      ++used;
    }
    cache.count[p] = static_cast<std::uint16_t>(used);
  });
}

}  // namespace tensor_product_detail

template <int D, class Kernel>
void build_tensor_product(const Kernel& kernel, const Grid<D>& grid, const Particles<D>& particles,
                          TransferCache<D>& cache) {
  using namespace tensor_product_detail;
  constexpr int max_width = 8;
  const int width = kernel.width(particles);
  if (width > max_width)
    throw std::invalid_argument("shape family: a stencil " + std::to_string(width) +
                                " nodes wide per axis exceeds the limit of " +
                                std::to_string(max_width) +
                                " (smoothing length or particle size too large for the cell size)");
  // Widths 2-4 (every family at ordinary particle sizes) keep the per-axis factors (tensor
  // layout); wider GIMP stencils are expanded into the list layout.
  const auto n = particles.n();
  StencilReach<D> reach;
  if (width >= 2 && width <= 4) {
    cache.reserve_tensor(n, width);
    if (width == 2) build_factored<2>(kernel, grid, particles, cache, reach);
    else if (width == 3) build_factored<3>(kernel, grid, particles, cache, reach);
    else build_factored<4>(kernel, grid, particles, cache, reach);
  } else {
    int slots = 1;
    for (int a = 0; a < D; ++a) slots *= width;
    cache.reserve(n, slots);
    build_expanded(kernel, width, grid, particles, cache, reach);
  }
  finish_stencils(reach, particles, cache, "its stencil");
}

}  // namespace cairn
