// WLS bodies in contact (docs/wls.md, "Contact"): the multimaterial mode of seed 004 on the WLS
// method of seed 001. Each contact field (a material or a body, [contact] mode) is its own WLS
// body: its particles alone give its node fits, signed distance and cut cells (Sec. 3-4), hence
// its node mass, least-squares momentum and forces (Eq. 22-24), which go into the field's slots
// of the engine's node arrays (slot = field * n_nodes + node, contact/contact.hpp). The engine's
// contact corrects those fields as it corrects MPM's, and each field's particles then move with
// their own field's grid velocities (Eq. 27-29).
//
// Fields keeps one Integrator per field and, each step, a copy of each field's particles: the
// Integrator's passes then run unchanged on a field. The copies cost a pass over the particles'
// arrays per step; contact runs are small next to that.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn::wls {

template <int D>
class Fields {
 public:
  /// n_fields integrators with `options`; `first` (not null) is field 0's, owned by the caller
  /// (the engine's Simulation::wls(), which its outputs and diagnostics read).
  Fields(const Grid<D>& grid, const Options& options, int n_fields, Integrator<D>* first);

  [[nodiscard]] int n() const { return static_cast<int>(integrators_.size()); }
  [[nodiscard]] Integrator<D>& integrator(int f) { return *integrators_[static_cast<std::size_t>(f)]; }
  [[nodiscard]] const Integrator<D>& integrator(int f) const { return *integrators_[static_cast<std::size_t>(f)]; }
  /// Field f's particles, as of the last split (moved by the last step).
  [[nodiscard]] Particles<D>& particles(int f) { return particles_[static_cast<std::size_t>(f)]; }
  /// Field f's least-squares velocity at node i (Eq. 11) of the last collect: the engine's grid
  /// velocity at a slot without mass (seed 001 Sec. 4.6).
  [[nodiscard]] const Vec<D>& node_velocity(int f, std::int32_t i) const {
    return integrator(f).node_velocity()[static_cast<std::size_t>(i)];
  }

  /// Copy each field's particles into its own Particles, in the order they are stored, and the
  /// body accelerations with them (null: none). Particle p's field is field_offset[p] / n_nodes
  /// (the engine's slot offsets, contact/contact.hpp).
  void split(const Particles<D>& particles, const std::vector<std::int32_t>& field_offset, std::int32_t n_nodes,
             const std::vector<Vec<D>>* body_acceleration);
  /// Sec. 4.1-4.5 for every field: build its stencils, collect its node mass, momentum and
  /// force into its slots of `nodes` (sized n() * n_nodes) and, when given, the external part of
  /// the force into its slots of `node_body_force`. With `surface_loads`, each field's integrator
  /// spreads the loads its Integrator::surface_loads() holds (its own faces).
  void collect(const Grid<D>& grid, const std::vector<double>& density0, bool body_force, NodeField<D>& nodes,
               std::vector<Vec<D>>* node_body_force, bool surface_loads = false);
  /// Eq. 27-29 for every field from its slots of nodes.velocity and nodes.velocity_new; the
  /// moved positions and velocities go back into `particles` and each particle's velocity
  /// gradient into particle_velocity_gradient(). `held` as for Integrator::move_particles;
  /// `impulse` (slots, or null) the contact's first correction as an impulse on the particles.
  void move_particles(const Grid<D>& grid, const NodeField<D>& nodes, Particles<D>& particles, double dt,
                      const std::vector<std::uint8_t>* held, const std::vector<Vec<D>>* impulse = nullptr);
  /// fn(integrator, node field) for every field, with the field's slots of nodes.mass,
  /// velocity and velocity_new in the node field; `write` copies its velocity_new back into the
  /// slots (the acceleration filter, hourglass damping), otherwise fn only reads (XPIC).
  template <class Fn>
  void for_each_field(NodeField<D>& nodes, std::int32_t n_nodes, bool write, Fn&& fn) {
    for (int f = 0; f < n(); ++f) {
      load_slots(nodes, f, n_nodes);
      fn(integrator(f), scratch_);
      if (write) {
        const auto off = static_cast<std::size_t>(f) * static_cast<std::size_t>(n_nodes);
        std::copy(scratch_.velocity_new.begin(), scratch_.velocity_new.end(), nodes.velocity_new.begin() + off);
      }
    }
  }
  /// Every field's Integrator::surface_loads(), in field order (for EngineStages::surface_loads).
  [[nodiscard]] const std::vector<SurfaceLoads<D>*>& surface_loads() const { return loads_; }
  /// The energy budget's sums (Integrator::grid_work, transfer_energy) over the fields and the
  /// steps: each step adds every field's sums of that step, so that the totals are the only
  /// state and a restart continues them bit for bit.
  [[nodiscard]] double grid_work() const { return grid_work_; }
  [[nodiscard]] double transfer_energy() const { return transfer_energy_; }
  /// Both sums from a checkpoint.
  void restore_energy_budget(double grid_work, double transfer_energy) {
    grid_work_ = grid_work;
    transfer_energy_ = transfer_energy;
  }
  /// grad V_p of every particle (the whole set's order) from the last move_particles.
  [[nodiscard]] const std::vector<Eigen::Matrix<double, D, D>>& particle_velocity_gradient() const {
    return gradient_;
  }

 private:
  /// Field f's slots of nodes.mass, velocity and velocity_new into scratch_.
  void load_slots(const NodeField<D>& nodes, int f, std::int32_t n_nodes) {
    const auto off = static_cast<std::ptrdiff_t>(f) * n_nodes;
    std::copy_n(nodes.mass.begin() + off, n_nodes, scratch_.mass.begin());
    std::copy_n(nodes.velocity.begin() + off, n_nodes, scratch_.velocity.begin());
    std::copy_n(nodes.velocity_new.begin() + off, n_nodes, scratch_.velocity_new.begin());
  }

  std::vector<std::unique_ptr<Integrator<D>>> owned_;  ///< the integrators of fields 1..n-1
  std::vector<Integrator<D>*> integrators_;
  std::vector<SurfaceLoads<D>*> loads_;                 ///< surface_loads()
  std::vector<Particles<D>> particles_;                 ///< per field: a copy of its particles
  std::vector<std::vector<std::int32_t>> index_;        ///< per field: their indices in the whole set
  std::vector<std::vector<Vec<D>>> body_;               ///< per field: their body accelerations
  NodeField<D> scratch_;                                ///< one field's node values
  std::vector<Vec<D>> scratch_body_;
  std::vector<Vec<D>> scratch_impulse_;
  std::vector<Eigen::Matrix<double, D, D>> gradient_;
  double grid_work_ = 0.0, transfer_energy_ = 0.0;
};

/// The integration regions of every field as points for a snapshot (region_points, fields one
/// after the other).
template <int D>
Particles<D> region_points(const Fields<D>& fields);

}  // namespace cairn::wls
