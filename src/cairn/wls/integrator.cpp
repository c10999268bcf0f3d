#include "cairn/wls/integrator.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "cairn/parallel/exact_sum.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/wls/grid_stencil.hpp"
#include "cairn/wls/least_squares.hpp"
#include "cairn/wls/weights.hpp"

namespace cairn::wls {
namespace {

using detail::for_each_corner_at;
using detail::for_each_corner_slot;
using detail::for_each_neighbour;
using detail::for_each_slot;
using detail::packed;
using detail::stencil_entry;

}  // namespace

template <int D>
Integrator<D>::Integrator(const Grid<D>& grid, const Options& options)
    : options_(options), h_(grid.cell_size()), n_cells_(grid.n_cells()) {
  for (int a = 0; a < D; ++a) {
    periodic_[a] = grid.periodic(a);
    any_periodic_ |= periodic_[a];
  }
  const std::int32_t n = grid.n_nodes();
  sums_.assign(n, NodeSums{});
  // The slopes of the fits are read only by the fitted point values, the extrapolated spurious
  // velocity and the fitted surface velocity; otherwise the values c0 alone are formed (Eq. 11).
  n_coef_ = options.fitted_point_values || options.extrapolated_spurious_velocity || options.fitted_surface_velocity
                ? n_basis
                : 1;
  coef_.assign(static_cast<std::size_t>(n) * n_coef_ * n_row, 0.0);
  inverse_rows_.assign(static_cast<std::size_t>(n) * n_coef_ * n_basis, 0.0);
  count_.assign(n, 0);
  surface_sum_.assign(n, Vec<D>::Zero());
  surface_weight_.assign(n, 0.0);
  velocity_.assign(n, Vec<D>::Zero());
  density_.assign(n, 0.0);
  force_density_.assign(n, Vec<D>::Zero());
  stress_.assign(n, Eigen::Matrix<double, D, D>::Zero());
  alpha_.assign(n, 0);
  live_.assign(n, 1);  // every node is fitted at the first step
  distance_.assign(n, 0.0);
  internal_force_.assign(n, Vec<D>::Zero());
  long long cells = 1;
  for (int a = 0; a < D; ++a) cells *= n_cells_[a];
  cell_begin_.assign(static_cast<std::size_t>(cells) + 1, 0);
  // The cells by colour for the region scatters: the parity of the cell index along each axis,
  // so that two cells of one colour are at least two apart and share no corner node; along a
  // periodic axis with an odd number of cells (more than one) the last cell, whose upper nodes
  // are cell 0's lower ones, takes a third colour.
  std::array<int, D> colours{};
  int n_colours = 1;
  for (int a = 0; a < D; ++a) {
    colours[a] = periodic_[a] && n_cells_[a] > 1 && n_cells_[a] % 2 == 1 ? 3 : 2;
    n_colours *= colours[a];
  }
  colour_cells_.assign(static_cast<std::size_t>(n_colours), {});
  for (std::int32_t c = 0; c < static_cast<std::int32_t>(cells); ++c) {
    const IVec<D> j = cell_index(c);
    std::int32_t colour = 0, scale = 1;
    for (int a = 0; a < D; ++a) {
      colour += scale * (colours[a] == 3 && j[a] == n_cells_[a] - 1 ? 2 : j[a] % 2);
      scale *= colours[a];
    }
    colour_cells_[static_cast<std::size_t>(colour)].push_back(c);
  }
}

template <int D>
void Integrator<D>::build_stencils(const Grid<D>& grid, const Particles<D>& particles) {
  // Per axis and particle the three nodes around the nearest one: their storage offsets and the
  // narrow S, G factors in the cache's tensor layout (S_pi = prod_a S_a, G_pi,b = prod_a (a == b ?
  // G_a : S_a)), and x_p - x_n to the nearest node n here (wide_stencil forms W and x_p - x_i from
  // it); the 3^D products are formed where they are used (W, S and G are tensor products, seed 001
  // Sec. 3.1).
  const auto n = static_cast<std::int64_t>(particles.n());
  cache_.reserve_tensor(particles.n(), 3);
  local_.resize(static_cast<std::size_t>(n) * D);
  const Vec<D> inv_h = h_.cwiseInverse();
  std::int64_t first_bad = std::numeric_limits<std::int64_t>::max();
#pragma omp parallel
  {
    std::int64_t bad_t = std::numeric_limits<std::int64_t>::max();
#pragma omp for schedule(static)
    for (std::int64_t p = 0; p < n; ++p) {
      const Vec<D> xi = grid.to_cell_units(particles.position[p]);
      const std::size_t q = static_cast<std::size_t>(p) * D * 3;
      bool outside = false;
      for (int a = 0; a < D; ++a) {
        const int cell = static_cast<int>(std::floor(xi[a]));
        // A periodic axis does not wrap the positions (sim/resources.cpp): every cell index is
        // inside, and axis_index wraps the nodes; r below is then measured to the node's image
        // next to the particle.
        if (!periodic_[a]) outside |= !(cell >= 0 && cell < n_cells_[a]);
        const int nearest = static_cast<int>(std::floor(xi[a] + 0.5));
        const double local = xi[a] - cell;
        local_[static_cast<std::size_t>(p) * D + a] = xi[a] - nearest;
        std::int32_t* node = &cache_.axis_node[q + 3 * a];
        double* S = &cache_.axis_value[2 * q + 6 * a];
        // The nodes nearest - 1 .. nearest + 1 start at the cell's lower node (shift 1) or one
        // below it (shift 0): the narrow shape (Eq. 5) and its gradient (Eq. 6) are nonzero at
        // the cell's two nodes, read here without a branch on which half of the cell x_p is in.
        const int shift = nearest - cell == 1 ? 1 : 0;  // 0 or 1 (0 also for a NaN position)
        const double shape[4] = {0.0, 1.0 - local, local, 0.0};
        const double gradient[4] = {0.0, -inv_h[a], inv_h[a], 0.0};
        for (int k = 0; k < 3; ++k) {
          const int j = nearest - 1 + k;
          S[k] = shape[k + shift];
          S[3 + k] = gradient[k + shift];
          node[k] = grid.axis_index(a, j);
          outside |= node[k] < 0;
        }
      }
      if (outside) bad_t = std::min(bad_t, p);
    }
#pragma omp critical(cairn_wls_stencil)
    first_bad = std::min(first_bad, bad_t);
  }
  if (first_bad != std::numeric_limits<std::int64_t>::max()) {
    const Vec<D>& x = particles.position[first_bad];
    std::string where;
    for (int a = 0; a < D; ++a) where += (a ? ", " : "") + std::to_string(x[a]);
    throw SimulationFailure(first_bad, "position",
                            "particle " + std::to_string(first_bad) + " left the grid at (" + where +
                                "): WLS integrates over the grid's cells only");
  }
  cache_.reach_lo = IVec<D>::Ones();
  cache_.reach_hi = IVec<D>::Ones();
  colour_blocks(grid, particles, cache_);  // blocks by the cell holding each particle
}

template <int D>
void Integrator<D>::collect(const Grid<D>& grid, const Particles<D>& particles,
                            const std::vector<double>& density0, const std::vector<Vec<D>>* body_acceleration,
                            NodeField<D>& nodes, std::vector<Vec<D>>* node_body_force, bool surface_loads) {
  const auto n = static_cast<std::int64_t>(particles.n());
  const bool body_force = body_acceleration != nullptr;
  // Sec. 4.1: J_p, rho_p = rho0 / J_p, sigma_p = tau_p / J_p, f_p = rho_p b_p; a row of n_row
  // values per particle (the fields, padded with zeros to pairs).
  particle_fields_.resize(static_cast<std::size_t>(n) * n_row);
#pragma omp parallel for schedule(static)
  for (std::int64_t p = 0; p < n; ++p) {
    double* f = &particle_fields_[static_cast<std::size_t>(p) * n_row];
    const double J = particles.deformation_gradient[p].determinant();
    const double rho = density0[particles.material[p]] / J;
    for (int a = 0; a < D; ++a) f[a] = particles.velocity[p][a];
    f[D] = rho;
    for (int a = 0; a < D; ++a)
      for (int b = a; b < D; ++b) f[D + 1 + voigt(a, b)] = particles.kirchhoff_stress[p](a, b) / J;
    for (int a = 0; a < D; ++a) f[D + 1 + n_stress + a] = body_force ? rho * (*body_acceleration)[p][a] : 0.0;
    for (int k = n_fields; k < n_row; ++k) f[k] = 0.0;
  }
  const std::int32_t n_nodes = grid.n_nodes();
  for_each_node(n_nodes, [&](std::int32_t i) {
    // The sums change only where a weight W > 0 counted a particle (beta too: S > 0 implies
    // W > 0, Eq. 4-5): nodes no particle counted last time are still zero (about half of them).
    if (count_[i] != 0) {
      sums_[i] = NodeSums{};
      std::fill_n(&coef_[static_cast<std::size_t>(i) * n_coef_ * n_row], n_coef_ * n_row, 0.0);
    }
    count_[i] = 0;
    surface_sum_[i].setZero();
    surface_weight_[i] = 0.0;
  });
  // First pass: moment matrices (Eq. 9) with the wide weight; particle flags (Eq. 13) and
  // surface positions (Eq. 15) with the narrow shape.
  scatter(cache_, [&](std::int32_t p, const auto&) {
    const std::size_t q = static_cast<std::size_t>(p) * D * 3;
    const std::int32_t* axis_node = &cache_.axis_node[q];
    const double* axis_S = &cache_.axis_value[2 * q];
    double axis_W[3 * D], axis_r[3 * D];
    wide_stencil(static_cast<std::size_t>(p), axis_W, axis_r);
    const bool surface = is_surface(particles, static_cast<std::size_t>(p));
    const double flag = surface ? 1.0 : 2.0;
    const Vec<D>& x_p = particles.position[p];
    // The surface positions over the 2^D corners where S can be nonzero ...
    if (surface) for_each_corner_slot<D>(axis_S, [&](const std::array<int, D>& k) __attribute__((always_inline)) {
      double S;
      const std::int32_t i = stencil_entry<D, 6>(k, axis_node, axis_S, S);
      if (S != 0.0) {
        // Along a periodic axis the particle's image next to the node (x_i + r h), so that
        // x_surf of a node on the seam averages the particles on both sides of it.
        Vec<D> x = x_p;
        if (any_periodic_) {
          const Vec<D> xi = grid.node_position(i);
          for (int a = 0; a < D; ++a)
            if (periodic_[a]) x[a] = xi[a] + axis_r[3 * a + k[a]] * h_[a];
        }
        surface_sum_[i] += S * x;
        surface_weight_[i] += S;
      }
    });
    // ... and the moments over all 3^D entries. The basis [1, r] at r = x_p - x_i in cells
    // (PlaneFit::basis) is a tensor product too: W b_r b_c = prod_a W_a r_a^(e_a) with e_a = 0, 1
    // or 2, from per-axis factors formed once per particle.
    double factor[D][3][3];  // [axis][entry][power of r]
    for (int a = 0; a < D; ++a)
      for (int k = 0; k < 3; ++k) {
        const double w = axis_W[3 * a + k], r = axis_r[3 * a + k];
        factor[a][k][0] = w;
        factor[a][k][1] = w * r;
        factor[a][k][2] = w * r * r;
      }
    for_each_slot<D>([&](const std::array<int, D>& k) __attribute__((always_inline)) {
      double W, S;
      const std::int32_t i = stencil_entry<D, 3>(k, axis_node, axis_W, W);
      stencil_entry<D, 6>(k, axis_node, axis_S, S);  // the narrow S on the same entries, zero off the cell's corners
      NodeSums& sum = sums_[i];
      sum.beta += S * flag;  // Eq. 13 (S > 0 implies W > 0)
      if (W <= 0.0) return;
      auto& M = sum.moment;
      for (int r = 0; r < n_basis; ++r)
        for (int c = r; c < n_basis; ++c) {
          // Entry (r, c) of b b^T: power 1 of r_(r-1) and of r_(c-1) (2 where they coincide).
          double m = 1.0;
          for (int a = 0; a < D; ++a) m *= factor[a][k[a]][(r == 1 + a) + (c == 1 + a)];
          M[packed(r, c, n_basis)] += m;
        }
      sum.max_weight = std::max(sum.max_weight, W);
      ++count_[i];
    });
  });
  fit_nodes(grid);
  // Second pass: the fits (Eq. 9-10). Where only a field's value c0 is read, c0 = psi_0 . f is
  // summed directly, psi_0 = W (M^-1 b)_0: one value per field and stencil entry instead of the
  // n_basis loads. Where the slopes are read too (fitted point values, the extrapolated spurious
  // and the fitted surface velocity), the loads l_e = sum W b_e f of Eq. 9 are summed and made
  // c = M^-1 l once per node: as many sums as coefficients, without forming psi per entry.
  // The velocity's slopes are read only by the extrapolated spurious and the fitted surface
  // velocity: without them the pairs that hold velocity components alone take c0 directly.
  const bool velocity_slopes = options_.extrapolated_spurious_velocity || options_.fitted_surface_velocity;
  // The fields are added in pairs (GCC/Clang vector extensions, SSE2: the same operations per
  // field) over compile-time numbers of pairs and coefficients.
  using Pair = double __attribute__((vector_size(16), may_alias));
  auto fits = [&]<int n_pair, int n_coef, int n_value_only>() {
    scatter(cache_, [&](std::int32_t p, const auto&) {
      const std::size_t q = static_cast<std::size_t>(p) * D * 3;
      const std::int32_t* axis_node = &cache_.axis_node[q];
      double axis_W[3 * D], axis_r[3 * D];
      wide_stencil(static_cast<std::size_t>(p), axis_W, axis_r);
      const Pair* f = reinterpret_cast<const Pair*>(&particle_fields_[static_cast<std::size_t>(p) * n_row]);
      for_each_slot<D>([&](const std::array<int, D>& k) __attribute__((always_inline)) {
        double W;
        const std::int32_t i = stencil_entry<D, 3>(k, axis_node, axis_W, W);
        if (W <= 0.0) return;
        const double r0 = axis_r[k[0]];
        const double r1 = D > 1 ? axis_r[3 + k[D > 1 ? 1 : 0]] : 0.0;
        const double r2 = D > 2 ? axis_r[6 + k[D > 2 ? 2 : 0]] : 0.0;
        Pair* l = reinterpret_cast<Pair*>(&coef_[static_cast<std::size_t>(i) * n_coef * n_row]);
        if constexpr (n_coef == 1 || n_value_only > 0) {  // c0 directly: psi_0 = W (M^-1 b)_0
          const double* row = &inverse_rows_[static_cast<std::size_t>(i) * n_coef * n_basis];
          double v = row[0] + row[1] * r0;
          if constexpr (D > 1) v += row[2] * r1;
          if constexpr (D > 2) v += row[3] * r2;
          const Pair psi = Pair{W * v, W * v};
          for (int m = 0; m < (n_coef == 1 ? n_pair : n_value_only); ++m) l[m] += psi * f[m];
        }
        if constexpr (n_coef > 1) {  // the loads W b_e f of Eq. 9, made coefficients per node below
          Pair wb[n_basis];
          wb[0] = Pair{W, W};
          const double r[3] = {r0, r1, r2};
          for (int a = 0; a < D; ++a) wb[1 + a] = Pair{W * r[a], W * r[a]};
          for (int m = n_value_only; m < n_pair; ++m)
            for (int e = 0; e < n_basis; ++e) l[e * (n_row / 2) + m] += wb[e] * f[m];
        }
      });
    });
  };
  constexpr int all_pairs = (n_fields + 1) / 2, no_body_pairs = (n_fields - D + 1) / 2;
  constexpr int velocity_pairs = D / 2;  // the pairs of velocity components alone
  if (n_coef_ == 1) {
    if (body_force) fits.template operator()<all_pairs, 1, 0>();
    else fits.template operator()<no_body_pairs, 1, 0>();
  } else if (velocity_slopes) {
    if (body_force) fits.template operator()<all_pairs, n_basis, 0>();
    else fits.template operator()<no_body_pairs, n_basis, 0>();
  } else {
    if (body_force) fits.template operator()<all_pairs, n_basis, velocity_pairs>();
    else fits.template operator()<no_body_pairs, n_basis, velocity_pairs>();
  }
  // The fields summed as loads: none with the values alone, else all but the velocity pairs
  // that took c0 directly.
  const int first_load = n_coef_ == 1 ? n_row : velocity_slopes ? 0 : 2 * velocity_pairs;
  for_each_node(n_nodes, [&](std::int32_t i) {  // the node values c0 (Eq. 11)
    if (count_[i] == 0) return;
    if (first_load < n_row) {  // c = M^-1 l (Eq. 10) for the fields summed as loads
      const double* rows = &inverse_rows_[static_cast<std::size_t>(i) * n_coef_ * n_basis];
      double* c = &coef_[static_cast<std::size_t>(i) * n_coef_ * n_row];
      for (int k = first_load; k < n_row; ++k) {
        double load[n_basis];
        for (int e = 0; e < n_basis; ++e) load[e] = c[e * n_row + k];
        for (int r = 0; r < n_basis; ++r) {
          double v = 0.0;
          for (int e = 0; e < n_basis; ++e) v += rows[r * n_basis + e] * load[e];
          c[r * n_row + k] = v;
        }
      }
    }
    auto value = [&](int k) { return coefficient(i, k, 0); };
    for (int a = 0; a < D; ++a) velocity_[i][a] = value(a);
    density_[i] = value(D);
    for (int a = 0; a < D; ++a)
      for (int b = a; b < D; ++b) stress_[i](a, b) = stress_[i](b, a) = value(D + 1 + voigt(a, b));
    for (int a = 0; a < D; ++a) force_density_[i][a] = body_force ? value(D + 1 + n_stress + a) : 0.0;
  });
  if (options_.extrapolated_spurious_velocity) extrapolate_spurious_velocity(grid);
  refine_distance(grid);
  build_regions(grid);
  if (options_.adjoint_point_stress) adjoint_point_stress(grid, particles);
  integrate(grid, body_force, nodes, node_body_force, surface_loads);
}

template <int D>
void Integrator<D>::adjoint_point_stress(const Grid<D>& grid, const Particles<D>& particles) {
  // The quadrature gradient gives particle p the velocity gradient
  //   L_p = sum_k (S_kp / s_p) sum_q S_kq V_q L_q / W_k,  W_k = sum_q S_kq V_q,
  // s_p = sum of S_kp over the corners with W_k > 0 (gradient_sums, move_particles).
  // The stress power of the particles, sum_p V_p sigma_p : L_p, is then sum_q V_q sigma_q : L_q
  // exactly when sigma_q = sum_k S_kq N_k / W_k with N_k = sum_p S_kp V_p sigma_p / s_p: the
  // transpose of that transfer. With it the internal force of Eq. 24, whose power is
  // -sum_q V_q sigma_q : L_q, takes from the grid what the particles store (docs/wls.md,
  // departure 15). V_p sigma_p = V0_p tau_p.
  const std::int32_t n_nodes = grid.n_nodes();
  node_volume_.resize(n_nodes);
  node_stress_power_.resize(n_nodes);
  for_each_node(n_nodes, [&](std::int32_t i) {
    node_volume_[i] = 0.0;
    node_stress_power_[i].setZero();
  });
  for_each_region_coloured([&](std::int32_t r) {
    const Corners& corner = corners_[r];
    for (int k = 0; k < (1 << D); ++k) node_volume_[corner.node[k]] += corner.S[k] * regions_[r].volume;
  });
  scatter(cache_, [&](std::int32_t p, const auto&) {
    const std::size_t q = static_cast<std::size_t>(p) * D * 3;
    const std::int32_t* axis_node = &cache_.axis_node[q];
    const double* axis_S = &cache_.axis_value[2 * q];
    double s_p = 0.0;
    for_each_corner_slot<D>(axis_S, [&](const std::array<int, D>& k) {
      double S;
      const std::int32_t i = stencil_entry<D, 6>(k, axis_node, axis_S, S);
      if (node_volume_[i] > 0.0) s_p += S;
    });
    if (!(s_p > 0.0) || particles.volume0[p] == 0.0) return;
    const Eigen::Matrix<double, D, D> tau =
        particles.kirchhoff_stress[p].full().template topLeftCorner<D, D>() * (particles.volume0[p] / s_p);
    for_each_corner_slot<D>(axis_S, [&](const std::array<int, D>& k) {
      double S;
      const std::int32_t i = stencil_entry<D, 6>(k, axis_node, axis_S, S);
      if (node_volume_[i] > 0.0 && S != 0.0) node_stress_power_[i] += S * tau;
    });
  });
  const auto n_regions = static_cast<std::int64_t>(regions_.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t r = 0; r < n_regions; ++r) {
    const Corners& corner = corners_[r];
    Eigen::Matrix<double, D, D> sigma = Eigen::Matrix<double, D, D>::Zero();
    for (int k = 0; k < (1 << D); ++k) {
      const std::int32_t i = corner.node[k];
      if (node_volume_[i] > 0.0) sigma += corner.S[k] * node_stress_power_[i] / node_volume_[i];
    }
    regions_[r].stress = sigma;
  }
}

template <int D>
void Integrator<D>::fit_nodes(const Grid<D>& grid) {
  const std::int32_t n_nodes = grid.n_nodes();
  const double h = grid.min_cell_size();
  std::vector<long long> spurious(static_cast<std::size_t>(omp_get_max_threads()), 0);
  for_each_node(n_nodes, [&](std::int32_t i) {
    // A node no particle reaches, now or at the last fit, keeps what that fit left: beta = 0,
    // distance -h, no surface position, zero values and coefficients (about half the nodes).
    if (count_[i] == 0 && !live_[i]) return;
    live_[i] = count_[i] > 0;
    // Flags summed over the mirror images across symmetry planes the node lies on (a node on
    // such a plane sees the same particles again on the other side).
    const IVec<D> j = grid.multi_index(i);
    bool on_symmetry[D];
    double mirror = 1.0;
    for (int a = 0; a < D; ++a) {
      on_symmetry[a] = (j[a] == 0 && options_.mirror[2 * a]) || (j[a] == n_cells_[a] && options_.mirror[2 * a + 1]);
      if (on_symmetry[a]) mirror *= 2.0;
    }
    sums_[i].beta *= mirror;
    distance_[i] = sums_[i].beta > 2.0 ? h : -h;  // first estimate, Eq. 14
    if (surface_weight_[i] > 0.0) {
      surface_sum_[i] /= surface_weight_[i];  // x_i^surf, Eq. 15
      const Vec<D> xi = grid.node_position(i);
      for (int a = 0; a < D; ++a)
        if (on_symmetry[a]) surface_sum_[i][a] = xi[a];
    }
    velocity_[i].setZero();
    density_[i] = 0.0;
    force_density_[i].setZero();
    stress_[i].setZero();
    alpha_[i] = 0;
    if (count_[i] == 0) return;
    Eigen::Matrix<double, n_basis, n_basis> M;
    for (int r = 0; r < n_basis; ++r)
      for (int c = r; c < n_basis; ++c) M(r, c) = M(c, r) = sums_[i].moment[packed(r, c, n_basis)];
    // Sec. 3.5: too few particles, or none above the trigger weight: constant fit only.
    const bool reduce = count_[i] < D + 1 || sums_[i].max_weight < options_.trigger_weight;
    bool reduced = true;
    const Eigen::Matrix<double, n_basis, n_basis> inverse = PlaneFit<D>::inverse(M, reduce, &reduced);
    double* rows = &inverse_rows_[static_cast<std::size_t>(i) * n_coef_ * n_basis];  // read by collect's fits
    for (int c = 0; c < n_coef_; ++c)
      for (int r = 0; r < n_basis; ++r) rows[c * n_basis + r] = inverse(c, r);
    alpha_[i] = reduced ? 0 : 1;
    if (reduced) ++spurious[static_cast<std::size_t>(omp_get_thread_num())];
  });
  n_spurious_ = 0;
  for (long long s : spurious) n_spurious_ += s;
}

template <int D>
Eigen::Matrix<double, D, D> Integrator<D>::velocity_gradient_fit(std::int32_t i) const {
  Eigen::Matrix<double, D, D> L = Eigen::Matrix<double, D, D>::Zero();
  if (n_coef_ == 1) return L;  // slopes not fitted (see the declaration)
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) L(a, b) = coefficient(i, a, 1 + b) / h_[b];  // Eq. 12, back from cell units
  return L;
}

