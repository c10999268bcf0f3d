#include "cairn/wls/fields.hpp"

#include <array>
#include <type_traits>

#include "cairn/transfer/transfer.hpp"

namespace cairn::wls {

template <int D>
Fields<D>::Fields(const Grid<D>& grid, const Options& options, int n_fields, Integrator<D>* first) {
  integrators_.push_back(first);
  for (int f = 1; f < n_fields; ++f) {
    owned_.push_back(std::make_unique<Integrator<D>>(grid, options));
    integrators_.push_back(owned_.back().get());
  }
  for (Integrator<D>* wls : integrators_) loads_.push_back(&wls->surface_loads());
  particles_.resize(static_cast<std::size_t>(n_fields));
  index_.resize(static_cast<std::size_t>(n_fields));
  body_.resize(static_cast<std::size_t>(n_fields));
  scratch_.resize(grid.n_nodes(), false);
}

template <int D>
void Fields<D>::split(const Particles<D>& particles, const std::vector<std::int32_t>& field_offset,
                      std::int32_t n_nodes, const std::vector<Vec<D>>* body_acceleration) {
  for (auto& idx : index_) idx.clear();
  for (std::size_t p = 0; p < particles.n(); ++p)
    index_[static_cast<std::size_t>(field_offset[p] / n_nodes)].push_back(static_cast<std::int32_t>(p));
  // Every per-particle array (Particles::for_each_array visits them in one fixed order), each
  // field's entries in storage order.
  std::array<const void*, Particles<D>::n_arrays> from{};
  int k = 0;
  particles.for_each_array([&](const auto& array, int) { from[static_cast<std::size_t>(k++)] = &array; });
  for (std::size_t f = 0; f < particles_.size(); ++f) {
    Particles<D>& sub = particles_[f];
    const std::vector<std::int32_t>& idx = index_[f];
    sub.n_state_per_particle = particles.n_state_per_particle;
    sub.has_affine = particles.has_affine;
    sub.has_temperature = particles.has_temperature;
    k = 0;
    sub.for_each_array([&](auto& array, int width) {
      using Array = std::remove_reference_t<decltype(array)>;
      const Array& source = *static_cast<const Array*>(from[static_cast<std::size_t>(k++)]);
      const auto w = static_cast<std::size_t>(width);
      array.resize(idx.size() * w);
      for (std::size_t q = 0; q < idx.size(); ++q)
        for (std::size_t c = 0; c < w; ++c) array[q * w + c] = source[static_cast<std::size_t>(idx[q]) * w + c];
    });
    body_[f].clear();
    if (body_acceleration)
      for (std::int32_t p : idx) body_[f].push_back((*body_acceleration)[static_cast<std::size_t>(p)]);
  }
}

template <int D>
void Fields<D>::collect(const Grid<D>& grid, const std::vector<double>& density0, bool body_force,
                        NodeField<D>& nodes, std::vector<Vec<D>>* node_body_force, bool surface_loads) {
  const std::int32_t nn = grid.n_nodes();
  if (body_force) scratch_body_.assign(static_cast<std::size_t>(nn), Vec<D>::Zero());
  for (int f = 0; f < n(); ++f) {
    const auto off = static_cast<std::size_t>(f) * static_cast<std::size_t>(nn);
    Integrator<D>& wls = integrator(f);
    const Particles<D>& sub = particles_[static_cast<std::size_t>(f)];
    wls.build_stencils(grid, sub);
    wls.collect(grid, sub, density0, body_force ? &body_[static_cast<std::size_t>(f)] : nullptr, scratch_,
                body_force ? &scratch_body_ : nullptr, surface_loads && !wls.surface_loads().centre.empty());
    for_each_node(nn, [&](std::int32_t i) {
      const std::size_t s = off + static_cast<std::size_t>(i);
      nodes.mass[s] = scratch_.mass[i];
      nodes.momentum[s] = scratch_.momentum[i];
      nodes.force[s] = scratch_.force[i];
      if (!nodes.reaction.empty()) nodes.reaction[s].setZero();
      if (node_body_force) (*node_body_force)[s] = body_force ? scratch_body_[i] : Vec<D>::Zero();
    });
  }
}

template <int D>
void Fields<D>::move_particles(const Grid<D>& grid, const NodeField<D>& nodes, Particles<D>& particles, double dt,
                               const std::vector<std::uint8_t>* held, const std::vector<Vec<D>>* impulse) {
  const std::int32_t nn = grid.n_nodes();
  gradient_.resize(particles.n());
  double grid_work = 0.0, transfer_energy = 0.0;  // this step's (method.energy_budget)
  for (int f = 0; f < n(); ++f) {
    load_slots(nodes, f, nn);
    if (impulse) {
      const auto first = impulse->begin() + static_cast<std::ptrdiff_t>(f) * nn;
      scratch_impulse_.assign(first, first + nn);
    }
    Particles<D>& sub = particles_[static_cast<std::size_t>(f)];
    Integrator<D>& wls = integrator(f);
    wls.restore_energy_budget(0.0, 0.0);
    wls.move_particles(grid, scratch_, sub, dt, held, impulse ? &scratch_impulse_ : nullptr);
    grid_work += wls.grid_work();
    transfer_energy += wls.transfer_energy();
    const std::vector<std::int32_t>& idx = index_[static_cast<std::size_t>(f)];
    for (std::size_t q = 0; q < idx.size(); ++q) {
      const auto p = static_cast<std::size_t>(idx[q]);
      particles.position[p] = sub.position[q];
      particles.velocity[p] = sub.velocity[q];
      gradient_[p] = wls.particle_velocity_gradient()[q];
    }
  }
  grid_work_ += grid_work;
  transfer_energy_ += transfer_energy;
}

template <int D>
Particles<D> region_points(const Fields<D>& fields) {
  Particles<D> out = region_points(fields.integrator(0));
  for (int f = 1; f < fields.n(); ++f) {
    const Particles<D> more = region_points(fields.integrator(f));
    for (std::size_t r = 0; r < more.n(); ++r)
      out.add(more.position[r], more.velocity[r], more.mass[r], more.volume0[r], more.size0[r], more.material[r],
              more.body[r]);
    const std::size_t first = out.n() - more.n();
    for (std::size_t r = 0; r < more.n(); ++r) out.kirchhoff_stress[first + r] = more.kirchhoff_stress[r];
  }
  return out;
}

template class Fields<1>;
template class Fields<2>;
template class Fields<3>;
template Particles<1> region_points<1>(const Fields<1>&);
template Particles<2> region_points<2>(const Fields<2>&);
template Particles<3> region_points<3>(const Fields<3>&);

}  // namespace cairn::wls
