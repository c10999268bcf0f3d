// Simulation<D>::step: the stages of seed 000 Table 1 in the order the stress-update timing asks
// for, the stencils (and a distributed step's exchanges), particles to grid and the grid update.
#include "cairn/sim/simulation_detail.hpp"
#include "cairn/sim/stress_timing.hpp"

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
#include "cairn/wls/fields.hpp"
#include "cairn/wls/integrator.hpp"
#include "cairn/wls/step.hpp"

namespace cairn {

template <int D>
void Simulation<D>::step(double dt) {
  if (wls_) {
    wls_step(dt);
    return;
  }
  auto clock = detail::StageClock::now();
  auto lap = [&](int stage) {
    const auto now = detail::StageClock::now();
    stage_seconds_[stage] += std::chrono::duration<double>(now - clock).count();
    clock = now;
  };
  const FullMass need = scheme_->full_mass();
  use_full_mass_ = need != FullMass::none;
  if (use_full_mass_ && config_.method.full_mass_cfl > 0.0) {
    // Periodic FMPM/XPIC (seed 000 Sec. 3.1): full-mass steps every CFL_X h / c, FLIP between.
    use_full_mass_ = time_ >= next_full_mass_time_ * (1.0 - 1e-12);
    if (use_full_mass_)
      next_full_mass_time_ = time_ + config_.method.full_mass_cfl * grid_.min_cell_size() / max_signal_speed();
  }
  const bool fmpm_velocities = use_full_mass_ && need == FullMass::of_updated;
  if (scheme_->affine() && particles_.affine_velocity.size() != particles_.n()) {
    particles_.has_affine = true;  // e.g. restarted with APIC from a checkpoint without C_p
    particles_.affine_velocity.assign(particles_.n(), Mat3::Zero());
  }
  const int k = config_.method.order;
  step_dt_ = dt;

  try {
    step_stages(dt, need, fmpm_velocities, k, lap);
  } catch (const SimulationFailure& f) {
    distribution_.drop_ghosts(particles_);
    if (distributed() || !cache_.sorted_storage) throw;  // (distributed: named by collectively)
    throw named_by_id(f);  // a sorted serial run
  } catch (...) {
    distribution_.drop_ghosts(particles_);  // a failed step leaves the owned particles only
    throw;
  }
  distribution_.drop_ghosts(particles_);
  velocity_conditions_.finish_step();
  time_ += dt;
  ++step_;
}

template <int D>
template <class Lap>
void Simulation<D>::step_stages(double dt, FullMass need, bool fmpm_velocities, int k, Lap& lap) {
  // Seed 000 Table 1, with the stress update where the timing puts it (sim/stress_timing.hpp).
  const StressTiming& timing = *timing_;
  build_stencils();  // S_pi, G_pi of every particle
  lap(0);
  if (timing.before_forces > 0.0) {
    particles_to_grid(true, false);  // Tasks 1-2: m, p
    velocity_conditions_.prepare(grid_, condition_fields(), small_mass_, time_, dt);
    lap(1);
    stress_velocity_from_momentum(nodes_.momentum, fmpm_velocities);
    lap(3);
    update_stresses(nodes_.velocity_work, timing.before_forces * dt);  // Task 5 (USF, USAVG)
    refresh_ghosts(particles_.kirchhoff_stress);  // the forces below read the ghosts' stresses
    lap(5);
    particles_to_grid(false, true);  // Task 2: f
  } else {
    particles_to_grid(true, true);  // Tasks 1-2: m, p, f
    velocity_conditions_.prepare(grid_, condition_fields(), small_mass_, time_, dt);
  }
  lap(1);
  update_grid(dt);  // Task 3: v, v+ with the conditions
  lap(2);
  if (use_full_mass_) {
    // Task 3 of FMPM/XPIC: v+ = m~_k^-1 p+ (FMPM) or v = m~_k^-1 p (XPIC, blends).
    full_mass_velocity(need == FullMass::of_updated ? nodes_.velocity_new : nodes_.velocity,
                       nodes_.velocity_full, k);
    run_hooks(StepPoint::after_full_mass, dt);
  }
  lap(3);
  // Task 4, and Task 5 in the same particle loop when the timing updates there (the stress
  // update reads the stencils and grid velocities the particle update reads; its time counts as
  // particle_update).
  update_particles(dt, timing.with_particle_update > 0.0
                           ? StressPass{fmpm_velocities ? &nodes_.velocity_full : &nodes_.velocity_new,
                                        timing.with_particle_update * dt}
                           : StressPass{});
  lap(4);
  if (timing.after_update > 0.0) {
    // Task 5 from the re-extrapolated updated particle momenta (USL+, USAVG+).
    refresh_ghosts(particles_.velocity);
    reextrapolate_momentum();
    lap(1);
    stress_velocity_from_momentum(grid_term_, fmpm_velocities);
    lap(3);
    update_stresses(nodes_.velocity_work, timing.after_update * dt);
  }
  lap(5);
  run_hooks(StepPoint::end_of_step, dt);
}

/// The engine's stages that the WLS step (wls/step.hpp) runs between its own.
template <int D>
class Simulation<D>::WlsStages final : public wls::EngineStages<D> {
 public:
  explicit WlsStages(Simulation& sim) : sim_(sim), clock_(detail::StageClock::now()) {}
  const std::vector<Vec<D>>* body_accelerations() override {
    sim_.compute_body_forces();
    return sim_.body_force_.empty() ? nullptr : &sim_.body_acceleration_;
  }
  std::vector<Vec<D>>* node_body_forces() override { return &sim_.node_body_force_; }
  bool surface_loads(double dt, std::span<wls::SurfaceLoads<D>* const> loads) override {
    if (sim_.tractions_.empty()) return false;
    // The tractions' faces convected by F (bc/traction.hpp); the integrator spreads their forces
    // over the cut-cell surface (wls/integrator.cpp, spread_surface_loads). With one SurfaceLoads
    // per contact field, a face goes to its particle's field.
    for (wls::SurfaceLoads<D>* l : loads) l->reset(2 * D * sim_.tractions_.n_loads());
    const std::int32_t nn = sim_.grid_.n_nodes();
    std::size_t q = 0;  // (for_each_face visits the faces in order)
    sim_.tractions_.for_each_face(
        sim_.particles_, sim_.time_ + 0.5 * dt,
        [&](std::int32_t g, const Vec<D>& centre, const Vec<D>& normal_area, const Vec<D>& force) {
          const auto p = static_cast<std::size_t>(sim_.tractions_.face_particle(q++));
          const std::size_t field = loads.size() == 1 ? 0 : static_cast<std::size_t>(sim_.field_offset_[p] / nn);
          wls::SurfaceLoads<D>& to = *loads[field];
          to.centre.push_back(centre);
          to.face_force.push_back(force);
          to.group.push_back(g);
          to.force[g] += force;
          to.normal[g] += normal_area;
        });
    return true;
  }
  void prepare_contact(double dt) override {
    // The contact's point clouds and normals read the engine's stencils of every particle (the
    // linear hat, seed 001's narrow S: sim/simulation.cpp) and their slot offsets; the
    // after_momentum hook is the contact's: nodes, normals, the first correction, the totals.
    sim_.build_stencils();
    sim_.run_hooks(StepPoint::after_momentum, dt);
  }
  const std::vector<Vec<D>>* contact_impulse() override {
    const Contact<D>* c = sim_.contact_.get();
    return c && c->impulse() && c->corrects_extrapolation() ? &sim_.contact_impulse_ : nullptr;
  }
  void prepare_conditions(double dt) override {
    sim_.velocity_conditions_.prepare(sim_.grid_, sim_.condition_fields(), sim_.small_mass_, sim_.time_, dt);
  }
  void update_grid(double dt) override { sim_.update_grid(dt); }
  void impose_end_conditions() override {
    sim_.impose_conditions(sim_.nodes_.velocity_new, VelocityConditions<D>::When::end);
  }
  void held_components(std::vector<std::uint8_t>& held) override {
    cairn::held_components(sim_.conditions_, sim_.velocity_conditions_, sim_.grid_.n_nodes(), held);
  }
  void update_materials(const std::vector<Eigen::Matrix<double, D, D>>& velocity_gradient, double dt) override {
    const auto n = static_cast<std::int64_t>(sim_.particles_.n());
    std::int64_t first_bad = -1;
    std::string what;
#pragma omp parallel for schedule(static)
    for (std::int64_t p = 0; p < n; ++p) {
      Mat3 L = Mat3::Zero();
      L.template topLeftCorner<D, D>() = velocity_gradient[p];
      const Mat3 dF = Mat3::Identity() + L * dt;
      if (const char* bad = sim_.update_particle(static_cast<std::size_t>(p), L, dF, dt)) {
#pragma omp critical(cairn_failure)
        if (first_bad < 0 || p < first_bad) {
          first_bad = p;
          what = bad;
        }
      }
    }
    if (first_bad >= 0) sim_.particle_failure(first_bad, what);
  }
  void lap(int stage) override {
    const auto now = detail::StageClock::now();
    sim_.stage_seconds_[stage] += std::chrono::duration<double>(now - clock_).count();
    clock_ = now;
  }

