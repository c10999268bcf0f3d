// The full mass matrix expansion of FMPM(k)/XPIC(k) (seed 000 Eq. 1-5), the lumped projection
// S+ S it is built from, velocity conditions on its terms, and the momenta the stress updates read.
#include "cairn/sim/simulation_detail.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>
#include <type_traits>
#include <unordered_set>

#include "cairn/contact/contact.hpp"
#include "cairn/materials/plane_stress.hpp"
#include "cairn/math/tensor.hpp"
#include "cairn/sim/resources.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn {

template <int D>
template <class Finish>
void Simulation<D>::lumped_projection(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out, Finish&& finish,
                                      SlotRange slots) {
  // S+ S u: U_p = sum_i S_pi u_i, then (S+ U)_i = sum_p M_p S_pi U_p / m_i (seed 000 Sec. 2.1).
  if (!distributed() || node_halo_) {
    // One pass: each particle's U_p is formed and scattered while its stencil is at hand (`in`
    // is only read, so the colour sweep may gather it; the same sums in the same order).
    // (A node-halo run sends every shared node's partial: all of them start from zero.)
    for_each_node(node_halo_ ? SlotRange{0, n_slots()} : slots, [&](std::int32_t i) { out[i].setZero(); });
    // Through raw pointers read once, the particle's field offset added to them: Eigen's vector
    // stores may alias anything, so through the std::vectors every entry reloaded their data
    // pointers and added the offset to the node.
    const Vec<D>* const in_all = in.data();
    Vec<D>* const out_all = out.data();
    const double* const mass = particles_.mass.data();
    scatter(cache_, [&, in_all, out_all, mass](std::int32_t p, const auto& stencil) {
      const std::int32_t off = field_offset(p);
      const Vec<D>* const in_f = in_all + off;
      Vec<D>* const out_f = out_all + off;
      double u[D] = {};
      stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) {
        for (int a = 0; a < D; ++a) u[a] += S * in_f[node][a];
      });
      const Vec<D> U(u);
      const double M = mass[p];
      stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) { out_f[node] += (S * M) * U; });
    });
    sum_halo(out);
  } else {
    lumped_projection_distributed(in, out);
  }
  for_each_node(slots, [&](std::int32_t i) {
    const double m = nodes_.mass[i];
    out[i] = m > small_mass_ ? Vec<D>(out[i] / m) : Vec<D>::Zero();
    finish(i, out[i]);
  });
}

template <int D>
void Simulation<D>::lumped_projection(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out) {
  lumped_projection(in, out, [](std::int32_t, const Vec<D>&) {}, {0, n_slots()});
}

template <int D>
void Simulation<D>::lumped_projection_distributed(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out) {
  // The ghosts' U_p come from their owners (this rank's nodes near the window's edge do not
  // hold every particle's contribution), then the scatter as above.
  particle_vec_.resize(particles_.n());
  gather(cache_, [&](std::int64_t p, const auto& stencil) {
    const std::int32_t off = field_offset(p);
    double u[D] = {};  // registers (see update_stresses)
    stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) {
      for (int a = 0; a < D; ++a) u[a] += S * in[node + off][a];
    });
    particle_vec_[p] = Vec<D>(u);
  });
  refresh_ghosts(particle_vec_);  // the scatter below reads the ghosts' U_p too
  for_each_node(n_slots(), [&](std::int32_t i) { out[i].setZero(); });
  scatter(cache_, [&](std::int32_t p, const auto& stencil) {
    const std::int32_t off = field_offset(p);
    stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) {
      out[node + off] += (S * particles_.mass[p]) * particle_vec_[p];
    });
  });
}