template <int D>
Eigen::Matrix<double, D + 1, D + 1> Integrator<D>::moment_matrix(std::int32_t i) const {
  Eigen::Matrix<double, n_basis, n_basis> M;
  for (int r = 0; r < n_basis; ++r)
    for (int c = r; c < n_basis; ++c) M(r, c) = M(c, r) = sums_[i].moment[packed(r, c, n_basis)];
  return M;
}

template <int D>
void Integrator<D>::extrapolate_spurious_velocity(const Grid<D>& grid) {
  // A spurious node's velocity: the mean of its well-conditioned neighbours' planar velocity fits
  // (Eq. 10) evaluated at the node, so that a linear velocity field is exact there too
  // (docs/wls.md). Written to a scratch first: neighbours read the fits, not the new values.
  const std::int32_t n_nodes = grid.n_nodes();
  filtered_.resize(n_nodes);
  for_each_node(n_nodes, [&](std::int32_t i) {
    filtered_[i] = velocity_[i];
    if (alpha_[i] || count_[i] == 0) return;
    Vec<D> sum = Vec<D>::Zero();
    int n = 0;
    for_each_neighbour(grid, i, [&](std::int32_t nb, const Vec<D>& offset) {
      if (!alpha_[nb]) return;
      for (int a = 0; a < D; ++a) sum[a] += fit_at(nb, a, -offset);  // component a is field a; x_i - x_nb = -offset
      ++n;
    });
    if (n > 0) filtered_[i] = sum / n;
  });
  for_each_node(n_nodes, [&](std::int32_t i) { velocity_[i] = filtered_[i]; });
}

