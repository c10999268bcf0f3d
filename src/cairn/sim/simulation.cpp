#include "cairn/sim/simulation.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "cairn/materials/plane_stress.hpp"
#include "cairn/math/tensor.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/failure.hpp"

namespace cairn {

namespace {

/// Deterministic parallel sum: fixed chunks, combined in order (independent of thread count).
template <class T, class Fn>
T chunked_sum(std::int64_t n, T zero, Fn&& term) {
  constexpr std::int64_t chunk = 4096;
  const std::int64_t n_chunks = (n + chunk - 1) / chunk;
  std::vector<T> partial(static_cast<std::size_t>(n_chunks), zero);
#pragma omp parallel for schedule(static)
  for (std::int64_t c = 0; c < n_chunks; ++c) {
    T s = zero;
    for (std::int64_t p = c * chunk; p < std::min(n, (c + 1) * chunk); ++p) s += term(p);
    partial[c] = s;
  }
  T total = zero;
  for (const auto& s : partial) total += s;
  return total;
}

}  // namespace

template <int D>
Simulation<D>::Simulation(const Config& config) : config_(config), mode_(config.simulation.mode) {
  if (config_.simulation.threads > 0) omp_set_num_threads(config_.simulation.threads);
  for (const auto& mc : config_.materials) materials_.push_back(make_material(mc));
  ShapeContext ctx{config_.method, D};
  shape_ = make_shape_family<D>(ctx);
  scheme_ = SchemeRegistry<D>::instance().create("update scheme", config_.method.update, config_.method);
  setup_grid();
  int n_state = 0;
  for (const auto& m : materials_) n_state = std::max(n_state, m->n_state());
  particles_.n_state_per_particle = n_state;
  create_particles<D>(config_, grid_, materials_, mode_, particles_);
  nodes_.resize(grid_.n_nodes());
  body_acceleration_.assign(particles_.n(), Vec<D>::Zero());
  double max_mass = 0.0;
  for (double m : particles_.mass) max_mass = std::max(max_mass, m);
  small_mass_ = 1e-15 * max_mass;  // nodes below this hold no velocity
  conditions_ = GridConditions<D>(config_.boundary, grid_);

  if (!config_.body_force.expression.empty()) {
    const int n_threads = omp_get_max_threads();
    for (int t = 0; t < n_threads; ++t)
      body_force_.push_back(std::make_unique<ExpressionVector<D>>(config_.body_force.expression,
                                                                  config_.constants));
    body_force_constant_ = body_force_[0]->is_constant();
    if (body_force_constant_) body_force_value_ = (*body_force_[0])(Vec<D>::Zero(), Vec<D>::Zero(), 0.0);
    node_body_force_.assign(grid_.n_nodes(), Vec<D>::Zero());
  }
}

template <int D>
Simulation<D>::~Simulation() = default;

template <int D>
void Simulation<D>::setup_grid() {
  const auto& g = config_.grid;
  Vec<D> origin, h;
  IVec<D> n_cells;
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) {
    origin[a] = g.origin[a];
    h[a] = g.cell_size[a];
    n_cells[a] = static_cast<int>(std::lround(g.extent[a] / g.cell_size[a]));
    periodic[a] = config_.boundary.face[2 * a] == FaceCondition::periodic;
  }
  grid_ = Grid<D>(origin, n_cells, h, shape_->ghost_layers(), periodic);
}

template <int D>
double Simulation<D>::next_dt() const {
  const auto& s = config_.simulation;
  double dt = s.fixed_dt;
  if (dt <= 0.0) {
    const auto n = static_cast<std::int64_t>(particles_.n());
    double c_max = 0.0, v_max = 0.0;
#pragma omp parallel for reduction(max : c_max, v_max)
    for (std::int64_t p = 0; p < n; ++p) {
      c_max = std::max(c_max, materials_[particles_.material[p]]->wave_speed(particles_.deformation_gradient[p]));
      v_max = std::max(v_max, particles_.velocity[p].norm());
    }
    dt = s.cfl * grid_.min_cell_size() / (c_max + v_max);  // seed 001 Eq. 34
  }
  const double remaining = s.end_time - time_;
  if (remaining > 0.0 && dt > remaining) dt = remaining;
  return dt;
}

template <int D>
void Simulation<D>::step(double dt) {
  build_stencils();
  particles_to_grid();
  update_grid(dt);
  update_particles(dt);
  update_stresses(dt);
  time_ += dt;
  ++step_;
}

template <int D>
void Simulation<D>::build_stencils() {
  shape_->build(grid_, particles_, cache_);
  colour_blocks(grid_, cache_);
}

template <int D>
void Simulation<D>::compute_body_forces() {
  if (body_force_.empty()) return;
  const auto n = static_cast<std::int64_t>(particles_.n());
  if (body_force_constant_) {
    std::fill(body_acceleration_.begin(), body_acceleration_.end(), body_force_value_);
    return;
  }
#pragma omp parallel
  {
    auto& expr = *body_force_[omp_get_thread_num()];
#pragma omp for schedule(static)
    for (std::int64_t p = 0; p < n; ++p)
      body_acceleration_[p] = expr(particles_.position[p], particles_.reference_position[p], time_);
  }
}

