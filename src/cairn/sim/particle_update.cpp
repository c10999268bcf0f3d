// Tasks 4-5 of seed 000 Table 1: the scheme moves the particles, the velocity gradient updates
// F and the material stress, with the failure checks of every particle.
#include "cairn/sim/simulation_detail.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
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
void Simulation<D>::update_particles(double dt, StressPass stress) {
  // Task 4 in the unified form (seed 002 Eq. 1.7-1.12): V += A dt, X += VV dt + A dt^2 / 2.
  const UpdateScheme<D>& scheme =
      (scheme_->full_mass() != FullMass::none && !use_full_mass_) ? *flip_ : *scheme_;
  const bool updated_field = scheme_->full_mass() == FullMass::of_updated;
  const bool affine = scheme.affine();
  const double alpha_g = config_.method.grid_damping, alpha_p = config_.method.particle_damping;
  const auto& v = nodes_.velocity;
  const auto& v_new = nodes_.velocity_new;
  const auto& v_full = nodes_.velocity_full;
  auto& P = particles_;
  const bool contact_impulse = contact_ && contact_->impulse() && contact_->corrects_extrapolation();
  const bool position_updated = config_.method.position_update == "updated";
  // With a stress pass, the velocity gradient of stress.velocity is summed in the same entry
  // loop and the stress update (update_stress_at) follows each particle's move.
  const std::vector<Vec<D>>* vs = stress.velocity;
  const bool increments = uses_increments();
  std::int64_t first_bad = -1;
  std::string what;
  // The sum is the energy dissipated relative to the non-dissipative FLIP update (below). The
  // entry loop is compiled with and without the full-mass velocity and the stress pass.
  auto move = [&](auto full_tag, auto stress_tag) {
    constexpr bool full = decltype(full_tag)::value;
    constexpr bool with_stress = decltype(stress_tag)::value;
    return gather_sum(cache_, [&](std::int64_t p, const auto& stencil) {
      // grad V is summed entry by entry in this loop as gradient_of does it, except for 3D
      // tensor stencils, whose gradient_of is sum-factorised (cheaper than per entry).
      constexpr bool grad_in_loop =
          with_stress && (D < 3 || std::is_same_v<std::decay_t<decltype(stencil)>, ListStencil<D>>);
      const std::int32_t off = field_offset(p);
      double sv[D] = {}, sv_new[D] = {}, sv_full[D] = {};  // registers (see update_stresses)
      double l[D][D] = {};
      // A 3D tensor stencil of width 3 or more whose stress velocity is v+ (FLIP-type USL): one
      // factorised walk gives S v, S v+ and grad v+ (tensor_gather_gradient).
      bool walked = false;
      if constexpr (with_stress && !full && D == 3 && !grad_in_loop) {
        if constexpr (std::decay_t<decltype(stencil)>::width >= 3) {
          if (vs == &v_new) {
            tensor_gather_gradient(stencil, v, v_new, off, sv, sv_new, l);
            walked = true;
          }
        }
      }
      if (!walked) stencil.for_each([&](std::int32_t node, double S, const Vec<D>& G) {
        const std::int32_t i = node + off;
        for (int a = 0; a < D; ++a) {
          sv[a] += S * v[i][a];
          sv_new[a] += S * v_new[i][a];
          if (full) sv_full[a] += S * v_full[i][a];
        }
        if constexpr (grad_in_loop) {
          const Vec<D>& u = (*vs)[i];
          for (int a = 0; a < D; ++a)
            for (int b = 0; b < D; ++b) l[a][b] += u[a] * G[b];
        }
      });
      GridAtParticle<D> g{P.velocity[p], Vec<D>(sv), Vec<D>(sv_new), Vec<D>(sv_full), dt};
      if (!full) g.Sv_full = updated_field ? g.Sv_new : g.Sv;
      if (contact_impulse) {
        // The first correction's contact change is an impulse on the particle (docs/contact.md):
        // V' = V + S dv_c, and the update proceeds from V'.
        stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) { g.V += S * contact_impulse_[node + off]; });
      }
      Effective<D> e = scheme.effective(g);
      e.A_dt -= (alpha_g * g.Sv + alpha_p * g.V) * dt;  // seed 002 Eq. 1.83
      // position_update = "updated": X += S v+ dt (seed 002 Eq. 1.61, the position update of
      // modified FLIP #1), the velocity whose gradient USL gives F, so that positions and F
      // integrate one field (docs/update-schemes.md, "Strong compression").
      const Vec<D> moved = position_updated ? g.Sv_new : Vec<D>(e.VV + 0.5 * e.A_dt);  // dX / dt
      const Vec<D> dX = moved * dt;
      // Dissipated energy relative to the non-dissipative FLIP update, seed 002 Eq. 1.44-1.46:
      // M Sa dt . (Sv + Sa dt / 2) - M dV . dX / dt. (Eq. 1.50 is the same only when VV = Sv.)
      const Vec<D> ag_dt = g.Sv_new - g.Sv;
      const double dissipated = P.mass[p] * (ag_dt.dot(g.Sv + 0.5 * ag_dt) - e.A_dt.dot(moved));
      const Vec<D> x_old = P.position[p];
      P.velocity[p] = g.V + e.A_dt;  // g.V is V, or V' after a contact impulse
      P.position[p] += dX;
      if (affine) {
        // APIC (Jiang et al. 2015): C = B D^-1 with B = sum S v+ (x_i - x_p)^T and
        // D = sum S (x_i - x_p)(x_i - x_p)^T, which makes the round trip conserve angular momentum
        // for every shape family (D = h^2/4 I for quadratic splines).
        Eigen::Matrix<double, D, D> B = Eigen::Matrix<double, D, D>::Zero(), Dp = B;
        stencil.for_each([&](std::int32_t node, double S, const Vec<D>&) {
          const Vec<D> d = detail::node_offset(grid_, node, x_old);
          B += S * v_new[node + off] * d.transpose();
          Dp += S * d * d.transpose();
        });
        P.affine_velocity[p].setZero();
        P.affine_velocity[p].template topLeftCorner<D, D>() = B * Dp.inverse();
      }
      if constexpr (with_stress) {
        Eigen::Matrix<double, D, D> L_D;
        if (grad_in_loop || walked) {
          for (int a = 0; a < D; ++a)
            for (int b = 0; b < D; ++b) L_D(a, b) = l[a][b];
        } else {
          L_D = stencil.gradient_of(*vs, off);
        }
        if (const char* bad = update_stress_at(p, L_D, stress.dt, increments)) record_failure(p, bad, first_bad, what);
      }
      return dissipated;
    });
  };
  ExactSum dissipated;
  if (vs) dissipated = use_full_mass_ ? move(std::true_type{}, std::true_type{}) : move(std::false_type{}, std::true_type{});
  else dissipated = use_full_mass_ ? move(std::true_type{}, std::false_type{}) : move(std::false_type{}, std::false_type{});
  sum_across(distribution_.comm(), &dissipated, 1);
  dissipated_energy_ += dissipated.value();
  if (vs)
    collectively([&] {
      if (first_bad >= 0) particle_failure(first_bad, what);
    });
}