template <int D>
void Integrator<D>::refine_distance(const Grid<D>& grid) {
  // Sec. 3.3, second stage: nodes with surface particles in their narrow support.
  const std::int32_t n_nodes = grid.n_nodes();
  const Vec<D> inv_h = h_.cwiseInverse();
  for_each_node(n_nodes, [&](std::int32_t i) {
    if (surface_weight_[i] <= 0.0) return;
    const Vec<D>& xs = surface_sum_[i];
    // Normal: gradient of the flag field at x_surf (Eq. 16), from the corners of its cell.
    Vec<D> normal = Vec<D>::Zero();
    for_each_corner_at(grid, xs, inv_h,
                       [&](std::int32_t node, double, const Vec<D>& G) { normal += G * sums_[node].beta; });
    const Vec<D> dv = xs - grid.node_position(i);
    const double along = dv.dot(normal);
    if (options_.projected_distance) {
      const double norm = normal.norm();
      if (norm > 0.0) distance_[i] = -along / norm;
    } else {
      distance_[i] = -(along < 0.0 ? -1.0 : 1.0) * dv.norm();  // Eq. 17
    }
  });
}

template <int D>
void Integrator<D>::integrate(const Grid<D>& grid, bool body_force, NodeField<D>& nodes,
                              std::vector<Vec<D>>* node_body_force, bool surface_loads) {
  const std::int32_t n_nodes = grid.n_nodes();
  if (surface_loads && surface_vector_.size() != static_cast<std::size_t>(n_nodes)) {
    surface_vector_.assign(n_nodes, Vec<D>::Zero());
    surface_force_.assign(n_nodes, Vec<D>::Zero());
    load_stamp_.assign(n_nodes, -1);
  }
  // Eq. 22-24, scattered from each region to its cell's corners (each region read once).
  for_each_node(n_nodes, [&](std::int32_t i) {
    nodes.mass[i] = 0.0;
    nodes.force[i].setZero();
    internal_force_[i].setZero();
    if (surface_loads) surface_vector_[i].setZero();
  });
  for_each_region_coloured([&](std::int32_t r) {
    const Region<D>& q = regions_[r];
    const Corners& corner = corners_[r];
    const double m = q.density * q.volume;                        // Eq. 22
    const Vec<D> fe = q.volume * q.force_density;                 // Eq. 23
    const Eigen::Matrix<double, D, D> stress = q.volume * q.stress;  // Eq. 24 (with sigma_q; Eq. 3's sign)
    for (int k = 0; k < (1 << D); ++k) {
      const std::int32_t i = corner.node[k];
      const double S = corner.S[k];
      const Vec<D>& G = corner.G[k];
      nodes.mass[i] += S * m;
      nodes.force[i] += S * fe;
      internal_force_[i] -= stress * G;
      if (surface_loads) surface_vector_[i] += q.volume * G;  // Eq. 24's rule for a unit stress: the surface vector
    }
  });
  for_each_node(n_nodes, [&](std::int32_t i) {
    nodes.momentum[i] = nodes.mass[i] * velocity_[i];
    if (node_body_force) (*node_body_force)[i] = body_force ? nodes.force[i] : Vec<D>::Zero();
    if (!nodes.reaction.empty()) nodes.reaction[i].setZero();  // kept only where conditions record it
  });
  if (surface_loads) {
    // The loads join the internal force: they are the boundary term of the weak form whose volume
    // term is Eq. 24, and a spurious node takes its neighbours' mean of both (docs/wls.md).
    spread_surface_loads(grid);
    for_each_node(n_nodes, [&](std::int32_t i) { internal_force_[i] += surface_force_[i]; });
  }
  // Sec. 3.5 / 4.5: the internal force of a spurious node is the mean over its 3^D - 1
  // neighbours that are well conditioned and carry mass (per unit mass by default, docs/wls.md).
  for_each_node(n_nodes, [&](std::int32_t i) {
    Vec<D> fi = internal_force_[i];
    if (!alpha_[i] && nodes.mass[i] > 0.0 && !options_.integrated_spurious_force) {
      Vec<D> sum = Vec<D>::Zero();
      int n = 0;
      for_each_neighbour(grid, i, [&](std::int32_t nb, const Vec<D>&) {
        if (nb == i || !alpha_[nb] || !(nodes.mass[nb] > 0.0)) return;
        sum += options_.average_per_mass ? Vec<D>(internal_force_[nb] / nodes.mass[nb]) : internal_force_[nb];
        ++n;
      });
      fi = n == 0 ? Vec<D>::Zero() : Vec<D>(sum / n);
      if (options_.average_per_mass) fi *= nodes.mass[i];
    }
    nodes.force[i] += fi;
  });
}