template <int D>
void Simulation<D>::full_mass_velocity(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out, int k) {
  // seed 000 Eq. 1 in its first form: m~_k^-1 = (I + A + ... + A^(k-1)) m^-1 with A = I - S+S.
  // Summing powers of the small operator A is the same polynomial as the alternating binomial
  // sum, without its cancellation for large k. (The recursion printed after Eq. 1 must start
  // from v*_1 = k m^-1 p for its terms to be binom(k, l) (S+S)^(l-1) m^-1 p.)
  // Velocity conditions (seed 000 Sec. 2.4, Eq. 3): `lumped`, `combined` and `constrained`
  // start from the corrected lumped velocity `in`; `velocity` from the uncorrected one;
  // `velocity` and `combined` impose the conditions again on the result, `constrained` after
  // every term.
  const std::string& method = config_.method.velocity_bc_method;
  // The uncorrected start is rebuilt from the step's p (and f) when `in` is one of the step's
  // own grid velocities; stress-update velocities (USF, USL+) start from their corrected value.
  const bool from_p = &in == &nodes_.velocity, from_p_new = &in == &nodes_.velocity_new;
  const bool uncorrected_start = method == "velocity" && (!conditions_.empty() || !velocity_conditions_.empty()) &&
                                 (from_p || from_p_new);
  // Slots without mass take no part (no particle reads them): the expansion visits the range
  // from the first to the last slot with mass. Beyond it `out` keeps what it held.
  const SlotRange slots = occupied_slots();
  for_each_node(slots, [&](std::int32_t i) {
    const double m = nodes_.mass[i];
    if (!uncorrected_start) grid_term_[i] = in[i];
    else if (m <= small_mass_) grid_term_[i].setZero();
    else grid_term_[i] = (nodes_.momentum[i] + (from_p_new ? Vec<D>(nodes_.force[i] * step_dt_) : Vec<D>::Zero())) / m;
  });
  using When = typename VelocityConditions<D>::When;
  const When when = from_p ? When::start : from_p_new ? When::end : work_when_;
  for_each_node(slots, [&](std::int32_t i) { out[i] = grid_term_[i]; });
  if (method == "constrained") {
    // Truncated Neumann series of the constrained system: the held components take their
    // prescribed values and the free ones solve (S+S)_ff v_f = v_f^(L) - (S+S)_fc v_c. As the
    // Richardson iteration v <- v + (v^(L) - S+S v), conditions imposed after every term; with
    // no conditions it is the same polynomial (I + A + ... + A^(k-1)) v^(L). Every term then
    // satisfies the homogeneous conditions, so the particle round trip has eigenvalues
    // 1 - (1 - mu)^k in [0, 1] (mu: eigenvalues of the principal block (S+S)_ff), where
    // `combined` (conditions on the start and the end only) approaches (K^-1)_ff K_ff, whose
    // eigenvalues are >= 1 (docs/boundary-conditions.md).
    for (int j = 1; j < k; ++j) {
      lumped_projection(out, grid_proj_, [](std::int32_t, const Vec<D>&) {}, slots);
      for_each_node(slots, [&](std::int32_t i) { out[i] += grid_term_[i] - grid_proj_[i]; });
      impose_conditions(out, when);
    }
    return;
  }
  for (int j = 1; j < k; ++j)
    lumped_projection(
        grid_term_, grid_proj_,
        [&](std::int32_t i, const Vec<D>& projected) {
          grid_term_[i] -= projected;  // A^j in
          out[i] += grid_term_[i];
        },
        slots);
  if (method != "lumped") impose_conditions(out, when);
}

template <int D>
SlotRange Simulation<D>::occupied_slots() const {
  const std::int32_t n = n_slots();
  if (distributed() || n_fields_ > 1) return {0, n};
  std::int32_t first = 0, last = n;
  while (first < n && nodes_.mass[first] == 0.0) ++first;
  while (last > first && nodes_.mass[last - 1] == 0.0) --last;
  return {first, last};
}

template <int D>
void Simulation<D>::impose_conditions(std::vector<Vec<D>>& velocity, typename VelocityConditions<D>::When when) {
  for (int f = 0; f < n_fields_; ++f) {
    const std::int32_t off = f * grid_.n_nodes();
    conditions_.apply(velocity, nodes_.mass, nullptr, 1.0, off);
    velocity_conditions_.apply(velocity, when, off);
  }
}

