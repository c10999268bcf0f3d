// The WLS particle velocity of particle_velocity = "xpic" (docs/wls.md, departure 18): seed 000's
// XPIC(k) with the least-squares fit in place of the lumped mass. Seed 000 Sec. 2.2 writes the
// XPIC(k) projection of the particle velocities as S m~_k^-1 p, with the full mass matrix inverse
// expanded to k terms, m~_k^-1 p = sum_{j<k} A^j m^-1 p, A = I - m^-1 S^T M S, and summed by the
// recursion v_(j+1) = m^-1 p + A v_j. WLS forms its node velocities by the fit F of Eq. 7-11
// (particles to nodes) instead of m^-1 S^T M, so here A = I - F S and
//     u_1 = v,   u_(j+1) = v + u_j - F(S u_j),
// with v = F V the fitted velocity; the limit solves F(S u) = v (node velocities that,
// interpolated to the particles with Eq. 27's S and fitted again, give back the fit). Eq. 27's
// FLIP increment then starts from the projection instead of the particle's own velocity (seed
// 000, "XPIC" of the P_X comparison): V_p = sum S u_k + sum S (v+ - v). It removes the part of V
// that the fits do not see (the noise FLIP keeps) and leaves the grid update as it is; k = 1 is PIC.
//
// The series is summed only at nodes inside the body (d_i > 0, Eq. 14-17) whose fit is well
// conditioned and which carry mass; elsewhere u = v. At nodes on or beyond the surface the fit
// extrapolates from one side, F S is no smoothing there, and the series grows: with every node
// summed, verification/plate_hole at h = 1/64 scatters 0.063 instead of 0.037 (docs/wls.md).
#include <array>
#include <cstdint>
#include <vector>

#include "cairn/transfer/transfer.hpp"
#include "cairn/wls/grid_stencil.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn::wls {

using detail::for_each_corner_slot;
using detail::for_each_slot;
using detail::stencil_entry;

template <int D>
void Integrator<D>::interpolate(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& out) const {
  out.resize(cache_.n);
  gather(cache_, [&](std::int64_t p, const auto&) {
    const std::size_t q = static_cast<std::size_t>(p) * D * 3;
    const std::int32_t* axis_node = &cache_.axis_node[q];
    const double* axis_S = &cache_.axis_value[2 * q];
    Vec<D> s = Vec<D>::Zero();
    for_each_corner_slot<D>(axis_S, [&](const std::array<int, D>& k) __attribute__((always_inline)) {
      double S;
      const std::int32_t i = stencil_entry<D, 6>(k, axis_node, axis_S, S);
      s += S * u[i];
    });
    out[static_cast<std::size_t>(p)] = s;
  });
}

template <int D>
void Integrator<D>::xpic_projection(const Grid<D>& grid, const std::vector<double>& mass,
                                    const std::vector<Vec<D>>& v) {
  const std::int32_t n_nodes = grid.n_nodes();
  xpic_node_ = v;  // u_1
  xpic_fit_.assign(static_cast<std::size_t>(n_nodes), Vec<D>::Zero());
  for (int term = 1; term < options_.xpic_order; ++term) {
    interpolate(xpic_node_, xpic_particle_);  // S u_j at every particle ...
    // ... fitted back to the nodes: the value c0 = sum_p W (M^-1 b)_0 (S u)_p of Eq. 10-11 with
    // this step's moment matrices (collect's second pass for one field) ...
    scatter(cache_, [&](std::int32_t p, const auto&) {
      const std::size_t q = static_cast<std::size_t>(p) * D * 3;
      const std::int32_t* axis_node = &cache_.axis_node[q];
      double axis_W[3 * D], axis_r[3 * D];
      wide_stencil(static_cast<std::size_t>(p), axis_W, axis_r);
      const Vec<D>& s = xpic_particle_[static_cast<std::size_t>(p)];
      for_each_slot<D>([&](const std::array<int, D>& k) __attribute__((always_inline)) {
        double W;
        const std::int32_t i = stencil_entry<D, 3>(k, axis_node, axis_W, W);
        if (W <= 0.0) return;
        const double* row = &inverse_rows_[static_cast<std::size_t>(i) * n_coef_ * n_basis];
        double psi = row[0];
        for (int a = 0; a < D; ++a) psi += row[1 + a] * axis_r[3 * a + k[a]];
        xpic_fit_[i] += W * psi * s;
      });
    });
    // ... and u_(j+1) = v + u_j - F(S u_j) at the inside nodes (see the top).
    for_each_node(n_nodes, [&](std::int32_t i) {
      if (mass[i] > 0.0 && alpha_[i] && distance_[i] > 0.0) xpic_node_[i] = v[i] + xpic_node_[i] - xpic_fit_[i];
      xpic_fit_[i].setZero();
    });
  }
  interpolate(xpic_node_, xpic_particle_);  // the projection S u_k, read by move_particles
}

template void Integrator<1>::xpic_projection(const Grid<1>&, const std::vector<double>&, const std::vector<Vec<1>>&);
template void Integrator<2>::xpic_projection(const Grid<2>&, const std::vector<double>&, const std::vector<Vec<2>>&);
template void Integrator<3>::xpic_projection(const Grid<3>&, const std::vector<double>&, const std::vector<Vec<3>>&);

}  // namespace cairn::wls
