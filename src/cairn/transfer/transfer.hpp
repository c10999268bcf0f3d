// Generic particle<->grid kernels over the transfer cache, written once for every shape family.
//
// A kernel's callback gets a particle index and that particle's stencil, whose for_each(fn)
// calls fn(node, S, G) for every entry: node is the storage index (add the particle's field
// offset in multimaterial mode), S = S_pi and G = G_pi. The stencil type depends on the cache
// layout (transfer/cache.hpp), so callbacks are generic lambdas ([&](auto p, const auto& st));
// each kernel picks the layout once per call and the entry loop is compiled for it.
//
// Parallel strategy and the guarantee it gives: particles are binned into blocks of cells wide
// enough that two blocks of the same colour never touch a common node. Scatters run colour by
// colour; within a colour, blocks run in parallel and each block adds its particles in storage
// order. Every node therefore receives its contributions in an order that does not depend on
// the number of threads, so results are bit-identical for any OMP_NUM_THREADS.
#pragma once

#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/parallel/exact_sum.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/transfer/cache.hpp"
#include "cairn/util/parallel.hpp"

namespace cairn {

/// Bin particles into coloured cell blocks by the cell holding each particle (grid.cell_of) and
/// the reach reported by the shape family. Call after every stencil build. Allocation-free once
/// sized.
template <int D>
void colour_blocks(const Grid<D>& grid, const Particles<D>& particles, TransferCache<D>& cache);

/// One particle's stencil in the list layout.
template <int D>
struct ListStencil {
  const std::int32_t* node;
  const double* weight;
  const Vec<D>* gradient;
  int count;

  template <class Fn>
  void for_each(Fn&& fn) const {
    for (int s = 0; s < count; ++s) fn(node[s], weight[s], gradient[s]);
  }
  /// fn(node, S, stress G) for every entry (the internal-force term of P2G).
  template <class Fn>
  void for_each_force(const Eigen::Matrix<double, D, D>& stress, Fn&& fn) const {
    for (int s = 0; s < count; ++s) fn(node[s], weight[s], Vec<D>(stress * gradient[s]));
  }
  /// sum over entries of u_i (x) G_i, u_i = u[node + offset] (the velocity gradient of Task 5).
  [[nodiscard]] Eigen::Matrix<double, D, D> gradient_of(const std::vector<Vec<D>>& u, std::int32_t offset) const {
    double l[D][D] = {};  // plain doubles stay in registers (docs/performance.md, "sums")
    for (int s = 0; s < count; ++s) {
      const Vec<D>& v = u[node[s] + offset];
      for (int a = 0; a < D; ++a)
        for (int b = 0; b < D; ++b) l[a][b] += v[a] * gradient[s][b];
    }
    Eigen::Matrix<double, D, D> out;
    for (int a = 0; a < D; ++a)
      for (int b = 0; b < D; ++b) out(a, b) = l[a][b];
    return out;
  }
};

/// One particle's stencil in the tensor layout with W nodes per axis: entry (k_0, ..., k_D-1),
/// axis 0 fastest, has node sum_a offset_a(k_a), S = prod_a phi_a(k_a) and
/// G_b = prod_a (a == b ? dphi_a : phi_a)(k_a) (seed 003 Eq. 18), the products taken in axis order.
template <int D, int W>
struct TensorStencil {
  static constexpr int width = W;
  const std::int32_t* node;  ///< D x W offsets
  const double* value;       ///< D x 2W: phi then dphi per axis