 private:
  Simulation& sim_;
  detail::StageClock::time_point clock_;
};

template <int D>
void Simulation<D>::wls_step(double dt) {
  step_dt_ = dt;
  keep_particles_sorted(false);  // by the last step's colouring (before its stencils are rebuilt)
  WlsStages stages(*this);
  if (wls_fields_)
    wls::step_fields(*wls_fields_, stages, grid_, particles_, field_offset_, nodes_, material_density_, dt);
  else
    wls::step(*wls_, stages, grid_, particles_, nodes_, material_density_, dt);
  velocity_conditions_.finish_step();
  time_ += dt;
  ++step_;
}

template <int D>
void Simulation<D>::build_stencils() {
  if (distributed()) {
    distribute_and_build();
  } else {
    keep_particles_sorted(false);
    shape_->build(grid_, particles_, cache_);
  }
  colour_blocks(grid_, particles_, cache_);
}

template <int D>
bool Simulation<D>::widened_to_global_reach() {
  std::int64_t reach[2 * D];
  for (int a = 0; a < D; ++a) {
    reach[a] = cache_.reach_lo[a];
    reach[D + a] = cache_.reach_hi[a];
  }
  distribution_.comm().max(reach, 2 * D);
  std::int64_t needed = 0;
  for (auto r : reach) needed = std::max(needed, r);
  if (needed > reach_) {
    reach_ = static_cast<int>(needed);
    return true;
  }
  for (int a = 0; a < D; ++a) {
    cache_.reach_lo[a] = static_cast<int>(reach[a]);
    cache_.reach_hi[a] = static_cast<int>(reach[D + a]);
  }
  return false;
}

template <int D>
void Simulation<D>::migrate_and_rebalance() {
  // Particles that crossed into another box move there; the imbalance (of particle counts or
  // costs, parallel.balance) is measured on the result, and beyond the threshold the cuts that
  // are out of balance move (docs/parallel.md, "Load balance").
  distribution_.migrate(particles_);
  imbalance_ = distribution_.imbalance(particles_);
  if (imbalance_ - 1.0 > config_.simulation.rebalance_threshold) {
    const auto repartitions = distribution_.repartitions();
    distribution_.rebalance(particles_, config_.simulation.rebalance_threshold);
    // Nodes change ranks: each takes the contact record with it (release = "separation").
    if (contact_ && distribution_.repartitions() != repartitions) contact_->share_record(distribution_.comm());
  }
}

template <int D>
void Simulation<D>::distribute_nodes_and_build() {
  const Comm& comm = distribution_.comm();
  // Storage sorted by cell block as in a serial run (the last colouring still indexes it), then
  // the migration: leavers out, arrivals appended.
  keep_particles_sorted(false);
  const std::size_t n_before = particles_.n();
  const std::int64_t received_before = distribution_.received();
  migrate_and_rebalance();
  if (particles_.n() != n_before || distribution_.received() != received_before)
    cache_.colouring_valid = false;  // block_of and order index the storage before the migration
  for (;;) {
    set_window(node_window());
    std::optional<SimulationFailure> failure;
    try {
      shape_->build(grid_, particles_, cache_);
    } catch (const SimulationFailure& f) {
      failure = f;
    }
    // The window must hold the stencils of every rank's particles at the largest reach (CPDI
    // domains stretch): a wider reach widens every window and the step starts over.
    if (widened_to_global_reach()) continue;
    // With the reach covered, a stencil leaving the window leaves the stored grid: the failure
    // of a serial run.
    if (comm.any(failure.has_value())) collectively([&] {
        if (failure) throw *failure;
      });
    break;
  }
  if (!halo_.built_for(reach_ + 1, distribution_.partitions()))
    halo_.build(comm, distribution_.decomposition(), whole_, reach_ + 1, distribution_.partitions());
  cache_.n_owned = particles_.n();
  cache_.id_order.clear();
  tractions_.localise(particles_, particles_.n());
  compute_field_offsets();
}

template <int D>
void Simulation<D>::distribute_and_build() {
  if (node_halo_) {
    distribute_nodes_and_build();
    return;
  }
  const Comm& comm = distribution_.comm();
  migrate_and_rebalance();
  for (;;) {
    distribution_.add_ghosts(particles_, reach_);
    set_window(distribution_.window(whole_, reach_));
    const std::size_t n_own = distribution_.n_owned();
    std::int64_t failed_at = -1;
    std::optional<SimulationFailure> failure;
    try {
      shape_->build(grid_, particles_, cache_);
    } catch (const SimulationFailure& f) {
      failure = f;
      failed_at = f.particle();
    }
    // The window and ghost band must cover the stencils' reach over all ranks' particles; a
    // wider reach (CPDI domains stretch) widens them and the step starts over.
    if (widened_to_global_reach()) {
      distribution_.drop_ghosts(particles_);
      continue;
    }
    // With the reach covered, an owned particle whose stencil leaves the window leaves the
    // stored grid: the failure of a serial run. (Owned particles come first, so the lowest
    // failing index is an owned one whenever there is one.)
    const bool owned_failed = failure && failed_at < static_cast<std::int64_t>(n_own);
    if (comm.any(owned_failed)) collectively([&] {
        if (owned_failed) throw *failure;
      });
    // Only a ghost failed while the reach fits: a sizing error; widen and retry (bounded).
    if (comm.any(failure.has_value())) {
      if (reach_ > 64) throw std::runtime_error("distributed run: ghost stencils do not fit the window");
      ++reach_;
      distribution_.drop_ghosts(particles_);
      continue;
    }
    break;
  }
  cache_.n_owned = distribution_.n_owned();
  cache_.id_order = distribution_.id_order();
  tractions_.localise(particles_, distribution_.n_owned());
  compute_field_offsets();
}

template <int D>
void Simulation<D>::compute_body_forces() {
  if (body_force_.empty()) return;
  const auto n = static_cast<std::int64_t>(particles_.n());
  if (body_force_constant_) {
    // particles_to_grid reads body_force_value_; the WLS fits take b_p per particle (seed 001
    // Sec. 4.1, f_p = rho_p b_p), so they get the constant in every slot.
    if (wls_) body_acceleration_.assign(particles_.n(), body_force_value_);
    return;
  }
  body_acceleration_.resize(particles_.n());
#pragma omp parallel
  {
    auto& expr = *body_force_[omp_get_thread_num()];
#pragma omp for schedule(static)
    for (std::int64_t p = 0; p < n; ++p)
      body_acceleration_[p] = expr(particles_.position[p], particles_.reference_position[p], time_);
  }
}

template <int D>
void Simulation<D>::particles_to_grid(bool mass_and_momentum, bool forces) {
  const bool has_body_force = !body_force_.empty();
  const bool affine = scheme_->affine();
  for_each_node(n_slots(), [&](std::int32_t i) {
    if (mass_and_momentum) {
      nodes_.mass[i] = 0.0;
      nodes_.momentum[i].setZero();
    }
    if (forces) {
      nodes_.force[i].setZero();
      if (has_body_force) node_body_force_[i].setZero();
    }
    if (!nodes_.reaction.empty()) nodes_.reaction[i].setZero();
  });
  if (forces) compute_body_forces();
  const auto& P = particles_;
  // Tasks 1-2: m = S^T M, p = S^T M V, f = -G^T V0 tau + S^T M b (seed 000 Table 1). The
  // particle's factors (M, V, -V0 tau) are read once, not once per stencil entry, and the entry
  // loop is compiled without tests for the plain step (all three sums, no affine part, no body
  // force).
  using MatD = Eigen::Matrix<double, D, D>;
  // The node arrays through raw pointers read once, offset by the particle's field: Eigen's
  // stores may alias anything, so through the std::vectors every entry reloaded their data
  // pointers (as in lumped_projection).
  double* const mass_all = nodes_.mass.data();
  Vec<D>* const momentum_all = nodes_.momentum.data();
  Vec<D>* const force_all = nodes_.force.data();
  auto extrapolate = [&](auto plain_tag) {
    constexpr bool plain = decltype(plain_tag)::value;
    scatter(cache_, [&](std::int32_t p, const auto& stencil) {
      const std::int32_t off = field_offset(p);
      double* const mass = mass_all + off;
      Vec<D>* const momentum = momentum_all + off;
      Vec<D>* const force_at = force_all + off;
      const double M = P.mass[p];
      const Vec<D> V = P.velocity[p];
      const MatD stress = -P.volume0[p] * P.kirchhoff_stress[p].template block<D>();
      stencil.for_each_force(stress, [&](std::int32_t node, double S, const Vec<D>& force) {
        const double Sm = S * M;
        if (plain || mass_and_momentum) {
          mass[node] += Sm;
          if (!plain && affine) {
            const Vec<D> dx = detail::node_offset(grid_, node, P.position[p]);
            momentum[node] += Sm * (V + P.affine_velocity[p].template topLeftCorner<D, D>() * dx);
          } else {
            momentum[node] += Sm * V;
          }
        }
        if (plain || forces) {
          force_at[node] += force;
          if (!plain && has_body_force) {
            const Vec<D> fb = Sm * (body_force_constant_ ? body_force_value_ : body_acceleration_[p]);
            force_at[node] += fb;
            node_body_force_[node + off] += fb;
          }
        }
      });
    });
  };
  if (mass_and_momentum && forces && !affine && !has_body_force) extrapolate(std::true_type{});
  else extrapolate(std::false_type{});
  if (forces) run_hooks(StepPoint::after_forces, step_dt_);  // (tractions: this rank's faces)
  // A node-halo run completes the sums at the nodes its neighbours share, in one exchange.
  if (node_halo_) {
    if (mass_and_momentum && forces) {
      if (has_body_force) sum_halo(nodes_.mass, nodes_.momentum, nodes_.force, node_body_force_);
      else sum_halo(nodes_.mass, nodes_.momentum, nodes_.force);
    } else if (mass_and_momentum) {
      sum_halo(nodes_.mass, nodes_.momentum);
    } else if (forces) {
      if (has_body_force) sum_halo(nodes_.force, node_body_force_);
      else sum_halo(nodes_.force);
    }
  }
  if (mass_and_momentum) run_hooks(StepPoint::after_momentum, step_dt_);
}

template <int D>
void Simulation<D>::update_grid(double dt) {
  // Task 3 with the lumped mass: v = m^-1 p, p+ = p + f dt, v+ = m^-1 p+. The staggered central
  // difference start uses half the first acceleration (seed 001 Sec. 4.7, seed 003 Eq. 11-15).
  const double f_scale =
      ((config_.method.time_integration == "central_difference" || wls_) && step_ == 0) ? 0.5 : 1.0;
  for_each_node(n_slots(), [&](std::int32_t i) {
    const double m = nodes_.mass[i];
    if (m > small_mass_) {
      nodes_.velocity[i] = nodes_.momentum[i] / m;
      nodes_.velocity_new[i] = (nodes_.momentum[i] + f_scale * nodes_.force[i] * dt) / m;
    } else if (wls_) {
      // WLS: the grid velocity is the least-squares fit wherever particles see the node, mass
      // or not (seed 001 Sec. 4.6); without mass there is no acceleration. With contact, the
      // fit of the slot's field.
      const std::int32_t nn = grid_.n_nodes();
      nodes_.velocity[i] = nodes_.velocity_new[i] =
          wls_fields_ ? wls_fields_->node_velocity(i / nn, i % nn) : wls_->node_velocity()[i];
    } else {
      nodes_.velocity[i].setZero();
      nodes_.velocity_new[i].setZero();
    }
  });
  run_hooks(StepPoint::before_conditions, dt);
  for (int f = 0; f < n_fields_; ++f) {
    const std::int32_t off = f * grid_.n_nodes();
    conditions_.apply_step(nodes_, dt, off);
    velocity_conditions_.apply_step(nodes_, dt, config_.boundary.acceleration == BoundaryAcceleration::zero, off,
                                    f == 0);
  }
  velocity_conditions_.reduce_reactions();

  // External work of this step: body forces, tractions and reactions at the mean grid velocity,
  // summed exactly over the nodes (traction faces) each rank owns and over the ranks.
  const bool has_body_force = !body_force_.empty();
  std::array<ExactSum, 3> work;
  if (!tractions_.empty() && wls_) {
    // (WLS: the node forces of the tractions are the integrator's, wls/integrator.cpp; with
    // contact each field's, on its slots)
    const int n_integrators = wls_fields_ ? wls_fields_->n() : 1;
    for (int k = 0; k < n_integrators; ++k) {
      const auto& f = (wls_fields_ ? wls_fields_->integrator(k) : *wls_).surface_force();
      const std::size_t off = static_cast<std::size_t>(k) * static_cast<std::size_t>(grid_.n_nodes());
      for (std::size_t i = 0; i < f.size(); ++i) {
        work[0].add(f[i].dot(nodes_.velocity[off + i]));
        work[1].add(f[i].dot(nodes_.velocity_new[off + i]));
      }
    }
  } else if (!tractions_.empty()) {
    work[0] = tractions_.power(nodes_.velocity, contact_ ? &field_offset_ : nullptr);
    work[1] = tractions_.power(nodes_.velocity_new, contact_ ? &field_offset_ : nullptr);
  }
  const bool node_work = has_body_force || !conditions_.empty() || !velocity_conditions_.empty();
  if (node_work) {
    const std::int32_t nn = grid_.n_nodes();
    const bool whole = grid_.is_whole();
    work[2] = exact_sums<1>(n_slots(), [&](std::int64_t i, std::array<double, 1>& w) {
      w[0] = 0.0;
      if (!whole && !grid_.owns(static_cast<std::int32_t>(i % nn))) return;
      const Vec<D> v_mean = 0.5 * (nodes_.velocity[i] + nodes_.velocity_new[i]);
      if (!nodes_.reaction.empty()) w[0] += nodes_.reaction[i].dot(v_mean);
      if (has_body_force) w[0] += node_body_force_[i].dot(v_mean);
    })[0];
  }
  sum_across(distribution_.comm(), work.data(), 3);
  if (!tractions_.empty()) external_work_ += 0.5 * dt * (work[0].value() + work[1].value());
  if (node_work || distributed()) external_work_ += dt * work[2].value();
}

#define CAIRN_INSTANTIATE(D) \
  template void Simulation<D>::step(double); \
  template void Simulation<D>::wls_step(double); \
  template void Simulation<D>::build_stencils(); \
  template void Simulation<D>::distribute_and_build(); \
  template void Simulation<D>::distribute_nodes_and_build(); \
  template bool Simulation<D>::widened_to_global_reach(); \
  template void Simulation<D>::compute_body_forces(); \
  template void Simulation<D>::particles_to_grid(bool, bool); \
  template void Simulation<D>::update_grid(double); \

CAIRN_INSTANTIATE(1)
CAIRN_INSTANTIATE(2)
CAIRN_INSTANTIATE(3)
#undef CAIRN_INSTANTIATE

}  // namespace cairn