template <int D>
void Simulation<D>::subtract_contact_term(std::vector<Vec<D>>& out, int k) {
  // Multimaterial XPIC(k)/FMPM(k): out -= m~_(k-1)^-1 m dv^a, the (I - S S+a)^(k-1) S dv^a term
  // of seed 004 Eq. 37 / 42-44 in the full-mass form of seed 000 Eq. 5: the sum of A^j dv,
  // j = 0 .. k-2, with A = I - S+a S per field.
  // With first_correction = "impulse" the particles received the contact part dv_c as an
  // impulse (V' = V + S dv_c), so the extrapolation correction left is v^a - S+a V' =
  // dv - S+a S dv_c.
  if (k < 2) return;
  const bool impulse = contact_->impulse() && contact_->corrects_extrapolation();
  if (impulse) lumped_projection(contact_impulse_, grid_proj_);
  for_each_node(n_slots(), [&](std::int32_t i) {
    grid_term_[i] = impulse ? Vec<D>(contact_dv_[i] - grid_proj_[i]) : contact_dv_[i];
    out[i] -= grid_term_[i];
  });
  for (int j = 1; j < k - 1; ++j)
    lumped_projection(
        grid_term_, grid_proj_,
        [&](std::int32_t i, const Vec<D>& projected) {
          grid_term_[i] -= projected;
          out[i] -= grid_term_[i];
        },
        {0, n_slots()});
}

template <int D>
void Simulation<D>::stress_velocity_from_momentum(const std::vector<Vec<D>>& momentum, bool full_mass) {
  for_each_node(n_slots(), [&](std::int32_t i) {
    const double m = nodes_.mass[i];
    nodes_.velocity_work[i] = m > small_mass_ ? Vec<D>(momentum[i] / m) : Vec<D>::Zero();
  });
  // USF/USAVG start from p (start-of-step values), USL+/USAVG+ from S^T M V^(n+1) (end values).
  using When = typename VelocityConditions<D>::When;
  work_when_ = &momentum == &nodes_.momentum ? When::start : When::end;
  impose_conditions(nodes_.velocity_work, work_when_);
  if (full_mass) {
    std::vector<Vec<D>>& tmp = nodes_.velocity_full;  // free at this point of the step
    full_mass_velocity(nodes_.velocity_work, tmp, config_.method.order);
    nodes_.velocity_work.swap(tmp);
  }
}

template <int D>
void Simulation<D>::reextrapolate_momentum() {
  for_each_node(n_slots(), [&](std::int32_t i) { grid_term_[i].setZero(); });
  scatter(cache_, [&](std::int32_t p, const auto& stencil) {
    const std::int32_t off = field_offset(p);
    stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) {
      grid_term_[node + off] += (S * particles_.mass[p]) * particles_.velocity[p];
    });
  });
  sum_halo(grid_term_);
  if (contact_)  // the re-extrapolated momenta obey contact too (same normals and separations)
    contact_->correct(nodes_.mass, grid_term_, true, Contact<D>::Pass::stress, time_, step_dt_, nullptr);
}

#define CAIRN_INSTANTIATE(D) \
  template void Simulation<D>::lumped_projection(const std::vector<Vec<D>>&, std::vector<Vec<D>>&); \
  template void Simulation<D>::lumped_projection_distributed(const std::vector<Vec<D>>&, std::vector<Vec<D>>&); \
  template void Simulation<D>::full_mass_velocity(const std::vector<Vec<D>>&, std::vector<Vec<D>>&, int); \
  template SlotRange Simulation<D>::occupied_slots() const; \
  template void Simulation<D>::impose_conditions(std::vector<Vec<D>>&, typename VelocityConditions<D>::When); \
  template void Simulation<D>::subtract_contact_term(std::vector<Vec<D>>&, int); \
  template void Simulation<D>::stress_velocity_from_momentum(const std::vector<Vec<D>>&, bool); \
  template void Simulation<D>::reextrapolate_momentum(); \

CAIRN_INSTANTIATE(1)
CAIRN_INSTANTIATE(2)
CAIRN_INSTANTIATE(3)
#undef CAIRN_INSTANTIATE

}  // namespace cairn