  template <class Fn>
  void for_each(Fn&& fn) const {
    const double* w0 = value;
    const double* d0 = value + W;
    if constexpr (D == 1) {
      for (int i = 0; i < W; ++i) fn(node[i], w0[i], Vec<1>(d0[i]));
    } else {
      const double* w1 = value + 2 * W;
      const double* d1 = value + 3 * W;
      if constexpr (D == 2) {
        for (int j = 0; j < W; ++j)
          for (int i = 0; i < W; ++i) fn(node[i] + node[W + j], w0[i] * w1[j], Vec<2>(d0[i] * w1[j], w0[i] * d1[j]));
      } else {
        const double* w2 = value + 4 * W;
        const double* d2 = value + 5 * W;
        for (int k = 0; k < W; ++k)
          for (int j = 0; j < W; ++j) {
            const std::int32_t row = node[W + j] + node[2 * W + k];
            for (int i = 0; i < W; ++i) {
              const double w01 = w0[i] * w1[j];
              fn(row + node[i], w01 * w2[k],
                 Vec<3>((d0[i] * w1[j]) * w2[k], (w0[i] * d1[j]) * w2[k], w01 * d2[k]));
            }
          }
      }
    }
  }
  /// As ListStencil::for_each_force and gradient_of, by sum factorisation (tensor_force below).
  template <class Fn>
  void for_each_force(const Eigen::Matrix<double, D, D>& stress, Fn&& fn) const;
  [[nodiscard]] Eigen::Matrix<double, D, D> gradient_of(const std::vector<Vec<D>>& u, std::int32_t offset) const;
};

/// The same operations on the tensor layout by sum factorisation: G_i is never formed. The
/// force stress G_ijk = w2_k (w1_j A_i + dw1_j B_i) + dw2_k w1_j C_i with A_i = dw0_i s_0,
/// B_i = w0_i s_1, C_i = w0_i s_2 (s_b the stress columns), and the gradient
/// sum_ijk u_ijk (x) G_ijk takes the sums over i first: a_jk = sum_i dw0_i u_ijk and
/// b_jk = sum_i w0_i u_ijk, then L = sum_jk [w1_j w2_k a_jk, dw1_j w2_k b_jk, w1_j dw2_k b_jk].
/// For a 3D quadratic B-spline that is 6 instead of 15 multiply-adds per entry.
template <int D, int W>
void tensor_force(const TensorStencil<D, W>& st, const Eigen::Matrix<double, D, D>& stress, auto&& fn) {
  if constexpr (D != 3) {
    st.for_each([&](std::int32_t node, double S, const Vec<D>& G) { fn(node, S, Vec<D>(stress * G)); });
  } else {
    const std::int32_t* n = st.node;
    const double *w0 = st.value, *d0 = w0 + W, *w1 = w0 + 2 * W, *d1 = w0 + 3 * W, *w2 = w0 + 4 * W,
                 *d2 = w0 + 5 * W;
    double A[W][3], B[W][3], C[W][3];
    for (int i = 0; i < W; ++i)
      for (int r = 0; r < 3; ++r) {
        A[i][r] = d0[i] * stress(r, 0);
        B[i][r] = w0[i] * stress(r, 1);
        C[i][r] = w0[i] * stress(r, 2);
      }
    for (int k = 0; k < W; ++k)
      for (int j = 0; j < W; ++j) {
        const std::int32_t row = n[W + j] + n[2 * W + k];
        const double wjk = w1[j] * w2[k], djk = d1[j] * w2[k], ejk = w1[j] * d2[k];
        for (int i = 0; i < W; ++i) {
          const Vec<3> f(wjk * A[i][0] + djk * B[i][0] + ejk * C[i][0],
                         wjk * A[i][1] + djk * B[i][1] + ejk * C[i][1],
                         wjk * A[i][2] + djk * B[i][2] + ejk * C[i][2]);
          fn(row + n[i], w0[i] * wjk, f);
        }
      }
  }
}

template <int D, int W>
Eigen::Matrix<double, D, D> tensor_gradient_of(const TensorStencil<D, W>& st, const std::vector<Vec<D>>& u,
                                               std::int32_t offset) {
  double l[D][D] = {};  // plain doubles stay in registers (docs/performance.md, "sums")
  if constexpr (D != 3) {
    st.for_each([&](std::int32_t node, double, const Vec<D>& G) {
      const Vec<D>& v = u[node + offset];
      for (int a = 0; a < D; ++a)
        for (int b = 0; b < D; ++b) l[a][b] += v[a] * G[b];
    });
  } else {
    const std::int32_t* n = st.node;
    const double *w0 = st.value, *d0 = w0 + W, *w1 = w0 + 2 * W, *d1 = w0 + 3 * W, *w2 = w0 + 4 * W,
                 *d2 = w0 + 5 * W;
    for (int k = 0; k < W; ++k)
      for (int j = 0; j < W; ++j) {
        const std::int32_t row = n[W + j] + n[2 * W + k] + offset;
        double a[3] = {}, b[3] = {};
        for (int i = 0; i < W; ++i) {
          const Vec<3>& v = u[row + n[i]];
          for (int r = 0; r < 3; ++r) {
            a[r] += d0[i] * v[r];
            b[r] += w0[i] * v[r];
          }
        }
        const double wjk = w1[j] * w2[k], djk = d1[j] * w2[k], ejk = w1[j] * d2[k];
        for (int r = 0; r < 3; ++r) {
          l[r][0] += wjk * a[r];
          l[r][1] += djk * b[r];
          l[r][2] += ejk * b[r];
        }
      }
  }
  Eigen::Matrix<double, D, D> out;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) out(a, b) = l[a][b];
  return out;
}