template <int D>
void Integrator<D>::move_particles(const Grid<D>& grid, const NodeField<D>& nodes, Particles<D>& particles,
                                   double dt, const std::vector<std::uint8_t>* held,
                                   const std::vector<Vec<D>>* impulse) {
  const auto& v = nodes.velocity;
  const auto& v_new = nodes.velocity_new;
  const auto& mass = nodes.mass;
  const bool transpose = options_.transpose_gradient;
  // The quadrature gradient is also the transposed gradient's fallback.
  const bool from_quadrature = options_.quadrature_gradient || transpose;
  const bool pic = options_.pic_velocity;
  const bool all_nodes = options_.massless_corners_included;
  const bool fitted_surface = options_.fitted_surface_velocity;
  const bool projected = options_.xpic_order > 0;  // XPIC: start from sum S u_k
  if (held && held->empty()) held = nullptr;
  if (from_quadrature) gradient_sums(grid, v_new);
  particle_gradient_.resize(particles.n());
  // Eq. 27-29 for particle p; returns its kinetic energy change (the energy budget's sum).
  const auto move = [&](std::int64_t p, const auto&) {
    const std::size_t q = static_cast<std::size_t>(p) * D * 3;
    const std::int32_t* axis_node = &cache_.axis_node[q];
    const double* axis_S = &cache_.axis_value[2 * q];
    Vec<D> dv = Vec<D>::Zero(), vx = Vec<D>::Zero(), kick = Vec<D>::Zero();
    Eigen::Matrix<double, D, D> L = Eigen::Matrix<double, D, D>::Zero();
    // The transpose of the stress transfer (docs/wls.md, departure 17), where its weight is a
    // volume near the particle's own: a massless surface particle stores no power, and where the
    // fits extrapolate (cells that a mirror plane fills up to a wall) the weight can be small or
    // negative. Elsewhere the quadrature gradient (not formed where the transpose is taken).
    bool transposed = false;
    if (transpose && !is_surface(particles, static_cast<std::size_t>(p))) {
      double w = 0.0;
      const Eigen::Matrix<double, D, D> G = transposed_gradient_sum(static_cast<std::size_t>(p), w);
      const double V = particles.volume0[p] * particles.deformation_gradient[p].determinant();
      transposed = w > V / transpose_band && w < V * transpose_band;
      if (transposed) L = G / w;
    }
    const bool quadrature = from_quadrature && !transposed;
    double weight = 0.0;
    bool massless = false;  // a node with S_ip > 0 and no mass
    for_each_corner_slot<D>(axis_S, [&](const std::array<int, D>& k) __attribute__((always_inline)) {
      double S;
      const std::int32_t i = stencil_entry<D, 6>(k, axis_node, axis_S, S);
      massless |= S != 0.0 && !(mass[i] > 0.0);
      dv += S * (v_new[i] - v[i]);  // Eq. 27: S a dt
      vx += S * v_new[i];           // Eq. 28
      if (impulse) kick += S * (*impulse)[i];
      if (!from_quadrature) {
        Vec<D> G = Vec<D>::Ones();  // G_ip,b = prod_a (a == b ? G_a : S_a)
        for (int a = 0; a < D; ++a)
          for (int c = 0; c < D; ++c) G[c] *= a == c ? axis_S[6 * a + 3 + k[a]] : axis_S[6 * a + k[a]];
        L += v_new[i] * G.transpose();  // Eq. 29
      } else if (quadrature && node_gradient_weight_[i] > 0.0) {
        // S-interpolated node means of the integration points' gradients (docs/wls.md), over
        // the nodes that have integration points around them.
        L += S * node_gradient_[i];
        weight += S;
      }
    });
    if (massless && !all_nodes) {
      // A corner of the particle's cell that no integration region reaches (the particle lies on
      // or beyond the cut surface) has no mass, hence no velocity or acceleration: Eq. 27-28
      // summed over it lose the partition of unity, and a rigid translation would slow such a
      // particle down (and then, through the next fits, its neighbours). Such a corner takes the
      // S-weighted mean of the corners with mass: Eq. 27-28 over the corners with mass, divided
      // by their sum of S (docs/wls.md, departure 12). A component that a velocity condition set
      // keeps the condition's value (a wall's zero normal velocity), so that a particle next to a
      // wall does not take the inner corners' motion into it. Eq. 29 is left as printed (measured
      // in docs/wls.md: the same mean there made plate_hole scatter more).
      Vec<D> dv_m = Vec<D>::Zero(), vx_m = Vec<D>::Zero();  // over the corners with mass
      Vec<D> dv_h = Vec<D>::Zero(), vx_h = Vec<D>::Zero();  // over held components without mass
      Vec<D> S_h = Vec<D>::Zero();
      double S_m = 0.0, S_all = 0.0;
      for_each_corner_slot<D>(axis_S, [&](const std::array<int, D>& k) {
        double S;
        const std::int32_t i = stencil_entry<D, 6>(k, axis_node, axis_S, S);
        S_all += S;
        if (mass[i] > 0.0) {
          S_m += S;
          dv_m += S * (v_new[i] - v[i]);
          vx_m += S * v_new[i];
        } else if (held && S != 0.0) {
          for (int a = 0; a < D; ++a)
            if ((*held)[i] >> a & 1U) {
              S_h[a] += S;
              dv_h[a] += S * (v_new[i][a] - v[i][a]);
              vx_h[a] += S * v_new[i][a];
            }
        }
      });
      if (S_m > 0.0) {
        for (int a = 0; a < D; ++a) {
          const double free = S_h[a] == 0.0 ? 1.0 : (S_all - S_h[a]);  // S of the corners taking the mean
          dv[a] = dv_m[a] / S_m * free + dv_h[a];
          vx[a] = vx_m[a] / S_m * free + vx_h[a];
        }
      }
    }
    if (quadrature && weight > 0.0) L /= weight;
    // Eq. 27 (FLIP), or PIC: V_p = sum S v+ (seed 002 Eq. 1.66; docs/wls.md, departure 11). With
    // XPIC the increment starts from the particle's projected velocity (departure 18), and a
    // surface particle may start from the fitted velocity at its position instead of its own.
    const double before = particles.velocity[p].squaredNorm();
    const Vec<D> start = projected ? xpic_particle_[static_cast<std::size_t>(p)]
                         : fitted_surface && is_surface(particles, static_cast<std::size_t>(p))
                             ? fitted_velocity(grid, axis_node, axis_S, particles.position[p], particles.velocity[p])
                             : particles.velocity[p];
    particles.velocity[p] = pic ? vx : impulse ? Vec<D>(start + kick + dv) : Vec<D>(start + dv);
    particles.position[p] += vx * dt;
    particle_gradient_[p] = L;
    return 0.5 * particles.mass[p] * (particles.velocity[p].squaredNorm() - before);
  };
  if (!options_.energy_budget) {
    gather(cache_, move);
    return;
  }
  // The grid's kinetic-energy change (grid_work()) and the particles', summed exactly (the same
  // for any thread count).
  const ExactSum grid_change = exact_sums<1>(grid.n_nodes(), [&](std::int64_t i, std::array<double, 1>& e) {
    e[0] = mass[i] > 0.0 ? 0.5 * mass[i] * (v_new[i].squaredNorm() - v[i].squaredNorm()) : 0.0;
  })[0];
  const ExactSum particle_change = gather_sum(cache_, move);
  grid_work_ += grid_change.value();
  transfer_energy_ += particle_change.value() - grid_change.value();
}