template <int D>
void Simulation<D>::particles_to_grid() {
  for_each_node(grid_.n_nodes(), [&](std::int32_t i) {
    nodes_.mass[i] = 0.0;
    nodes_.momentum[i].setZero();
    nodes_.force[i].setZero();
    nodes_.reaction[i].setZero();
  });
  compute_body_forces();
  const bool has_body_force = !body_force_.empty();
  if (has_body_force) std::fill(node_body_force_.begin(), node_body_force_.end(), Vec<D>::Zero());
  const auto& P = particles_;
  // Tasks 1-2: m = S^T M, p = S^T M V, f = -G^T V0 tau + S^T M B (seed 000 Table 1).
  scatter(cache_, [&](std::int32_t p, std::size_t s) {
    const std::int32_t i = cache_.node[s];
    const double Sm = cache_.weight[s] * P.mass[p];
    nodes_.mass[i] += Sm;
    nodes_.momentum[i] += Sm * P.velocity[p];
    const Vec<D> internal =
        -P.volume0[p] * (P.kirchhoff_stress[p].template topLeftCorner<D, D>() * cache_.gradient[s]);
    nodes_.force[i] += internal;
    if (has_body_force) {
      const Vec<D> fb = Sm * body_acceleration_[p];
      nodes_.force[i] += fb;
      node_body_force_[i] += fb;
    }
  });
}

template <int D>
void Simulation<D>::update_grid(double dt) {
  // Task 3 with the lumped mass: v = m^-1 p, p+ = p + f dt, v+ = m^-1 p+.
  for_each_node(grid_.n_nodes(), [&](std::int32_t i) {
    const double m = nodes_.mass[i];
    if (m > small_mass_) {
      nodes_.velocity[i] = nodes_.momentum[i] / m;
      nodes_.velocity_new[i] = (nodes_.momentum[i] + nodes_.force[i] * dt) / m;
    } else {
      nodes_.velocity[i].setZero();
      nodes_.velocity_new[i].setZero();
    }
  });
  conditions_.apply_step(nodes_, dt);

  // External work of this step: body forces and reactions at the mean grid velocity.
  const bool has_body_force = !body_force_.empty();
  if (has_body_force || !conditions_.empty()) {
    external_work_ += dt * chunked_sum<double>(grid_.n_nodes(), 0.0, [&](std::int64_t i) {
      const Vec<D> v_mean = 0.5 * (nodes_.velocity[i] + nodes_.velocity_new[i]);
      double w = nodes_.reaction[i].dot(v_mean);
      if (has_body_force) w += node_body_force_[i].dot(v_mean);
      return w;
    });
  }
}

template <int D>
void Simulation<D>::update_particles(double dt) {
  StepState<D> state{grid_, nodes_, cache_, particles_, dt};
  scheme_->update_particles(state);
}

template <int D>
Mat3 Simulation<D>::stress_for(std::size_t p, const Mat3& L, double dt) {
  Mat3& F = particles_.deformation_gradient[p];
  double* state = particles_.n_state_per_particle
                      ? &particles_.state[p * static_cast<std::size_t>(particles_.n_state_per_particle)]
                      : nullptr;
  const MaterialPoint point{F, L, state, dt};
  const Material& m = *materials_[particles_.material[p]];
  if (mode_ == Mode::plane_stress) return plane_stress_update(m, F, point);
  return m.update(point);
}

template <int D>
void Simulation<D>::update_stresses(double dt) {
  // Task 5: grad V_p = sum_i v+_i (x) G_pi, dF = exp(grad V dt), F <- dF F, tau from the material.
  std::int64_t first_bad = -1;
  std::string what;
  gather(cache_, [&](std::int64_t p, std::size_t begin, std::size_t end) {
    Mat3 L = Mat3::Zero();
    for (std::size_t s = begin; s < end; ++s)
      L.template topLeftCorner<D, D>() += nodes_.velocity_new[cache_.node[s]] * cache_.gradient[s].transpose();
    particles_.velocity_gradient[p] = L;
    Mat3& F = particles_.deformation_gradient[p];
    F = tensor_exp(L * dt) * F;
    particles_.kirchhoff_stress[p] = stress_for(static_cast<std::size_t>(p), L, dt);
    const double J = F.determinant();
    const char* bad = nullptr;
    if (!particles_.velocity[p].allFinite()) bad = "velocity";
    else if (!particles_.position[p].allFinite()) bad = "position";
    else if (!(J > 0.0)) bad = "det F";
    else if (!particles_.kirchhoff_stress[p].allFinite()) bad = "stress";
    if (bad) {
#pragma omp critical(cairn_failure)
      if (first_bad < 0 || p < first_bad) {
        first_bad = p;
        what = bad;
      }
    }
  });
  if (first_bad >= 0) {
    const auto p = static_cast<std::size_t>(first_bad);
    std::string value;
    if (what == "det F") value = "det F = " + std::to_string(particles_.deformation_gradient[p].determinant());
    else value = what + " is not finite";
    throw SimulationFailure(first_bad, what,
                            "particle " + std::to_string(first_bad) + " (body " +
                                std::to_string(particles_.body[p]) + "): " + value);
  }
}

template <int D>
Totals Simulation<D>::totals() const {
  const auto& P = particles_;
  const auto n = static_cast<std::int64_t>(P.n());
  Totals t;
  t.kinetic_energy = chunked_sum<double>(n, 0.0, [&](std::int64_t p) {
    return 0.5 * P.mass[p] * P.velocity[p].squaredNorm();
  });
  t.strain_energy = chunked_sum<double>(n, 0.0, [&](std::int64_t p) {
    return P.volume0[p] * materials_[P.material[p]]->energy_density(P.deformation_gradient[p]);
  });
  t.momentum = chunked_sum<Vec3>(n, Vec3::Zero(), [&](std::int64_t p) {
    return Vec3(to3<D>(P.mass[p] * P.velocity[p]));
  });
  t.mass = chunked_sum<double>(n, 0.0, [&](std::int64_t p) { return P.mass[p]; });
  return t;
}

template class Simulation<1>;
template class Simulation<2>;
template class Simulation<3>;

}  // namespace cairn