/// 3D tensor stencil, two gathered fields in one sum-factorised walk: sv = sum_i S_i v_i,
/// su = sum_i S_i u_i and l = sum_i u_i (x) G_i (the particle update with its stress pass when
/// the stress velocity u is also a gathered field). With b_jk = sum_i w0_i u_ijk (already a sum
/// of tensor_gradient_of), su = sum_jk w1_j w2_k b_jk, and c_jk = sum_i w0_i v_ijk gives sv the
/// same way: 9 multiply-adds per entry instead of 8 for the two sums plus 6 for the gradient in
/// a second walk. Pays from W = 3 (quadratic splines); for W = 2 two walks are faster.
template <int W>
void tensor_gather_gradient(const TensorStencil<3, W>& st, const std::vector<Vec<3>>& v, const std::vector<Vec<3>>& u,
                            std::int32_t offset, double sv[3], double su[3], double l[3][3]) {
  const std::int32_t* n = st.node;
  const double *w0 = st.value, *d0 = w0 + W, *w1 = w0 + 2 * W, *d1 = w0 + 3 * W, *w2 = w0 + 4 * W,
               *d2 = w0 + 5 * W;
  for (int k = 0; k < W; ++k)
    for (int j = 0; j < W; ++j) {
      const std::int32_t row = n[W + j] + n[2 * W + k] + offset;
      double a[3] = {}, b[3] = {}, c[3] = {};
      for (int i = 0; i < W; ++i) {
        const Vec<3>& ui = u[row + n[i]];
        const Vec<3>& vi = v[row + n[i]];
        for (int r = 0; r < 3; ++r) {
          a[r] += d0[i] * ui[r];
          b[r] += w0[i] * ui[r];
          c[r] += w0[i] * vi[r];
        }
      }
      const double wjk = w1[j] * w2[k], djk = d1[j] * w2[k], ejk = w1[j] * d2[k];
      for (int r = 0; r < 3; ++r) {
        l[r][0] += wjk * a[r];
        l[r][1] += djk * b[r];
        l[r][2] += ejk * b[r];
        su[r] += wjk * b[r];
        sv[r] += wjk * c[r];
      }
    }
}

template <int D, int W>
template <class Fn>
void TensorStencil<D, W>::for_each_force(const Eigen::Matrix<double, D, D>& stress, Fn&& fn) const {
  tensor_force(*this, stress, fn);
}
template <int D, int W>
Eigen::Matrix<double, D, D> TensorStencil<D, W>::gradient_of(const std::vector<Vec<D>>& u, std::int32_t offset) const {
  return tensor_gradient_of(*this, u, offset);
}