template <int D>
Vec<D> Integrator<D>::fitted_velocity(const Grid<D>& grid, const std::int32_t* axis_node, const double* axis_S,
                                      const Vec<D>& x, const Vec<D>& otherwise) const {
  // The well-conditioned corners' planar velocity fits (seed 001 Eq. 10; component a is field a) at x,
  // S-weighted (docs/wls.md, departure 16); `otherwise` where no corner is well conditioned.
  Vec<D> sum = Vec<D>::Zero();
  double weight = 0.0;
  for_each_corner_slot<D>(axis_S, [&](const std::array<int, D>& k) {
    double S;
    const std::int32_t i = stencil_entry<D, 6>(k, axis_node, axis_S, S);
    if (S == 0.0 || !alpha_[i]) return;
    Vec<D> r = (x - grid.node_position(i)).cwiseQuotient(h_);
    for (int a = 0; a < D; ++a)  // along a periodic axis, the node's image next to x
      if (periodic_[a]) r[a] -= n_cells_[a] * std::round(r[a] / n_cells_[a]);
    for (int a = 0; a < D; ++a) sum[a] += S * fit_at(i, a, r);
    weight += S;
  });
  return weight > 0.0 ? Vec<D>(sum / weight) : otherwise;
}

template <int D>
Particles<D> region_points(const Integrator<D>& integrator) {
  Particles<D> out;
  const auto& regions = integrator.regions();
  for (std::size_t r = 0; r < regions.size(); ++r) {
    const Region<D>& q = regions[r];
    const int within = (r > 0 && regions[r - 1].cell == q.cell) ? out.material.back() + 1 : 0;
    out.add(q.centroid, Vec<D>::Zero(), q.density * q.volume, q.volume, Vec<D>::Zero(), within, q.cell);
    Mat3 tau = Mat3::Zero();
    tau.template topLeftCorner<D, D>() = q.stress;
    out.kirchhoff_stress.back() = tau;
  }
  return out;
}

template Particles<1> region_points<1>(const Integrator<1>&);
template Particles<2> region_points<2>(const Integrator<2>&);
template Particles<3> region_points<3>(const Integrator<3>&);

template class Integrator<1>;
template class Integrator<2>;
template class Integrator<3>;

}  // namespace cairn::wls
