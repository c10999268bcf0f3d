// The integration regions of the WLS method (seed 001 Sec. 3.4): the inside part of every cut
// or full cell from the nodes' signed distances (wls/cut_cell.hpp), one centroid point each, the
// corners' S and G there, and the values at the point (Eq. 19-21).
#include <omp.h>

#include <array>
#include <cstdint>
#include <vector>

#include "cairn/wls/cut_cell.hpp"
#include "cairn/wls/grid_stencil.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn::wls {

using detail::corner_shape;

template <int D>
void Integrator<D>::build_regions(const Grid<D>& grid) {
  if constexpr (D == 1) {
    (void)grid;
  } else {
    const auto n_cells_total = static_cast<std::int64_t>(cell_begin_.size()) - 1;
    // The inside regions of cell c from the distances at its corners (nodes, lower corner lo).
    auto cut = [&](std::int64_t c, std::array<std::int32_t, (1 << D)>& node, Vec<D>& lo,
                   std::array<CellRegion<D>, max_regions<D>>& out) {
      const IVec<D> cell = cell_index(static_cast<std::int32_t>(c));
      std::array<std::array<std::int32_t, 2>, D> axis;  // each axis's part of the corners' storage index
      for (int a = 0; a < D; ++a)
        for (int side = 0; side < 2; ++side) axis[a][side] = grid.axis_index(a, cell[a] + side);
      std::array<double, (1 << D)> d;
      for (int k = 0; k < (1 << D); ++k) {
        node[k] = 0;
        for (int a = 0; a < D; ++a) node[k] += axis[a][(k >> a) & 1];
        d[k] = distance_[node[k]];
      }
      lo = grid.origin() + cell.template cast<double>().cwiseProduct(h_);
      return cut_cell<D>(d, lo, h_, out);
    };
    // Pass 1: regions per cell; pass 2 (after the prefix sum) the regions themselves.
    std::vector<std::int32_t>& begin = cell_begin_;
#pragma omp parallel for schedule(static)
    for (std::int64_t c = 0; c < n_cells_total; ++c) {
      std::array<std::int32_t, (1 << D)> node;
      std::array<CellRegion<D>, max_regions<D>> out;
      Vec<D> lo;
      begin[c + 1] = cut(c, node, lo, out);
    }
    begin[0] = 0;
    for (std::int64_t c = 0; c < n_cells_total; ++c) begin[c + 1] += begin[c];
    regions_.resize(static_cast<std::size_t>(begin[n_cells_total]));
    corners_.resize(regions_.size());
    const double thickness = D == 2 ? options_.thickness : 1.0;
    const Vec<D> inv_h = h_.cwiseInverse();
#pragma omp parallel for schedule(static)
    for (std::int64_t c = 0; c < n_cells_total; ++c) {
      if (begin[c + 1] == begin[c]) continue;
      std::array<std::int32_t, (1 << D)> node;
      std::array<CellRegion<D>, max_regions<D>> out;
      Vec<D> lo;
      const int n = cut(c, node, lo, out);
      for (int r = 0; r < n; ++r) {
        Region<D>& q = regions_[begin[c] + r];
        q.cell = static_cast<std::int32_t>(c);
        q.volume = out[r].volume * thickness;
        q.centroid = out[r].centroid;
        // The corners' nodes, S and G at the point, for the stages that read them (integrate,
        // gradient_sums) as for the values below.
        const Vec<D> local = (q.centroid - lo).cwiseProduct(inv_h);
        Corners& corner = corners_[begin[c] + r];
        for (int k = 0; k < (1 << D); ++k) {
          corner.node[k] = node[k];
          corner_shape<D>(k, local, inv_h, corner.S[k], corner.G[k]);
        }
        // Eq. 19-21: values at the point from the well-conditioned corners (alpha_i = 1); a
        // cell whose corners are all spurious falls back to all of them.
        const bool fitted = options_.fitted_point_values;
        for (int pass = 0; pass < 2; ++pass) {
          double sum = 0.0;
          q.density = 0.0;
          q.force_density.setZero();
          q.stress.setZero();
          for (int k = 0; k < (1 << D); ++k) {
            if (pass == 0 && !alpha_[node[k]]) continue;
            const double S = corner.S[k];
            sum += S;
            if (!fitted) {
              q.density += S * density_[node[k]];
              q.force_density += S * force_density_[node[k]];
              q.stress += S * stress_[node[k]];
              continue;
            }
            // The corner's planar fits at the point (Eq. 10 at r = x_q - x_k, in cells); a
            // reduced fit has zero slopes and gives its c0.
            Vec<D> r;
            for (int a = 0; a < D; ++a) r[a] = local[a] - ((k >> a) & 1);
            auto at = [&](int field) { return fit_at(node[k], field, r); };
            q.density += S * at(D);
            for (int a = 0; a < D; ++a) {
              q.force_density[a] += S * at(D + 1 + n_stress + a);
              for (int b = a; b < D; ++b) {
                const double v = S * at(D + 1 + voigt(a, b));
                q.stress(a, b) += v;
                if (b != a) q.stress(b, a) += v;
              }
            }
          }
          if (sum > 0.0) {
            q.density /= sum;
            q.force_density /= sum;
            q.stress /= sum;
            break;
          }
        }
      }
    }
  }
}

template void Integrator<1>::build_regions(const Grid<1>&);
template void Integrator<2>::build_regions(const Grid<2>&);
template void Integrator<3>::build_regions(const Grid<3>&);

}  // namespace cairn::wls