/// Calls fn(stencil_of) with a callable that returns particle p's stencil, typed for the cache's
/// layout (and width), so that everything fn does per particle is compiled for that layout.
template <int D, class Fn>
void with_stencils(const TransferCache<D>& cache, Fn&& fn) {
  if (cache.layout == StencilLayout::list) {
    fn([&cache](std::size_t p) {
      const std::size_t b = p * static_cast<std::size_t>(cache.stride);
      return ListStencil<D>{&cache.node[b], &cache.weight[b], &cache.gradient[b], cache.count[p]};
    });
    return;
  }
  auto tensor = [&]<int W>() {
    fn([&cache](std::size_t p) {
      return TensorStencil<D, W>{&cache.axis_node[p * D * W], &cache.axis_value[p * D * 2 * W]};
    });
  };
  switch (cache.width) {
    case 2: tensor.template operator()<2>(); break;
    case 3: tensor.template operator()<3>(); break;
    default: tensor.template operator()<4>(); break;
  }
}

/// fn(node, S, G) for every stencil entry of particle p (one layout test per call: for code
/// outside the hot loops).
template <int D, class Fn>
void for_each_entry(const TransferCache<D>& cache, std::size_t p, Fn&& fn) {
  with_stencils(cache, [&](auto stencil_of) { stencil_of(p).for_each(fn); });
}

/// One stencil entry, for code that wants the entries as data (tests, diagnostics).
template <int D>
struct StencilEntry {
  std::int32_t node;
  double weight;
  Vec<D> gradient;
};

/// Particle p's entries with S != 0 or G != 0, in stencil order.
template <int D>
std::vector<StencilEntry<D>> stencil_entries(const TransferCache<D>& cache, std::size_t p) {
  std::vector<StencilEntry<D>> out;
  for_each_entry(cache, p, [&](std::int32_t node, double S, const Vec<D>& G) {
    if (S != 0.0 || !G.isZero(0.0)) out.push_back({node, S, G});
  });
  return out;
}

/// Scatter: calls fn(p, stencil) for every particle p, race-free as above; fn may add into node
/// arrays at the stencil's nodes. Up to affinity_max_particles particles each thread takes the
/// blocks around its share of each colour's particles, the colour's blocks ranked by their middle
/// particle (about the particles it builds and gathers, util/parallel.hpp); beyond, the blocks of
/// a colour are handed out dynamically.
template <int D, class Fn>
void scatter(const TransferCache<D>& cache, Fn&& fn) {
  const auto n = static_cast<std::int64_t>(cache.n);
  const bool affinity = n <= affinity_max_particles;
  with_stencils(cache, [&](auto stencil_of) {
    // One function for a block's particles, called from both schedules below: kept out of line
    // so that the particle work is compiled once, inlined into its loop (with two inlined copies
    // GCC stopped inlining the stencil's force sum, and P2G of (d) took 1.25x the time).
    auto run_block = [&](std::int32_t block) __attribute__((noinline)) {
      for (std::int32_t i = cache.block_begin[block]; i < cache.block_begin[block + 1]; ++i) {
        const std::int32_t p = cache.order[i];
        fn(p, stencil_of(static_cast<std::size_t>(p)));
      }
    };
    // One team for all colours; the barrier at the end of each colour's loop keeps them apart.
#pragma omp parallel
    {
      const int t = omp_get_thread_num(), T = omp_get_num_threads();
      for (std::size_t c = 0; c < cache.colour_blocks.size(); ++c) {
        const auto& blocks = cache.colour_blocks[c];
        const auto n_blocks = static_cast<std::int64_t>(blocks.size());
        if (affinity) {
          // Block b goes to the thread whose T-quantile of the colour's particles holds the
          // block's middle (TransferCache::colour_rank).
          const std::vector<std::int64_t>& rank = cache.colour_rank[c];
          const std::int64_t twice_total = std::max<std::int64_t>(1, rank[n_blocks]);
          for (std::int64_t b = 0; b < n_blocks; ++b)
            if (std::min<std::int64_t>(T * rank[b] / twice_total, T - 1) == t) run_block(blocks[b]);
#pragma omp barrier
        } else {
#pragma omp for schedule(dynamic, 1)
          for (std::int64_t b = 0; b < n_blocks; ++b) run_block(blocks[b]);
        }
      }
    }
  });
}

