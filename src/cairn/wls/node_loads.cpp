// The loads and corrections the WLS integrator applies at the nodes after its sums: the
// tractions' spread over the cut-cell surface (docs/wls.md, departure 10), the opt-in
// acceleration filter and the opt-in hourglass damping (departure 13).
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

#include "cairn/transfer/transfer.hpp"
#include "cairn/wls/grid_stencil.hpp"
#include "cairn/wls/integrator.hpp"
#include "cairn/wls/least_squares.hpp"
#include "cairn/wls/weights.hpp"

namespace cairn::wls {

using detail::for_each_corner_at;
using detail::for_each_neighbour;
using detail::pow3;

template <int D>
void Integrator<D>::spread_surface_loads(const Grid<D>& grid) {
  // A traction is defined on the particles' faces (seed 000 Sec. 2.4), but the body the method
  // integrates is the union of the cut-cell regions (Eq. 18), and Eq. 24's internal force of a
  // uniform stress sigma is -sigma a_i with a_i = sum_q G_iq V_q, which in 2D is exactly the
  // integral of S_i n over the regions' surface (the patch test
  // UniformStressForceIsTheSurfaceTractionIntegral; inner cell faces cancel). A group's force
  // F (sum of T A_s over its faces, outward direction n) is spread over the nodes near its faces
  // in proportion to max(0, n . a_i), the area of the cut-cell surface facing n that each node
  // carries: then the loaded body's stress T (x) n balances the load node by node, also at the
  // nodes that see only a sliver of a cut cell, whose mass is O(eps^2) (Eq. 22) while their
  // forces are O(eps). Not in seed 001, which defines no tractions (docs/wls.md).
  const auto n_groups = static_cast<std::int32_t>(loads_.force.size());
  std::fill(surface_force_.begin(), surface_force_.end(), Vec<D>::Zero());
  std::fill(load_stamp_.begin(), load_stamp_.end(), -1);
  const Vec<D> inv_h = h_.cwiseInverse();
  for (std::int32_t g = 0; g < n_groups; ++g) {
    const double area = loads_.normal[g].norm();
    if (!(area > 0.0)) continue;
    const Vec<D> n = loads_.normal[g] / area;
    // The nodes of the 3^D blocks around the nearest nodes of the group's face centres.
    load_nodes_.clear();
    for (std::size_t f = 0; f < loads_.group.size(); ++f) {
      if (loads_.group[f] != g) continue;
      const Vec<D> x = grid.to_cell_units(loads_.centre[f]);
      for (int s = 0; s < pow3(D); ++s) {
        IVec<D> j;
        for (int a = 0, k = s; a < D; ++a, k /= 3) j[a] = static_cast<int>(std::lround(x[a])) + k % 3 - 1;
        const std::int32_t i = grid.node_index(j);
        if (i < 0 || load_stamp_[i] == g) continue;
        load_stamp_[i] = g;
        load_nodes_.push_back(i);
      }
    }
    double sum = 0.0;
    for (std::int32_t i : load_nodes_) sum += std::max(0.0, n.dot(surface_vector_[i]));
    if (sum > 1e-9 * area) {
      for (std::int32_t i : load_nodes_)
        surface_force_[i] += (std::max(0.0, n.dot(surface_vector_[i])) / sum) * loads_.force[g];
      continue;
    }
    // No cut-cell surface faces the group (it lies outside every region): each face's force by
    // the narrow shape S of Eq. 5 at its centre, as MPM's linear family would.
    for (std::size_t f = 0; f < loads_.group.size(); ++f) {
      if (loads_.group[f] != g) continue;
      for_each_corner_at(grid, loads_.centre[f], inv_h, [&](std::int32_t i, double S, const Vec<D>&) {
        surface_force_[i] += S * loads_.face_force[f];
      });
    }
  }
}

template <int D>
void Integrator<D>::filter_acceleration(const Grid<D>& grid, NodeField<D>& nodes) {
  // dv_i = v+_i - v_i = a_i dt replaced by the planar least-squares fit (Eq. 7-12 on the grid)
  // over the node and its 3^D - 1 neighbours that carry mass, weighted by W(x_j - x_i) m_j:
  // linear acceleration fields pass unchanged, the node-to-node zig-zag a single node's small
  // cut-cell mass and force produce does not (docs/wls.md).
  const std::int32_t n_nodes = grid.n_nodes();
  filtered_.resize(n_nodes);
  for_each_node(n_nodes, [&](std::int32_t i) {
    filtered_[i] = nodes.velocity_new[i] - nodes.velocity[i];
    if (!(nodes.mass[i] > 0.0)) return;
    typename PlaneFit<D>::Matrix M = PlaneFit<D>::Matrix::Zero();
    Eigen::Matrix<double, n_basis, D> load = Eigen::Matrix<double, n_basis, D>::Zero();
    for_each_neighbour(grid, i, [&](std::int32_t nb, const Vec<D>& r) {
      if (!(nodes.mass[nb] > 0.0)) return;
      double w = 1.0;
      for (int a = 0; a < D; ++a) w *= wide_weight(r[a], 1.0);
      w *= nodes.mass[nb];
      const auto b = PlaneFit<D>::basis(r);
      M += w * b * b.transpose();
      load += w * b * (nodes.velocity_new[nb] - nodes.velocity[nb]).transpose();
    });
    const auto inverse = PlaneFit<D>::inverse(M, false);
    filtered_[i] = (inverse.row(0) * load).transpose();
  });
  for_each_node(n_nodes, [&](std::int32_t i) { nodes.velocity_new[i] = nodes.velocity[i] + filtered_[i]; });
}

template <int D>
void Integrator<D>::damp_hourglass(const Grid<D>& grid, NodeField<D>& nodes) {
  // The bilinear (trilinear) corner patterns Gamma_k = prod_{a in A} s_a(k), s = -1 at the lower
  // and +1 at the upper corner along a, over every axis set A of two or more axes: one pattern in
  // 2D, four in 3D. They are orthogonal to every linear field, so a rigid motion or a uniform
  // strain rate loses nothing. Seed 001 Sec. 3.4.2 expects no zero-energy mode of its one-point
  // cell integration; measured, this mode goes unresisted (docs/wls.md, departure 13).
  // Per cell whose 2^D corners carry mass and per pattern, q = sum_k Gamma_k v+_k / 2^D, and
  // corner k receives the momentum -kappa m_min Gamma_k q (sum_k Gamma_k = 0: the cell's
  // momentum is kept; m_min is the cell's smallest corner mass); gathered per node, race-free. With
  // kappa = hourglass_damping / 2^D, a node-scale checkerboard of one pattern on nodes of equal
  // mass loses the fraction hourglass_damping of its amplitude per step (each of a node's 2^D
  // cells takes kappa of it), and a linear field nothing.
  constexpr int corners = 1 << D;
  const double kappa = options_.hourglass_damping / corners;
  const std::int32_t n_nodes = grid.n_nodes();
  filtered_.resize(n_nodes);
  for_each_node(n_nodes, [&](std::int32_t i) {
    filtered_[i] = Vec<D>::Zero();
    if (!(nodes.mass[i] > 0.0)) return;
    const IVec<D> j = grid.multi_index(i);
    Vec<D> momentum = Vec<D>::Zero();
    for (int own = 0; own < corners; ++own) {  // i is corner `own` of this cell
      std::array<std::int32_t, corners> node{};
      double m_min = std::numeric_limits<double>::infinity();
      bool full = true;
      for (int k = 0; k < corners && full; ++k) {
        IVec<D> jk = j;
        for (int a = 0; a < D; ++a) jk[a] += ((k >> a) & 1) - ((own >> a) & 1);
        node[k] = grid.node_index(jk);
        full = node[k] >= 0 && nodes.mass[node[k]] > 0.0;
        if (full) m_min = std::min(m_min, nodes.mass[node[k]]);
      }
      if (!full) continue;
      for (int axes = 3; axes < corners; ++axes) {
        if (std::popcount(static_cast<unsigned>(axes)) < 2) continue;
        const auto gamma = [axes](int k) { return std::popcount(static_cast<unsigned>(axes & ~k)) % 2 ? -1.0 : 1.0; };
        Vec<D> q = Vec<D>::Zero();
        for (int k = 0; k < corners; ++k) q += gamma(k) * nodes.velocity_new[node[k]];
        momentum -= kappa * m_min * gamma(own) * q / corners;
      }
    }
    filtered_[i] = momentum / nodes.mass[i];
  });
  for_each_node(n_nodes, [&](std::int32_t i) { nodes.velocity_new[i] += filtered_[i]; });
}

template void Integrator<1>::spread_surface_loads(const Grid<1>&);
template void Integrator<1>::filter_acceleration(const Grid<1>&, NodeField<1>&);
template void Integrator<1>::damp_hourglass(const Grid<1>&, NodeField<1>&);
template void Integrator<2>::spread_surface_loads(const Grid<2>&);
template void Integrator<2>::filter_acceleration(const Grid<2>&, NodeField<2>&);
template void Integrator<2>::damp_hourglass(const Grid<2>&, NodeField<2>&);
template void Integrator<3>::spread_surface_loads(const Grid<3>&);
template void Integrator<3>::filter_acceleration(const Grid<3>&, NodeField<3>&);
template void Integrator<3>::damp_hourglass(const Grid<3>&, NodeField<3>&);

}  // namespace cairn::wls
