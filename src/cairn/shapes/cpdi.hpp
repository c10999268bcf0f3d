// Convected particle domain interpolation (CPDI; Sadeghirad, Brannon & Burghardt 2011), written
// once for any grid function N (linear: cpdi, quadratic B-spline: b2cpdi; seed 000 Sec. 2.1).
//
// The particle domain is the parallelogram (2D) / parallelepiped (3D) / segment (1D) spanned by
// the initial half edges convected by F: R = F diag(l_p0 / 2), corners x_c = x_p + R s_c with
// s_c in {-1, +1}^D. Seed 000 Sec. 2.1 (bracketed forms) replaces N_i inside the domain by its
// multilinear interpolation from the corners, sum_c M_c(x) N_i(x_c). Because the map
// x = x_p + R xi from the reference cube [-1, 1]^D is affine, both integrals are exact in closed
// form: (1/V_p) int M_c dx = 1 / 2^D and (1/V_p) int grad M_c dx = R^-T s_c / 2^D, so
//     S_pi = 2^-D sum_c N_i(x_c),       G_pi = 2^-D sum_c N_i(x_c) R^-T s_c.
// (In 2D this is the familiar CPDI gradient built from the edge vectors r1, r2: R^-T s_c / 4
// expands to the same cross-product expressions.) Partition of unity, zero gradient sum and exact
// reproduction of linear fields follow from sum_c s_c = 0 and sum_c s_c s_c^T = 2^D I.
//
// Guard for domains that get too distorted: when the domain spans more than
// method.cpdi_max_span cells along some axis, or R is singular or inverted, the particle uses
// the GIMP weights of its undeformed box (uGIMP for cpdi, B2GIMP for b2cpdi) for that step. This
// bounds the stencil (and the cache stride) and avoids the numerical separation of stretched
// domains whose corners fall in disconnected cells (seed 000 Sec. 3.4, item 4).
#pragma once

#include <omp.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <vector>

#include "cairn/shapes/grid_functions.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/shapes/stencil_build.hpp"