template <int D>
bool Simulation<D>::uses_increments() const {
  for (const auto& m : materials_)
    if (m->uses_increment()) return true;
  return false;
}

template <int D>
void Simulation<D>::record_failure(std::int64_t p, const char* bad, std::int64_t& first_bad, std::string& what) {
#pragma omp critical(cairn_failure)
  if (first_bad < 0 || p < first_bad) {
    first_bad = p;
    what = bad;
  }
}

template <int D>
void Simulation<D>::update_stress_of(std::size_t p, const Mat3& L, const Mat3& dF, double dt) {
  Mat3& F = particles_.deformation_gradient[p];
  double* state = particles_.n_state_per_particle
                      ? &particles_.state[p * static_cast<std::size_t>(particles_.n_state_per_particle)]
                      : nullptr;
  MaterialPoint point{F, L, state, dt};
  point.dF = &dF;
  point.tau_old = &particles_.kirchhoff_stress[p];
  point.cell_size = grid_.min_cell_size();
  point.temperature = particles_.has_temperature ? &particles_.temperature[p] : nullptr;
  point.planar = D < 3;
  const Material& m = *materials_[particles_.material[p]];
  SymMat3& tau = particles_.kirchhoff_stress[p];
  if (mode_ == Mode::plane_stress) tau = plane_stress_update(m, F, point);
  else m.update_stress(point, tau);
}

template <int D>
void Simulation<D>::update_stresses(const std::vector<Vec<D>>& grid_velocity, double dt) {
  // Task 5: grad V_p = sum_i v_i (x) G_pi, dF = exp(grad V dt), F <- dF F, tau from the material.
  std::int64_t first_bad = -1;
  std::string what;
  const bool increments = uses_increments();
  gather(cache_, [&](std::int64_t p, const auto& stencil) {
    if (const char* bad = update_stress_at(p, stencil.gradient_of(grid_velocity, field_offset(p)), dt, increments))
      record_failure(p, bad, first_bad, what);
  });
  collectively([&] {
    if (first_bad >= 0) particle_failure(first_bad, what);
  });
}

