// Grid stencils shared by the WLS integrator's stages (internal to src/cairn/wls): the 3^D block
// of nodes around a node and the narrow cell-corner shape of seed 001 Eq. 5-6.
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

}  // namespace cairn::wls::detail