/// Particles per work chunk of a gather beyond affinity_max_particles: small, so that threads
/// share the work evenly when one of them is slowed down by another process on its core (chunks
/// are handed out dynamically).
inline constexpr std::int64_t gather_chunk = 512;

/// Calls body(first, last) on every thread for its share of the owned particles [0, n): its
/// static_range with stealing up to affinity_max_particles (the cache's particle count decides,
/// as in scatter; `share` made before the region for n), dynamically handed-out chunks beyond.
/// Call inside a parallel region.
template <int D, class Body>
void share_particles(const TransferCache<D>& cache, std::int64_t n, StealingShare& share, Body&& body) {
  if (static_cast<std::int64_t>(cache.n) <= affinity_max_particles) {
    auto cursor = share.cursor();
    for (std::int64_t first, last; cursor.next(first, last);) body(first, last);
    return;
  }
  const std::int64_t n_chunks = (n + gather_chunk - 1) / gather_chunk;
#pragma omp for schedule(dynamic, 1) nowait
  for (std::int64_t c = 0; c < n_chunks; ++c) body(c * gather_chunk, std::min(n, (c + 1) * gather_chunk));
}

/// Gather: calls fn(p, stencil) for every owned particle (cache.n_owned), in parallel
/// (share_particles).
template <int D, class Fn>
void gather(const TransferCache<D>& cache, Fn&& fn) {
  with_stencils(cache, [&](auto stencil_of) {
    const auto n = static_cast<std::int64_t>(cache.n_owned);
    // Defined outside the region (clang 14 rejects a lambda inside it that names fn).
    const auto range = [&](std::int64_t first, std::int64_t last) {
      for (std::int64_t p = first; p < last; ++p) fn(p, stencil_of(static_cast<std::size_t>(p)));
    };
    StealingShare share(n);
#pragma omp parallel
    share_particles(cache, n, share, range);
  });
}

/// Gather over the owned particles that also returns sum_p fn(p, stencil), summed exactly
/// (parallel/exact_sum.hpp): the same for any thread count and any distribution of the
/// particles over ranks (this rank's part; the caller sums across ranks).
template <int D, class Fn>
ExactSum gather_sum(const TransferCache<D>& cache, Fn&& fn) {
  const auto n = static_cast<std::int64_t>(cache.n_owned);
  ExactSum total;
  with_stencils(cache, [&](auto stencil_of) {
    // Defined outside the region (clang 14 rejects a lambda inside it that names fn).
    const auto add_range = [&](ExactSum& sum, std::int64_t first, std::int64_t last) {
      for (std::int64_t p = first; p < last; ++p) sum.add(fn(p, stencil_of(static_cast<std::size_t>(p))));
    };
    StealingShare share(n);
#pragma omp parallel
    {
      ExactSum sum;
      share_particles(cache, n, share, [&](std::int64_t first, std::int64_t last) { add_range(sum, first, last); });
#pragma omp critical(cairn_gather_sum)
      total += sum;
    }
  });
  return total;
}

/// Parallel loop over nodes (on the calling thread for small grids, util/parallel.hpp,
/// node_loop_min).
template <class Fn>
void for_each_node(std::int32_t n_nodes, Fn&& fn) {
#pragma omp parallel for schedule(static) if (n_nodes >= node_loop_min)
  for (std::int32_t i = 0; i < n_nodes; ++i) fn(i);
}

/// for_each_node over the slots of `range` only.
template <class Fn>
void for_each_node(SlotRange range, Fn&& fn) {
  const std::int32_t first = range.first;
  for_each_node(range.last - first, [&](std::int32_t k) { fn(first + k); });
}

}  // namespace cairn