template <int D>
const char* Simulation<D>::update_stress_at(std::int64_t p, const Eigen::Matrix<double, D, D>& L_D, double dt,
                                            bool increments) {
  // The kinematics stay in D dimensions: grad V has only its D x D block, so exp(grad V dt) is
  // [[exp(L_D dt), 0], [0, I]] and only the first D rows of F change. The 3x3 increments are
  // assembled only for models that read them (Material::uses_increment).
  static const Mat3 zero = Mat3::Zero(), identity = Mat3::Identity();
  Mat3& F = particles_.deformation_gradient[p];
  Eigen::Matrix<double, D, D> dF_D;
  if constexpr (D == 3) {
    // In scalars from the exponential to F (math/tensor.hpp, exp_detail::Scalar3).
    const exp_detail::Scalar3 dF3 = tensor_exp_scalars(L_D * dt);
    F = (dF3 * exp_detail::Scalar3::of(F)).matrix();
    if (increments) dF_D = dF3.matrix();
  } else {
    dF_D = tensor_exp<D>(L_D * dt);
    F.template topRows<D>() = (dF_D * F.template topRows<D>()).eval();
  }
  if (increments) {
    Mat3 L = Mat3::Zero(), dF = Mat3::Identity();
    L.template topLeftCorner<D, D>() = L_D;
    dF.template topLeftCorner<D, D>() = dF_D;
    update_stress_of(static_cast<std::size_t>(p), L, dF, dt);
  } else {
    update_stress_of(static_cast<std::size_t>(p), zero, identity, dt);
  }
  return failed_quantity(static_cast<std::size_t>(p));
}

template <int D>
const char* Simulation<D>::failed_quantity(std::size_t p) const {
  const Mat3& F = particles_.deformation_gradient[p];
  const SymMat3& tau = particles_.kirchhoff_stress[p];
  // det F; below 3D F is block diagonal [[F_D, 0], [0, F_zz]].
  const double J = D == 3 ? F.determinant() : F(2, 2) * (F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0));
  // One test for the common case: a sum is finite only if every term is.
  if (std::isfinite(particles_.velocity[p].sum() + particles_.position[p].sum() + tau.trace() + tau(1, 2) +
                    tau(0, 2) + tau(0, 1)) &&
      J > 0.0)
    return nullptr;
  if (!particles_.velocity[p].allFinite()) return "velocity";
  if (!particles_.position[p].allFinite()) return "position";
  if (!(J > 0.0)) return "det F";
  if (!tau.allFinite()) return "stress";
  return nullptr;
}

template <int D>
const char* Simulation<D>::update_particle(std::size_t p, const Mat3& L, const Mat3& dF, double dt) {
  Mat3& F = particles_.deformation_gradient[p];
  // Below 3D dF = [[dF_D, 0], [0, 1]]: only the first D rows of F change (the same values as
  // the full product, which adds zeros).
  if constexpr (D == 3) F = dF * F;
  else F.template topRows<D>() = (dF.template topLeftCorner<D, D>() * F.template topRows<D>()).eval();
  update_stress_of(p, L, dF, dt);
  return failed_quantity(p);
}

template <int D>
void Simulation<D>::particle_failure(std::int64_t first_bad, const std::string& what) const {
  const auto p = static_cast<std::size_t>(first_bad);
  std::string value;
  if (what == "det F") value = "det F = " + failure_number(particles_.deformation_gradient[p].determinant());
  else value = what + " is not finite";
  std::string where = fmt::format("body {}, at ({:.6g})", particles_.body[p], fmt::join(particles_.position[p], ", "));
  if (wls_ && wls::is_surface(particles_, p)) {
    // A WLS surface particle carries no mass: say whether it has left the body (docs/wls.md).
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < particles_.n(); ++k)
      if (!wls::is_surface(particles_, k))
        nearest = std::min(nearest, (particles_.position[k] - particles_.position[p]).norm());
    where += fmt::format("; a WLS surface particle (zero volume), {:.3g} cells from the nearest particle with volume",
                         nearest / grid_.min_cell_size());
  }
  throw SimulationFailure(first_bad, what, "particle " + std::to_string(first_bad) + " (" + where + "): " + value);
}

#define CAIRN_INSTANTIATE(D) \
  template void Simulation<D>::update_particles(double, StressPass); \
  template bool Simulation<D>::uses_increments() const; \
  template void Simulation<D>::record_failure(std::int64_t, const char*, std::int64_t&, std::string&); \
  template void Simulation<D>::update_stress_of(std::size_t, const Mat3&, const Mat3&, double); \
  template void Simulation<D>::update_stresses(const std::vector<Vec<D>>&, double); \
  template const char* Simulation<D>::update_stress_at(std::int64_t, const Eigen::Matrix<double, D, D>&, double, bool); \
  template const char* Simulation<D>::update_particle(std::size_t, const Mat3&, const Mat3&, double); \
  template const char* Simulation<D>::failed_quantity(std::size_t) const; \
  template void Simulation<D>::particle_failure(std::int64_t, const std::string&) const; \

CAIRN_INSTANTIATE(1)
CAIRN_INSTANTIATE(2)
CAIRN_INSTANTIATE(3)
#undef CAIRN_INSTANTIATE

}  // namespace cairn
