// Grid stencils shared by the WLS integrator's stages (internal to src/cairn/wls): the 3^D block
// of nodes around a node, the narrow cell-corner shape of seed 001 Eq. 5-6, and the walks over a
// particle's stored stencil (Integrator::build_stencils' tensor layout).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

#include "cairn/grid/grid.hpp"

namespace cairn::wls::detail {

constexpr int pow3(int d) { return d == 0 ? 1 : 3 * pow3(d - 1); }

/// fn(nb, offset) for every node nb of the 3^D block around node i (itself included) that the
/// grid holds; offset = position of nb minus that of i, in cells.
template <int D, class Fn>
void for_each_neighbour(const Grid<D>& grid, std::int32_t i, Fn&& fn) {
  const IVec<D> j = grid.multi_index(i);
  std::array<int, D> k{};
  for (int s = 0; s < pow3(D); ++s) {
    IVec<D> jn = j;
    Vec<D> offset;
    for (int a = 0; a < D; ++a) {
      jn[a] += k[a] - 1;
      offset[a] = k[a] - 1;
    }
    for (int a = 0; a < D; ++a) {
      if (++k[a] < 3) break;
      k[a] = 0;
    }
    const std::int32_t nb = grid.node_index(jn);
    if (nb >= 0) fn(nb, offset);
  }
}

/// Narrow shape value and gradient of corner `corner` (bit a: upper node along a) of a cell at the
/// local coordinates xi in [0, 1]^D: the cell-wise form of seed 001 Eq. 5-6 (a point on a node
/// takes the cell it lies in, so sum S = 1 and sum G = 0 hold everywhere).
template <int D>
void corner_shape(int corner, const Vec<D>& xi, const Vec<D>& inv_h, double& S, Vec<D>& G) {
  S = 1.0;
  G.setOnes();
  for (int a = 0; a < D; ++a) {
    const bool up = (corner >> a) & 1;
    const double s = up ? xi[a] : 1.0 - xi[a];
    const double g = (up ? 1.0 : -1.0) * inv_h[a];
    S *= s;
    for (int b = 0; b < D; ++b) G[b] *= (a == b) ? g : s;
  }
}

/// fn(node, S, G) for the corners of the cell holding x that the grid holds: the narrow shape of
/// seed 001 Eq. 5-6 at x.
template <int D, class Fn>
void for_each_corner_at(const Grid<D>& grid, const Vec<D>& x, const Vec<D>& inv_h, Fn&& fn) {
  const Vec<D> u = grid.to_cell_units(x);
  IVec<D> cell;
  Vec<D> local;
  for (int a = 0; a < D; ++a) {
    cell[a] = static_cast<int>(std::floor(u[a]));
    local[a] = u[a] - cell[a];
  }
  for (int corner = 0; corner < (1 << D); ++corner) {
    IVec<D> j = cell;
    for (int a = 0; a < D; ++a) j[a] += (corner >> a) & 1;
    const std::int32_t node = grid.node_index(j);
    if (node < 0) continue;
    double S;
    Vec<D> G;
    corner_shape<D>(corner, local, inv_h, S, G);
    fn(node, S, G);
  }
}

/// fn(k) for the 3^D entries k (the node index along each axis, 0..2) of a WLS stencil, axis 0
/// fastest: the order of the sums, the same for every particle. Inlined with its callers' bodies
/// (GCC kept them out of line, with every captured pointer reloaded per entry).
template <int D, class Fn>
[[gnu::always_inline]] inline void for_each_slot(Fn&& fn) {
  if constexpr (D == 1) {
    for (int i = 0; i < 3; ++i) fn(std::array<int, 1>{i});
  } else if constexpr (D == 2) {
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) fn(std::array<int, 2>{i, j});
  } else {
    for (int l = 0; l < 3; ++l)
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) fn(std::array<int, 3>{i, j, l});
  }
}

/// fn(k) for the 2^D entries of a WLS stencil where the narrow shape S (Eq. 5) and its gradient
/// (Eq. 6) can be nonzero: the corners of the particle's cell, entries first..first + 1 along each
/// axis, with first = 0 where S[0] != 0 (build_stencils: shift 1, x_p in the cell's upper half)
/// and 1 otherwise. The other entries give S = G = 0 exactly, so the sums skip only zero terms.
template <int D, class Fn>
[[gnu::always_inline]] inline void for_each_corner_slot(const double* axis_S, Fn&& fn) {
  int first[D];
  for (int a = 0; a < D; ++a) first[a] = axis_S[6 * a] != 0.0 ? 0 : 1;
  if constexpr (D == 1) {
    for (int i = 0; i < 2; ++i) fn(std::array<int, 1>{first[0] + i});
  } else if constexpr (D == 2) {
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) fn(std::array<int, 2>{first[0] + i, first[1] + j});
  } else {
    for (int l = 0; l < 2; ++l)
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) fn(std::array<int, 3>{first[0] + i, first[1] + j, first[2] + l});
  }
}

/// Stencil entry k of a particle in the tensor layout of build_stencils: its node's storage index
/// (the sum of the axes' offsets) and the product of its per-axis factors, `stride` apart per
/// axis (3 for the wide W, 6 for the narrow S whose gradients follow each axis's values).
template <int D, int stride>
[[gnu::always_inline]] inline std::int32_t stencil_entry(const std::array<int, D>& k, const std::int32_t* axis_node,
                                                         const double* axis_factor, double& product) {
  std::int32_t i = 0;
  product = 1.0;
  for (int a = 0; a < D; ++a) {
    i += axis_node[3 * a + k[a]];
    product *= axis_factor[stride * a + k[a]];
  }
  return i;
}

/// Index of entry (r, c), r <= c, of the packed upper triangle of an n x n symmetric matrix.
constexpr int packed(int r, int c, int n) { return r * n - r * (r - 1) / 2 + (c - r); }

}  // namespace cairn::wls::detail