namespace cairn {

namespace cpdi_detail {

/// Geometry of one particle's stencil for this step.
template <int D>
struct Domain {
  static constexpr int n_corners = 1 << D;
  Vec<D> xi;                               ///< particle position in cell units
  Eigen::Matrix<double, D, D> Rc;          ///< half edges in cell units (columns)
  std::array<Vec<D>, n_corners> corner;    ///< corner positions in cell units
  std::array<IVec<D>, n_corners> first;    ///< each corner's first node per axis (Fn::first_node)
  IVec<D> lo, dims;                        ///< node box: first node and nodes per axis
  bool fallback = false;                   ///< GIMP of the undeformed box instead
  Vec<D> half;                             ///< fallback: box half-width in cells
};

/// Sign vector s_c of corner c: bit a of c set means +1 along axis a.
template <int D>
Vec<D> corner_sign(int c) {
  Vec<D> s;
  for (int a = 0; a < D; ++a) s[a] = (c >> a) & 1 ? 1.0 : -1.0;
  return s;
}

/// Corners, guard decision and node box; cheap enough to run twice per step. The box is taken
/// from the corners as computed here, so both passes agree to the last bit. The corners' first
/// nodes are kept for the weights (one floor per corner and axis, not two). Inlined, as is
/// accumulate_fixed: out of line the Domain went through the stack on every particle
/// (docs/performance.md, seventh session).
template <int D, class Fn>
[[gnu::always_inline]] inline Domain<D> make_domain(const Grid<D>& grid, const Particles<D>& parts, std::size_t p,
                                                    double max_span) {
  Domain<D> dom;
  const Vec<D> inv_h = grid.cell_size().cwiseInverse();
  dom.xi = grid.to_cell_units(parts.position[p]);
  const Vec<D> half_size = 0.5 * parts.size0[p];
  const auto F = parts.deformation_gradient[p].template topLeftCorner<D, D>();
  dom.Rc = inv_h.asDiagonal() * F * half_size.asDiagonal();
  const Vec<D> spread = 2.0 * dom.Rc.cwiseAbs().rowwise().sum();
  const double det = F.determinant();
  bool ok = std::isfinite(det) && det > 0.0;
  for (int a = 0; a < D && ok; ++a) ok = spread[a] <= max_span;
  if (!ok) {
    dom.fallback = true;
    dom.half = half_size.cwiseProduct(inv_h);
    for (int a = 0; a < D; ++a) {
      dom.lo[a] = static_cast<int>(std::ceil(dom.xi[a] - Fn::support - dom.half[a]));
      dom.dims[a] = convolved_width<Fn>(dom.half[a]);
    }
    return dom;
  }
  IVec<D> hi;
  dom.lo.setConstant(INT_MAX);
  hi.setConstant(INT_MIN);
  for (int c = 0; c < Domain<D>::n_corners; ++c) {
    dom.corner[c] = dom.xi + dom.Rc * corner_sign<D>(c);
    for (int a = 0; a < D; ++a) {
      const int f = dom.first[c][a] = Fn::first_node(dom.corner[c][a]);
      dom.lo[a] = std::min(dom.lo[a], f);
      hi[a] = std::max(hi[a], f);
    }
  }
  dom.dims = hi - dom.lo + IVec<D>::Constant(Fn::n_nodes);
  return dom;
}

constexpr int ipow(int base, int exponent) { return exponent == 0 ? 1 : base * ipow(base, exponent - 1); }

/// Fixed node box of the common case: every corner's first node along each axis is lo or lo + 1,
/// so the box is (n_nodes + 1)^D with compile-time strides. Each entry accumulates
/// (G, S) as one vector, so a corner's contribution N (g_c, 1/2^D) is one vector update.
template <int D, class Fn>
struct FixedBox {
  // (G, S) padded to an even count of doubles: every load of an entry (the accumulation's, and
  // G and S in compact_fixed) then reads whole 16-byte halves as they were stored. With (S, G) in
  // 3 doubles, G straddled two stores and every load of it missed store forwarding (the
  // compaction took 20 of 67 ns per particle in BM_Stencil2D/cpdi; docs/performance.md).
  static constexpr int entry_size = (D + 2) / 2 * 2;
  using Entry = Eigen::Matrix<double, entry_size, 1>;
  static constexpr int width = Fn::n_nodes + 1;
  static constexpr int size = ipow(width, D);
  std::array<Entry, size> acc;
};

/// Accumulate S_i = 2^-D sum_c N_i(x_c) and G_i = sum_c N_i(x_c) g_c into a FixedBox; g holds
/// the corner gradients g_c = 2^-D R^-T s_c (physical units).
template <int D, class Fn>
[[gnu::always_inline]] inline void accumulate_fixed(const Domain<D>& dom, const std::array<Vec<D>, (1 << D)>& g,
                                                   FixedBox<D, Fn>& box) {
  using Entry = typename FixedBox<D, Fn>::Entry;
  constexpr int nn = Fn::n_nodes;
  constexpr int W = FixedBox<D, Fn>::width;
  constexpr int n_corners = Domain<D>::n_corners;
  // All corner updates (2^-D, g_c) are assembled before the loop, so that the vector loads in
  // it never wait on the scalar stores that build them.
  std::array<Entry, n_corners> update;
  for (int c = 0; c < n_corners; ++c) {
    update[c].setZero();
    update[c].template head<D>() = g[c];
    update[c][D] = 1.0 / n_corners;
  }
  for (Entry& e : box.acc) e.setZero();
  for (int c = 0; c < n_corners; ++c) {
    double v[D][nn];
    int base = 0, scale = 1;
    for (int a = 0; a < D; ++a) {
      Fn::weights_from(dom.corner[c][a], dom.first[c][a], v[a]);
      base += (dom.first[c][a] - dom.lo[a]) * scale;
      scale *= W;
    }
    const Entry gc = update[c];
    if constexpr (D == 1) {
      for (int i = 0; i < nn; ++i) box.acc[base + i] += v[0][i] * gc;
    } else if constexpr (D == 2) {
      for (int j = 0; j < nn; ++j)
        for (int i = 0; i < nn; ++i) box.acc[base + j * W + i] += (v[0][i] * v[1][j]) * gc;
    } else {
      for (int k = 0; k < nn; ++k)
        for (int j = 0; j < nn; ++j) {
          const double vjk = v[1][j] * v[2][k];
          Entry* row = &box.acc[base + (k * W + j) * W];
          for (int i = 0; i < nn; ++i) row[i] += (v[0][i] * vjk) * gc;
        }
    }
  }
}

/// Write the non-zero entries of a FixedBox into one particle's cache slots. `offset[a][k]` is the
/// storage offset of node lo[a] + k along axis a (-1 beyond the ghost layers). S = 0 means every
/// corner weight was zero (the grid functions are non-negative), so G = 0 too. Returns the
/// number of entries kept; `outside` is set when a non-zero entry has no storage. Writes up to
/// FixedBox::size slots (the cache stride is at least that).
template <int D, class Fn>
int compact_fixed(const FixedBox<D, Fn>& box,
                  const std::array<std::array<std::int32_t, FixedBox<D, Fn>::width>, D>& offset,
                  std::int32_t* node, double* S, Vec<D>* G, bool& outside) {
  constexpr int W = FixedBox<D, Fn>::width;
  constexpr int rows = FixedBox<D, Fn>::size / W;
  int used = 0;
  for (int row = 0; row < rows; ++row) {
    std::int32_t row_node = 0;
    bool row_outside = false;
    int rem = row;
    for (int a = 1; a < D; ++a) {
      const std::int32_t off = offset[a][rem % W];
      rem /= W;
      row_outside |= off < 0;
      row_node += off;
    }
    // Branch-free: every entry is written at `used`, which only advances past non-zero ones
    // (which entries vanish varies from particle to particle, so a branch mispredicts often).
    for (int i = 0; i < W; ++i) {
      const auto& e = box.acc[row * W + i];
      const bool keep = e[D] != 0.0;
      outside |= keep & (row_outside | (offset[0][i] < 0));
      node[used] = row_node + offset[0][i];
      S[used] = e[D];
      G[used] = e.template head<D>();
      used += keep;
    }
  }
  return used;
}

}  // namespace cpdi_detail

/// Fill the cache with CPDI weights of grid function Fn (see the file comment).
template <int D, class Fn>
void build_cpdi(double max_span, const Grid<D>& grid, const Particles<D>& particles,
                TransferCache<D>& cache) {
  using Domain = cpdi_detail::Domain<D>;
  using MatD = Eigen::Matrix<double, D, D>;
  constexpr int n_corners = Domain::n_corners;
  using Fixed = cpdi_detail::FixedBox<D, Fn>;
  constexpr int nn = Fn::n_nodes;
  const auto n = static_cast<std::int64_t>(particles.n());
  const Vec<D> h = grid.cell_size();
  const Vec<D> inv_h = h.cwiseInverse();

  // S_i = 2^-D sum_c N_i(x_c), G_i = sum_c N_i(x_c) g_c with g_c = 2^-D R^-T s_c, where
  // R = diag(h) Rc is the physical half-edge matrix (corner domains only, not the fallback).
  const auto corner_gradients = [&h](const Domain& dom) {
    const MatD RinvT = (h.asDiagonal() * dom.Rc).inverse().transpose() / static_cast<double>(n_corners);
    std::array<Vec<D>, n_corners> g;
    for (int c = 0; c < n_corners; ++c) g[c] = RinvT * cpdi_detail::corner_sign<D>(c);
    return g;
  };
  // The cache stride must hold the largest node box of the step (and at least the fixed box).
  // Reuse the stride of the last step when the cache already has one for these particles; a
  // particle whose box does not fit sends the build through the sizing pass and a second try
  // (rare: the stride only grows).
  int slots = 1, widest = 1;
  bool sized = !(cache.layout == StencilLayout::list && cache.stride > 0 && cache.n == particles.n());
  if (!sized) {
    slots = cache.stride;
    widest = cache.stride;
  }
  StencilReach<D> reach;
  for (int attempt = 0; attempt < 2; ++attempt) {
  if (sized) {
    // Sizing pass: the largest node box of this step, at least the fixed box.
    slots = Fixed::size;
    widest = Fixed::width;
#pragma omp parallel for reduction(max : slots, widest) schedule(static)
    for (std::int64_t p = 0; p < n; ++p) {
      const IVec<D> dims = cpdi_detail::make_domain<D, Fn>(grid, particles, p, max_span).dims;
      slots = std::max(slots, dims.prod());
      widest = std::max(widest, dims.maxCoeff());
    }
    cache.reserve(particles.n(), slots);
  }
  bool overflow = false;
  reach = StencilReach<D>();
  StealingShare share(n);
#pragma omp parallel
  {
    StencilReach<D> local;
    bool overflow_t = false;
    std::vector<std::int32_t> offset(static_cast<std::size_t>(D) * widest);
    std::array<std::vector<double>, D> w1, dw1;  // fallback weights per axis
    cpdi_detail::FixedBox<D, Fn> fixed_box;
    for (int a = 0; a < D; ++a) {
      w1[a].resize(widest);
      dw1[a].resize(widest);
    }
    // Each thread builds the particles it later gathers and scatters, and helps a slower one
    // (util/parallel.hpp).
    auto cursor = share.cursor();
    for (std::int64_t first_p, last_p; cursor.next(first_p, last_p);)
    for (std::int64_t p = first_p; p < last_p; ++p) {
      if (!Grid<D>::indexable(grid.to_cell_units(particles.position[p]))) {  // far outside or NaN
        local.bad(p);
        cache.count[p] = 0;
        continue;
      }
      const Domain dom = cpdi_detail::make_domain<D, Fn>(grid, particles, p, max_span);
      IVec<D> cell;
      for (int a = 0; a < D; ++a) cell[a] = static_cast<int>(std::floor(dom.xi[a]));
      // The common case takes the fixed (n_nodes + 1)^D box; stretched domains, the fallback and
      // a stride sized for smaller boxes take the general box of dom.dims.
      const bool fixed = !dom.fallback && dom.dims.maxCoeff() <= Fixed::width &&
                         Fixed::size <= cache.stride;
      const IVec<D> dims = fixed ? IVec<D>::Constant(Fixed::width) : dom.dims;
      IVec<D> stride;
      int box = 1;
      for (int a = 0; a < D; ++a) {
        stride[a] = box;
        box *= dims[a];
      }
      if (box > cache.stride || dims.maxCoeff() > widest) {
        overflow_t = true;  // the reused stride is too small: size and build again
        continue;
      }
      const std::size_t out = static_cast<std::size_t>(p) * cache.stride;
      double* S = &cache.weight[out];
      Vec<D>* G = &cache.gradient[out];
      if (fixed) {
        cpdi_detail::accumulate_fixed<D, Fn>(dom, corner_gradients(dom), fixed_box);
      } else {
        // General box: accumulate straight into the particle's cache slots (box order,
        // box <= stride), compacted in place below.
        std::fill(S, S + box, 0.0);
        std::fill(G, G + box, Vec<D>::Zero());
        if (dom.fallback) {
          // GIMP of the undeformed box: tensor product of the exact 1D convolutions.
          for (int a = 0; a < D; ++a)
            convolved_weights<Fn>(dom.xi[a], dom.half[a], dims[a], w1[a].data(), dw1[a].data());
          for (int idx = 0; idx < box; ++idx) {
            double value = 1.0;
            Vec<D> grad = Vec<D>::Ones();
            int rem = idx;
            for (int a = 0; a < D; ++a) {
              const int k = rem % dims[a];
              rem /= dims[a];
              value *= w1[a][k];
              for (int b = 0; b < D; ++b) grad[b] *= (a == b) ? dw1[a][k] * inv_h[a] : w1[a][k];
            }
            S[idx] = value;
            G[idx] = grad;
          }
        } else {
          const std::array<Vec<D>, n_corners> g = corner_gradients(dom);
          for (int c = 0; c < n_corners; ++c) {
            std::array<std::array<double, nn>, D> v;
            int base = 0;
            for (int a = 0; a < D; ++a) {
              Fn::weights_from(dom.corner[c][a], dom.first[c][a], v[a].data());
              base += (dom.first[c][a] - dom.lo[a]) * stride[a];
            }
            for (int idx = 0; idx < cpdi_detail::ipow(nn, D); ++idx) {
              int rem = idx, at = base;
              double N = 1.0;
              for (int a = 0; a < D; ++a) {
                const int k = rem % nn;
                rem /= nn;
                N *= v[a][k];
                at += k * stride[a];
              }
              S[at] += N;
              G[at] += N * g[c];
            }
          }
          const double inv_corners = 1.0 / n_corners;
          for (int idx = 0; idx < box; ++idx) S[idx] *= inv_corners;
        }
      }

      // Compact the non-zero entries into the cache: rows along axis 0, the other axes by an
      // odometer (used <= idx, so the general box compacts in place). The box bounds give the
      // colouring reach.
      for (int a = 0; a < D; ++a) {
        local.lo[a] = std::max(local.lo[a], cell[a] - dom.lo[a]);
        local.hi[a] = std::max(local.hi[a], dom.lo[a] + dom.dims[a] - 1 - cell[a] - 1);
      }
      int used = 0;
      if (fixed) {
        std::array<std::array<std::int32_t, Fixed::width>, D> off;
        for (int a = 0; a < D; ++a)
          for (int k = 0; k < Fixed::width; ++k) off[a][k] = grid.axis_index(a, dom.lo[a] + k);
        bool outside = false;
        used = cpdi_detail::compact_fixed<D, Fn>(fixed_box, off, &cache.node[out], S, G, outside);
        if (outside) local.bad(p);
      } else {
        for (int a = 0; a < D; ++a)
          for (int k = 0; k < dims[a]; ++k) offset[a * widest + k] = grid.axis_index(a, dom.lo[a] + k);
        const int n_rows = box / dims[0];
        IVec<D> k = IVec<D>::Zero();
        for (int row = 0; row < n_rows; ++row) {
          std::int32_t row_node = 0;
          bool row_outside = false;
          for (int a = 1; a < D; ++a) {
            const std::int32_t off = offset[a * widest + k[a]];
            row_outside |= off < 0;
            row_node += off;
          }
          const int first = row * dims[0];
          for (int i = 0; i < dims[0]; ++i) {
            const int idx = first + i;
            if (S[idx] == 0.0 && G[idx].isZero(0.0)) continue;
            const std::int32_t off = offset[i];
            if (row_outside || off < 0) {
              local.bad(p);
              continue;
            }
            cache.node[out + used] = row_node + off;
            S[used] = S[idx];
            G[used] = G[idx];
            ++used;
          }
          for (int a = 1; a < D; ++a) {
            if (++k[a] < dims[a]) break;
            k[a] = 0;
          }
        }
      }
      cache.count[p] = static_cast<std::uint16_t>(used);
    }
#pragma omp critical
    {
      overflow = overflow || overflow_t;
      reach.merge(local);
    }
  }
  if (!overflow) break;
  sized = true;
  }
  finish_stencils(reach, particles, cache, "its CPDI domain");
}

}  // namespace cairn
