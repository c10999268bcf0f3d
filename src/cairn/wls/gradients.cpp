// The WLS particles' velocity gradients other than Eq. 29 (docs/wls.md, departures 4 and 17):
// the node sums of the quadrature gradient and of the transposed gradient over the integration
// regions (one pass), and the transposed gradient's gather over a particle's wide stencil.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "cairn/transfer/transfer.hpp"
#include "cairn/wls/grid_stencil.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn::wls {

using detail::for_each_slot;
using detail::stencil_entry;

template <int D>
void Integrator<D>::gradient_sums(const Grid<D>& grid, const std::vector<Vec<D>>& v_new) {
  // The velocity gradient at every integration point, L_q = sum_k v_k (x) G_kq over its cell's
  // corners (the strain rate the internal force of Eq. 24 is the power conjugate of), and in one
  // pass over the regions:
  //  - its S V-weighted mean over the integration points around each node (the quadrature
  //    gradient), scattered to the corners;
  //  - with the transposed gradient, seed 001 Eq. 10 and 19-21 as build_regions evaluates them:
  //    sigma_q = sum_{k used} (S_kq / s_q) fit_k(x_q), fit_k(x) = sum_c coef_kc beta_c(x - x_k)
  //    with beta = [1, r] (r in cells; only c = 0 with the node values) and coef_kc =
  //    sum_p psi_kcp sigma_p: so sum_q V_q sigma_q : L_q = sum_p sigma_p : sum_k sum_c psi_kcp A_kc
  //    with A_kc = sum_q (V_q / s_q) S_kq beta_c L_q, the node sums formed here (race-free by
  //    colour).
  const bool transpose = options_.transpose_gradient;
  const int n_c = options_.fitted_point_values ? n_basis : 1;
  const std::int32_t n_nodes = grid.n_nodes();
  node_gradient_.resize(n_nodes);
  node_gradient_weight_.resize(n_nodes);
  if (transpose) {
    transpose_sum_.resize(static_cast<std::size_t>(n_nodes) * n_basis);
  }
  for_each_node(n_nodes, [&](std::int32_t i) {
    node_gradient_[i].setZero();
    node_gradient_weight_[i] = 0.0;
    if (transpose)
      for (int c = 0; c < n_basis; ++c) transpose_sum_[static_cast<std::size_t>(i) * n_basis + c].setZero();
  });
  const Vec<D> inv_h = h_.cwiseInverse();
  for_each_region_coloured([&](std::int32_t r) {
    const Corners& corner = corners_[r];
    const Eigen::Matrix<double, D, D> L = point_gradient(r, v_new);
    for (int k = 0; k < (1 << D); ++k) {
      const double w = corner.S[k] * regions_[r].volume;
      node_gradient_[corner.node[k]] += w * L;
      node_gradient_weight_[corner.node[k]] += w;
    }
    if (!transpose) return;
    TransposeSum L_one;  // [L_q, 1]: the sum and its weight in one add
    L_one.template head<D * D>() = Eigen::Map<const Eigen::Matrix<double, D * D, 1>>(L.data());
    L_one[D * D] = 1.0;
    double sum = 0.0;
    const unsigned used = value_corners(corner, sum);
    const double scale = regions_[r].volume / sum;
    // The point in its cell, in cells from the lower corner (as build_regions places it).
    const Vec<D> lo = grid.origin() + cell_index(regions_[r].cell).template cast<double>().cwiseProduct(h_);
    const Vec<D> local = (regions_[r].centroid - lo).cwiseProduct(inv_h);
    for (int k = 0; k < (1 << D); ++k) {
      if (!(used >> k & 1U)) continue;
      const std::size_t at = static_cast<std::size_t>(corner.node[k]) * n_basis;
      const double w = scale * corner.S[k];
      for (int c = 0; c < n_c; ++c) {
        const double beta = c == 0 ? 1.0 : local[c - 1] - ((k >> (c - 1)) & 1);
        transpose_sum_[at + c] += (w * beta) * L_one;
      }
    }
  });
  // The means; and the transposed sums folded with the node's fit rows, once per node rather than
  // once per particle and entry: sum_c psi_kcp A_kc = W_kp sum_e b_e(x_p - x_k) B_ke with
  // B_ke = sum_c (M_k^-1)_ce A_kc (only where a particle's wide stencil reads them: count_ > 0).
  const int stride = n_coef_ * n_basis;
  for_each_node(n_nodes, [&](std::int32_t i) {
    if (node_gradient_weight_[i] > 0.0) node_gradient_[i] /= node_gradient_weight_[i];
    if (!transpose || count_[i] == 0) return;
    const std::size_t at = static_cast<std::size_t>(i) * n_basis;
    const double* rows = &inverse_rows_[static_cast<std::size_t>(i) * stride];
    std::array<TransposeSum, n_basis> A;
    for (int c = 0; c < n_c; ++c) A[c] = transpose_sum_[at + c];
    for (int e = 0; e < n_basis; ++e) {
      TransposeSum B = TransposeSum::Zero();
      for (int c = 0; c < n_c; ++c) B += rows[c * n_basis + e] * A[c];
      transpose_sum_[at + e] = B;
    }
  });
}

template <int D>
Eigen::Matrix<double, D, D> Integrator<D>::transposed_gradient_sum(std::size_t p, double& weight) const {
  // sum_k sum_c psi_kcp A_kc with psi_kcp = W_kp (M_k^-1 b_p)_c (Eq. 10 as collect sums it), over
  // the particle's wide stencil: W_kp sum_e b_e B_ke with the node sums gradient_sums folded.
  const std::size_t q = p * D * 3;
  const std::int32_t* axis_node = &cache_.axis_node[q];
  double axis_W[3 * D], axis_r[3 * D];
  wide_stencil(p, axis_W, axis_r);
  TransposeSum G = TransposeSum::Zero();
  for_each_slot<D>([&](const std::array<int, D>& k) __attribute__((always_inline)) {
    double W;
    const std::int32_t i = stencil_entry<D, 3>(k, axis_node, axis_W, W);
    if (W <= 0.0) return;
    const std::size_t at = static_cast<std::size_t>(i) * n_basis;
    TransposeSum B = transpose_sum_[at];
    for (int a = 0; a < D; ++a) B += axis_r[3 * a + k[a]] * transpose_sum_[at + 1 + a];
    G += W * B;
  });
  weight = G[D * D];
  return Eigen::Map<const Eigen::Matrix<double, D, D>>(G.data());
}

template void Integrator<1>::gradient_sums(const Grid<1>&, const std::vector<Vec<1>>&);
template void Integrator<2>::gradient_sums(const Grid<2>&, const std::vector<Vec<2>>&);
template void Integrator<3>::gradient_sums(const Grid<3>&, const std::vector<Vec<3>>&);
template Eigen::Matrix<double, 1, 1> Integrator<1>::transposed_gradient_sum(std::size_t, double&) const;
template Eigen::Matrix<double, 2, 2> Integrator<2>::transposed_gradient_sum(std::size_t, double&) const;
template Eigen::Matrix<double, 3, 3> Integrator<3>::transposed_gradient_sum(std::size_t, double&) const;

}  // namespace cairn::wls
