#include "cairn/wls/step.hpp"

namespace cairn::wls {

template <int D>
void step(Integrator<D>& wls, EngineStages<D>& engine, const Grid<D>& grid, Particles<D>& particles,
          NodeField<D>& nodes, const std::vector<double>& density0, double dt) {
  wls.build_stencils(grid, particles);
  engine.lap(0);
  // Sec. 4.1-4.5: node mass, least-squares velocity (as m v) and forces.
  const std::vector<Vec<D>>* body = engine.body_accelerations();
  SurfaceLoads<D>* const one = &wls.surface_loads();
  const bool loads = engine.surface_loads(dt, {&one, 1});  // tractions at t + dt/2
  wls.collect(grid, particles, density0, body, nodes, body ? engine.node_body_forces() : nullptr, loads);
  engine.prepare_conditions(dt);
  engine.lap(1);
  engine.update_grid(dt);  // Eq. 25-26 with the conditions; half the first acceleration (Sec. 4.7)
  if (wls.options().filter_acceleration) {
    wls.filter_acceleration(grid, nodes);
    engine.impose_end_conditions();
  }
  if (wls.options().hourglass_damping > 0.0) {
    wls.damp_hourglass(grid, nodes);
    engine.impose_end_conditions();
  }
  if (wls.options().xpic_order > 0)  // particle_velocity = "xpic": the particles' start
    wls.xpic_projection(grid, nodes.mass, nodes.velocity);
  engine.lap(2);
  // Eq. 27-29 (or the quadrature gradient)
  engine.held_components(wls.held_components());
  wls.move_particles(grid, nodes, particles, dt, &wls.held_components());
  engine.lap(4);
  engine.update_materials(wls.particle_velocity_gradient(), dt);  // Eq. 30
  engine.lap(5);
}

template <int D>
void step_fields(Fields<D>& fields, EngineStages<D>& engine, const Grid<D>& grid, Particles<D>& particles,
                 const std::vector<std::int32_t>& field_offset, NodeField<D>& nodes,
                 const std::vector<double>& density0, double dt) {
  // Each field's particles on their own (Sec. 4.1-4.5 per field), into the field's slots.
  const std::vector<Vec<D>>* body = engine.body_accelerations();
  fields.split(particles, field_offset, grid.n_nodes(), body);
  engine.lap(0);
  const bool loaded = engine.surface_loads(dt, fields.surface_loads());  // each field's own faces
  fields.collect(grid, density0, body != nullptr, nodes, body ? engine.node_body_forces() : nullptr, loaded);
  engine.prepare_contact(dt);  // seed 004: contact nodes, normals, first correction
  engine.prepare_conditions(dt);
  engine.lap(1);
  engine.update_grid(dt);  // Eq. 25-26 per field, the second contact correction, the conditions
  // The options that act on the node velocities, each field's on its own (as in step above).
  const Options& o = fields.integrator(0).options();
  const std::int32_t nn = grid.n_nodes();
  if (o.filter_acceleration) {
    fields.for_each_field(nodes, nn, true,
                          [&](Integrator<D>& wls, NodeField<D>& f) { wls.filter_acceleration(grid, f); });
    engine.impose_end_conditions();
  }
  if (o.hourglass_damping > 0.0) {
    fields.for_each_field(nodes, nn, true,
                          [&](Integrator<D>& wls, NodeField<D>& f) { wls.damp_hourglass(grid, f); });
    engine.impose_end_conditions();
  }
  if (o.xpic_order > 0)  // particle_velocity = "xpic": each field's particles' start
    fields.for_each_field(nodes, nn, false,
                          [&](Integrator<D>& wls, NodeField<D>& f) { wls.xpic_projection(grid, f.mass, f.velocity); });
  engine.lap(2);
  // Eq. 27-29 per field with its own grid velocities.
  std::vector<std::uint8_t>& held = fields.integrator(0).held_components();
  engine.held_components(held);
  fields.move_particles(grid, nodes, particles, dt, &held, engine.contact_impulse());
  engine.lap(4);
  engine.update_materials(fields.particle_velocity_gradient(), dt);  // Eq. 30
  engine.lap(5);
}

template void step<1>(Integrator<1>&, EngineStages<1>&, const Grid<1>&, Particles<1>&, NodeField<1>&,
                      const std::vector<double>&, double);
template void step<2>(Integrator<2>&, EngineStages<2>&, const Grid<2>&, Particles<2>&, NodeField<2>&,
                      const std::vector<double>&, double);
template void step<3>(Integrator<3>&, EngineStages<3>&, const Grid<3>&, Particles<3>&, NodeField<3>&,
                      const std::vector<double>&, double);

template void step_fields<1>(Fields<1>&, EngineStages<1>&, const Grid<1>&, Particles<1>&,
                             const std::vector<std::int32_t>&, NodeField<1>&, const std::vector<double>&, double);
template void step_fields<2>(Fields<2>&, EngineStages<2>&, const Grid<2>&, Particles<2>&,
                             const std::vector<std::int32_t>&, NodeField<2>&, const std::vector<double>&, double);
template void step_fields<3>(Fields<3>&, EngineStages<3>&, const Grid<3>&, Particles<3>&,
                             const std::vector<std::int32_t>&, NodeField<3>&, const std::vector<double>&, double);

}  // namespace cairn::wls
