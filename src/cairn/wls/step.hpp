// One step of the WLS method of seed 001 Sec. 4 on an engine's grid, node fields and particles:
// the method's collection (Sec. 4.1-4.5) replaces the particle transfers and its particle move
// (Eq. 27-29) the scheme's; the grid update with its velocity conditions and the material update
// (Eq. 30) are the engine's, asked for through EngineStages (sim/ implements it, so that this
// folder stays below sim/).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/wls/fields.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn::wls {

/// What the WLS step asks of the engine that runs it.
template <int D>
class EngineStages {
 public:
  virtual ~EngineStages() = default;
  /// The body accelerations b_p of this step, computed now (null: no body force), and where the
  /// S^T M b part of the node forces goes.
  virtual const std::vector<Vec<D>>* body_accelerations() = 0;
  virtual std::vector<Vec<D>>* node_body_forces() = 0;
  /// Fill `loads` with the surface loads (tractions) at t + dt/2: one SurfaceLoads for all
  /// particles, or (step_fields) one per contact field, each with its field's faces; false: none.
  virtual bool surface_loads(double dt, std::span<SurfaceLoads<D>* const> loads) = 0;
  /// Multimaterial mode (step_fields): the contact nodes, normals and separations of this step
  /// from the collected fields and the first correction of their momenta (seed 004 Eq. 26);
  /// the second one comes with update_grid (Eq. 30-34).
  virtual void prepare_contact(double dt) = 0;
  /// The contact's first correction as an impulse on the particles (slots; null unless
  /// contact.first_correction = "impulse").
  virtual const std::vector<Vec<D>>* contact_impulse() = 0;
  /// The velocity conditions of this step, from the collected node masses.
  virtual void prepare_conditions(double dt) = 0;
  /// Eq. 25-26: v+ = v + a dt with the velocity conditions (half the first acceleration, Sec. 4.7).
  virtual void update_grid(double dt) = 0;
  /// The end-of-step velocity conditions on v+ again (after the filter changed it).
  virtual void impose_end_conditions() = 0;
  /// Into `held`, per node, bit a set where this step's velocity conditions set component a of
  /// v+ (a condition along a direction off the axes sets every component it has); empty: none.
  virtual void held_components(std::vector<std::uint8_t>& held) = 0;
  /// Eq. 30: F <- (I + L_p dt) F and the material stress of every particle from its velocity
  /// gradient L_p; a failing particle stops the step (SimulationFailure).
  virtual void update_materials(const std::vector<Eigen::Matrix<double, D, D>>& velocity_gradient, double dt) = 0;
  /// The end of a timed stage (0 stencils, 1 particles to grid, 2 grid update, 4 particle update,
  /// 5 stress update: Simulation::stage_times).
  virtual void lap(int stage) = 0;
};

/// One step of length dt; `density0` is each material's initial density (Eq. 19).
template <int D>
void step(Integrator<D>& wls, EngineStages<D>& engine, const Grid<D>& grid, Particles<D>& particles,
          NodeField<D>& nodes, const std::vector<double>& density0, double dt);

/// One step of length dt of WLS bodies in contact (wls/fields.hpp): every field's collection into
/// its slots of `nodes`, the engine's contact and grid update on the slots, every field's
/// particle move; each field spreads the tractions on its own faces, and the acceleration filter,
/// hourglass damping and XPIC act on each field's node values.
template <int D>
void step_fields(Fields<D>& fields, EngineStages<D>& engine, const Grid<D>& grid, Particles<D>& particles,
                 const std::vector<std::int32_t>& field_offset, NodeField<D>& nodes,
                 const std::vector<double>& density0, double dt);

}  // namespace cairn::wls
