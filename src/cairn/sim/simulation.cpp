// Simulation<D>: set-up (grid, materials, particles, contact, WLS), the state and its totals.
// The step lives in step.cpp, full_mass.cpp and particle_update.cpp.
#include "cairn/sim/simulation.hpp"

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
#include "cairn/sim/simulation_detail.hpp"
#include "cairn/sim/stress_timing.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/wls/fields.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn {

template <int D>
Simulation<D>::Simulation(const Config& config, const Comm& comm) : config_(config), mode_(config.simulation.mode) {
  if (config_.simulation.threads > 0) omp_set_num_threads(config_.simulation.threads);
  for (const auto& mc : config_.materials) materials_.push_back(make_material(mc));
  for (const auto& m : materials_) {
    // The plane-stress solve calls the model several times per step (materials/plane_stress.hpp),
    // which would count a viscous stress's work more than once.
    if (mode_ == Mode::plane_stress && m->damping_time() > 0.0)
      throw std::invalid_argument("material '" + m->name() + "': damping_time is not available in plane stress "
                                  "(simulation.mode = \"plane_stress\"); use plane strain or 3D");
    damping_time_.push_back(m->damping_time());
  }
  // WLS bodies in contact: the contact's point clouds are the particles whose narrow shape S
  // (seed 001 Eq. 5, the linear hat) reaches the node, whatever method.shape (unused by WLS).
  MethodConfig shape_method = config_.method;
  if (config_.method.integration == "wls" && config_.contact.enabled()) shape_method.shape = "linear";
  ShapeContext ctx{shape_method, D};
  shape_ = make_shape_family<D>(ctx);
  scheme_ = SchemeRegistry<D>::instance().create("update scheme", config_.method.update, config_.method);
  flip_ = SchemeRegistry<D>::instance().create("update scheme", "flip", config_.method);
  timing_ = &stress_timing(config_.method.stress_update);
  setup_grid();
  int n_state = 0;
  for (const auto& m : materials_) n_state = std::max(n_state, m->n_state());
  particles_.n_state_per_particle = n_state;
  particles_.has_affine = scheme_->affine();
  particles_.has_temperature = config_.thermal.conduction;
  for (const auto& m : materials_) particles_.has_temperature |= m->uses_temperature();
  check_memory<D>(config_, grid_, velocity_fields(config_), n_state, shape_->ghost_layers() + 1, comm.size());
  if (comm.parallel()) {
    // Per-rank generation (docs/parallel.md): the ranks walk the bodies' particles twice. The
    // first time (the census) rank r runs the inside tests of the r-th block of lattice rows of
    // each lattice body (of the r-th block of the candidates of any other body) and records the
    // cells of its particles: the histograms, summed over the ranks, are those of all particles.
    // The domain is bisected by them, and the second time each rank tests and stores only the
    // lattice points of its own box, and its block of the other bodies' particles, which then
    // move to their owners. With parallel.balance = "cost" each census entry weighs what a
    // particle of its body's material costs.
    distribution_ = Distribution<D>(comm, whole_);
    distribution_.set_material_weights(material_weights());
    std::vector<std::int64_t> body_weight;
    for (const BodyConfig& body : config_.bodies) {
      std::int64_t w = 1;  // (a body naming no material is refused by create_particles)
      for (std::size_t m = 0; m < config_.materials.size(); ++m)
        if (config_.materials[m].name == body.material) w = distribution_.weight_of(static_cast<std::int32_t>(m));
      body_weight.push_back(w);
    }
    const bool weighed = config_.parallel.balance == "cost";
    std::vector<IVec<D>> census;
    std::vector<std::int64_t> census_weight;
    const ParticleSelection<D> count = [&](std::int64_t, std::int32_t body, const Vec<D>&, const Vec<D>& x, bool) {
      census.push_back(distribution_.cell_of(x));
      if (weighed) census_weight.push_back(body_weight[static_cast<std::size_t>(body)]);
      return false;
    };
    const GenerationShare<D> rows{&comm, nullptr};
    create_particles<D>(config_, grid_, materials_, mode_, particles_, &count, &rows);
    distribution_.partition_cells(census, census_weight);
    std::vector<IVec<D>>().swap(census);
    std::vector<std::int64_t>().swap(census_weight);
    const ParticleSelection<D> mine = [&](std::int64_t, std::int32_t, const Vec<D>&, const Vec<D>& x,
                                          bool in_share) { return in_share || distribution_.owner_of(x) == comm.rank(); };
    const GenerationShare<D> own{&comm, &distribution_.decomposition()};
    create_particles<D>(config_, grid_, materials_, mode_, particles_, &mine, &own);
    distribution_.place(particles_);  // (a share of a body off the lattice to the owners)
  } else {
    create_particles<D>(config_, grid_, materials_, mode_, particles_);
  }
  particles_.shrink_to_fit();
  for (const auto& m : materials_) {
    material_density_.push_back(m->density());
    wave_speed_varies_.push_back(m->wave_speed_varies() ? 1 : 0);
  }
  material_in_use_.assign(materials_.size(), 0);
  for (std::int32_t m : particles_.material) material_in_use_[m] = 1;
  if (comm.parallel()) {
    std::vector<std::int64_t> in_use(material_in_use_.begin(), material_in_use_.end());
    comm.max(in_use.data(), static_cast<int>(in_use.size()));
    for (std::size_t m = 0; m < in_use.size(); ++m) material_in_use_[m] = static_cast<char>(in_use[m]);
  }
  if (config_.thermal.conduction) {  // on the whole grid here; windows in allocate_nodes
    std::vector<double> k, cp;
    for (const auto& mc : config_.materials) {
      k.push_back(mc.has("conductivity") ? mc.number("conductivity") : 0.0);
      cp.push_back(mc.has("heat_capacity") ? mc.number("heat_capacity") : 0.0);
    }
    conduction_ = std::make_unique<Conduction<D>>(config_.thermal, grid_, k, cp,
                                                  config_.simulation.thickness);
    // Grid heat conduction over the step's stencils (docs/thermal.md), after the mechanics.
    on(StepPoint::end_of_step, [this](double dt) {
      refresh_ghosts(particles_.temperature, particles_.has_temperature ? 1 : 0);
      std::function<void(std::vector<Vec<D>>&)> share_flux;
      std::function<void(std::vector<double>&, std::vector<double>*)> sum_nodes;
      if (distributed() && !node_halo_) share_flux = [this](std::vector<Vec<D>>& flux) { refresh_ghosts(flux); };
      if (node_halo_)
        sum_nodes = [this](std::vector<double>& a, std::vector<double>* b) {
          if (b) halo_.sum(1, a, *b);
          else halo_.sum(1, a);
        };
      conduction_->step(cache_, particles_, dt, share_flux, sum_nodes);
    });
  }
  double max_mass = 0.0;
  for (double m : particles_.mass) max_mass = std::max(max_mass, m);
  max_mass = comm.max(max_mass);
  small_mass_ = 1e-15 * max_mass;  // nodes below this hold no velocity
  if (config_.contact.enabled()) {
    // Multimaterial mode: one field per material or body, side by side (contact/contact.hpp).
    contact_ = std::make_unique<Contact<D>>(config_, grid_, particles_, small_mass_);
    n_fields_ = contact_->n_fields();
    // The first correction's contact change reaches the particle velocities as an impulse
    // (first_correction = "impulse"); otherwise only the second correction's does (the particle
    // update takes v+ - v, or v+ whose change the dissipation tally of the update already sees).
    contact_->count_first_correction(contact_->impulse() && contact_->corrects_extrapolation());
    contact_->set_start_velocity(&nodes_.velocity);
    on(StepPoint::after_momentum, [this](double dt) {
      // Contact nodes, normals and separations of this step, then the first correction
      // p^a = p^a0 + dp^a kept as dv^a (seed 004 Eq. 26).
      contact_->prepare(particles_, cache_, nodes_.mass);
      // dv^a is zero wherever this step's first correction does not set it (nodes that were
      // contact nodes last step included).
      for_each_node(n_slots(), [&](std::int32_t i) {
        contact_dv_[i].setZero();
        contact_impulse_[i].setZero();
      });
      if (contact_->corrects_extrapolation())
        contact_->correct(nodes_.mass, nodes_.momentum, true, Contact<D>::Pass::extrapolated, time_, dt,
                          &contact_dv_, contact_->impulse() ? &contact_impulse_ : nullptr);
      const std::int32_t nn = grid_.n_nodes();
      for_each_node(nn, [&](std::int32_t i) {
        double m = 0.0;
        Vec<D> q = Vec<D>::Zero();
        for (int f = 0; f < n_fields_; ++f) {
          m += nodes_.mass[f * nn + i];
          q += nodes_.momentum[f * nn + i];
        }
        totals_.mass[i] = m;
        totals_.momentum[i] = q;
      });
    });
    on(StepPoint::before_conditions, [this](double dt) {
      // Second correction, on the updated momenta: dp^a+ / dt is the contact force and the
      // acceleration is (v^a+ - v^a) / dt with the corrected v^a (seed 004 Eq. 30-34).
      contact_->correct(nodes_.mass, nodes_.velocity_new, false, Contact<D>::Pass::updated, time_, dt, nullptr);
      contact_->reduce(distribution_.comm());
    });
    if (contact_->xpic_correction())
      on(StepPoint::after_full_mass, [this](double) {
        // Multimaterial XPIC/FMPM: the dv term of seed 004 Eq. 37 comes after the conditions
        // that full_mass_velocity imposed: impose them again, so that a held node that is also
        // a contact node keeps its condition.
        subtract_contact_term(nodes_.velocity_full, config_.method.order);
        if (config_.method.velocity_bc_method != "lumped")
          impose_conditions(nodes_.velocity_full, scheme_->full_mass() == FullMass::of_updated
                                                      ? VelocityConditions<D>::When::end
                                                      : VelocityConditions<D>::When::start);
      });
  }
  // Scratch node arrays only where the step uses them: full-mass expansions (FMPM, XPIC and
  // their blends) and the second stress-update velocity of USF/USAVG/USL+/USAVG+.
  node_scratch_ = scheme_->full_mass() != FullMass::none || timing_->before_forces > 0.0 || timing_->after_update > 0.0;
  // Conditions and tractions select their nodes and faces on the whole grid and every particle
  // (the faces gathered from every rank), so that a selection holding none is refused the same
  // way on any number of ranks.
  conditions_ = GridConditions<D>(config_.boundary, grid_, shape_->face_basis());
  velocity_conditions_ = VelocityConditions<D>(config_, grid_, conditions_);
  if (comm.parallel() && !config_.tractions.empty()) {
    // A face is exposed when its body has no particle in the lattice site across it, which may
    // belong to another rank: a third walk over the bodies records which of those sites hold a
    // particle. The sites across this rank's faces lie within a cell of its box, so of a lattice
    // body the walk tests only the points in the box widened by one cell.
    std::vector<std::unordered_set<std::int64_t>> across(config_.bodies.size()), occupied(config_.bodies.size());
    for (std::size_t p = 0; p < particles_.n(); ++p)
      for (int a = 0; a < D; ++a)
        for (int sign = -1; sign <= 1; sign += 2)
          across[particles_.body[p]].insert(Tractions<D>::lattice_site(particles_.reference_position[p],
                                                                      grid_.origin(), particles_.size0[p], a, sign));
    const ParticleSelection<D> sites = [&](std::int64_t, std::int32_t body, const Vec<D>& X, const Vec<D>&, bool) {
      const auto b = static_cast<std::size_t>(body);
      IVec<D> ppc;
      for (int a = 0; a < D; ++a) ppc[a] = config_.bodies[b].particles_per_cell[a];
      const std::int64_t key =
          Tractions<D>::lattice_site(X, grid_.origin(), grid_.cell_size().cwiseQuotient(ppc.template cast<double>()));
      if (across[b].count(key)) occupied[b].insert(key);
      return false;
    };
    Particles<D> none;
    none.n_state_per_particle = particles_.n_state_per_particle;
    const GenerationShare<D> near{&comm, &distribution_.decomposition(), 1};
    create_particles<D>(config_, grid_, materials_, mode_, none, &sites, &near);
    tractions_ = Tractions<D>(config_, grid_, particles_, shape_->particle_domain(), occupied, comm);
  } else {
    // WLS: the faces are convected by F, as the cut cells follow the deformed body.
    tractions_ = Tractions<D>(config_, grid_, particles_,
                              config_.method.integration == "wls" ? ParticleDomain::convected
                                                                  : shape_->particle_domain());
  }
  if (!config_.tractions.empty())
    on(StepPoint::after_forces, [this](double dt) {
      // Tractions on particle faces join the grid forces (seed 000 Sec. 2.4, first equation).
      collectively([&] {
        tractions_.add_forces(grid_, particles_, *shape_, time_ + 0.5 * dt, nodes_.force,
                              contact_ ? &field_offset_ : nullptr);
      });
    });

  if (config_.method.integration == "wls") {
    // The WLS method (seed 001) replaces the particle transfers; features that act through
    // them are not defined for it (docs/wls.md says why for each).
    const char* unsupported = D == 1                          ? "a 1D simulation"
                              : config_.thermal.conduction    ? "[thermal] conduction"
                                                              : nullptr;
    if (unsupported)
      throw std::invalid_argument(std::string("method.integration = \"wls\" does not support ") + unsupported +
                                  " (docs/wls.md)");
    // Tractions load the faces of lattice particles (bc/traction.hpp); the rings of the radial
    // arrangement have none.
    for (const auto& tc : config_.tractions)
      for (const auto& b : config_.bodies)
        if ((tc.body.empty() || tc.body == b.name) && b.arrangement == "radial")
          throw std::invalid_argument(tc.where.str() + ": traction '" + tc.name + "' loads body '" + b.name +
                                      "', whose arrangement is \"radial\": tractions load the faces of lattice "
                                      "particles (arrangement = \"cartesian\"; docs/wls.md)");
    // Periodic axes wrap the stencils, fits, neighbour averages and cut cells; the 3 nodes of a
    // stencil along the axis must be distinct nodes.
    for (int a = 0; a < D; ++a)
      if (grid_.periodic(a) && grid_.n_cells()[a] < 3)
        throw std::invalid_argument(std::string("method.integration = \"wls\" needs at least 3 cells along the "
                                                "periodic ") +
                                    "xyz"[a] + " axis (its stencils span 3 nodes; docs/wls.md)");
    wls::Options o = wls::options(config_.method);
    // With Eq. 29 as printed a held bar under a traction grows node-scale noise until det F < 0
    // (docs/wls.md, "Tractions"); the quadrature gradient and its transpose reach the static stress.
    if (!config_.tractions.empty() && !o.quadrature_gradient && !o.transpose_gradient)
      throw std::invalid_argument(config_.tractions.front().where.str() + ": [[traction]] under method.integration = "
                                  "\"wls\" needs method.velocity_gradient = \"quadrature\" (the default) or "
                                  "\"transpose\": with \"narrow\" (Eq. 29 as printed) a loaded body grows node-scale "
                                  "noise (docs/wls.md)");
    if (o.adjoint_point_stress && !o.quadrature_gradient)
      throw std::invalid_argument("method.point_values = \"adjoint\" needs method.velocity_gradient = "
                                  "\"quadrature\" (the default): it is that gradient's transpose (docs/wls.md)");
    // Every symmetry face is a mirror plane of the body (method.mirror_planes = "all", the
    // default: a body landing on a frictionless wall meets its mirror image there); with
    // "reached" only a face the body reaches at the start (a particle within half a cell), the
    // others being held like any grid face (docs/wls.md, departure 14).
    for (int f = 0; f < 2 * D; ++f) {
      if (config_.boundary.face[f] != FaceCondition::symmetry) continue;
      o.mirror[f] = o.every_symmetry_face_mirrors;
      const int a = f / 2;
      const double plane = f % 2 ? grid_.extent_max()[a] : grid_.origin()[a];
      for (std::size_t p = 0; p < particles_.n() && !o.mirror[f]; ++p)
        o.mirror[f] = std::abs(particles_.position[p][a] - plane) < 0.5 * grid_.cell_size()[a];
    }
    o.thickness = config_.simulation.thickness;
    wls_ = std::make_unique<wls::Integrator<D>>(grid_, o);
    if (contact_) wls_fields_ = std::make_unique<wls::Fields<D>>(grid_, o, contact_->n_fields(), wls_.get());
  }

  if (!config_.body_force.expression.empty()) {
    const int n_threads = omp_get_max_threads();
    for (int t = 0; t < n_threads; ++t)
      body_force_.push_back(std::make_unique<ExpressionVector<D>>(config_.body_force.expression,
                                                                  config_.constants));
    body_force_constant_ = body_force_[0]->is_constant();
    if (body_force_constant_) body_force_value_ = (*body_force_[0])(Vec<D>::Zero(), Vec<D>::Zero(), 0.0);
  }
  check_run_length<D>(*this);
  if (comm.parallel()) {
    // Each rank keeps the particles of its box (generated there, above) and a window of the
    // grid (docs/parallel.md).
    velocity_conditions_.set_comm(comm);
    reach_ = std::max(1, shape_->ghost_layers());
    node_halo_ = config_.parallel.halo != "particles";
    if (node_halo_ && contact_) contact_->use_halo(&halo_);  // (its point clouds and node arrays)
    distribution_.keep_storage_order(node_halo_);  // (sorted by cell block as a serial run's)
    grid_ = node_halo_ ? node_window() : distribution_.window(whole_, reach_);
  }
  keep_particles_sorted(true);
  allocate_nodes();
  if (wls_) {
    // The initial node fields and integration regions, so that output at t = 0 shows them.
    compute_body_forces();
    const std::vector<Vec<D>>* body = body_force_.empty() ? nullptr : &body_acceleration_;
    if (wls_fields_) {
      wls_fields_->split(particles_, field_offset_, grid_.n_nodes(), body);
      wls_fields_->collect(grid_, material_density_, body != nullptr, nodes_, body ? &node_body_force_ : nullptr);
    } else {
      wls_->build_stencils(grid_, particles_);
      wls_->collect(grid_, particles_, material_density_, body, nodes_, body ? &node_body_force_ : nullptr);
    }
  }
}

template <int D>
std::vector<std::int64_t> Simulation<D>::material_weights() const {
  if (config_.parallel.balance != "cost") return {};
  std::vector<std::int64_t> weights;
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    const MaterialConfig& mc = config_.materials[m];
    const double given = mc.has("balance_cost") ? mc.number("balance_cost") : 0.0;
    const double cost = given > 0.0 ? given : materials_[m]->relative_cost();
    weights.push_back(std::max<std::int64_t>(1, std::llround(1000.0 * cost)));
  }
  return weights;
}

template <int D>
void Simulation<D>::allocate_nodes() {
  nodes_.resize(n_slots(), node_scratch_);
  if (node_scratch_) {
    grid_term_.assign(n_slots(), Vec<D>::Zero());
    grid_proj_.assign(n_slots(), Vec<D>::Zero());
  }
  if (contact_) {
    contact_->grid_changed();
    contact_dv_.assign(n_slots(), Vec<D>::Zero());
    contact_impulse_.assign(n_slots(), Vec<D>::Zero());
    totals_.mass.assign(grid_.n_nodes(), 0.0);
    totals_.momentum.assign(grid_.n_nodes(), Vec<D>::Zero());
    compute_field_offsets();
  }
  if (!grid_.is_whole()) {
    conditions_ = GridConditions<D>(config_.boundary, grid_, shape_->face_basis());
    VelocityConditions<D> window_conditions(config_, grid_, conditions_, false);
    window_conditions.take_state(std::move(velocity_conditions_));
    velocity_conditions_ = std::move(window_conditions);
  }
  if (conditions_.empty() && velocity_conditions_.empty())
    std::vector<Vec<D>>().swap(nodes_.reaction);  // nothing records reactions
  if (conduction_) conduction_->grid_changed();
  if (!body_force_.empty()) node_body_force_.assign(n_slots(), Vec<D>::Zero());
}

template <int D>
void Simulation<D>::set_window(const Grid<D>& window) {
  bool same = window.n_nodes() == grid_.n_nodes();
  for (int a = 0; a < D && same; ++a)
    same = window.first_node(a) == grid_.first_node(a) && window.stored_nodes(a) == grid_.stored_nodes(a) &&
           window.own_lo()[a] == grid_.own_lo()[a] && window.own_hi()[a] == grid_.own_hi()[a];
  if (same) return;
  grid_ = window;
  allocate_nodes();
}

template <int D>
SimulationFailure Simulation<D>::named_by_id(const SimulationFailure& f) const {
  // Name the particle by its id, the number a serial run in creation order gives it (-1: no
  // particle of this rank).
  const std::int64_t p = f.particle();
  const std::int64_t id =
      p >= 0 && static_cast<std::size_t>(p) < particles_.id.size() ? particles_.id[static_cast<std::size_t>(p)] : -1;
  std::string message = f.what();
  if (p >= 0) {
    const std::string local = "particle " + std::to_string(p);
    if (const auto at = message.find(local); at != std::string::npos)
      message.replace(at, local.size(), "particle " + std::to_string(id));
  }
  return {id, f.quantity(), message};
}

template <int D>
double Simulation<D>::wls_grid_work() const {
  return wls_fields_ ? wls_fields_->grid_work() : wls_ ? wls_->grid_work() : 0.0;
}

template <int D>
double Simulation<D>::wls_transfer_energy() const {
  return wls_fields_ ? wls_fields_->transfer_energy() : wls_ ? wls_->transfer_energy() : 0.0;
}

template <int D>
void Simulation<D>::restore_wls_energy_budget(double grid_work, double transfer_energy) {
  if (wls_fields_) wls_fields_->restore_energy_budget(grid_work, transfer_energy);
  else if (wls_) wls_->restore_energy_budget(grid_work, transfer_energy);
}

template <int D>
void Simulation<D>::compute_field_offsets() {
  if (!contact_) return;
  field_offset_.resize(particles_.n());
  for (std::size_t p = 0; p < particles_.n(); ++p) field_offset_[p] = contact_->field_of(particles_, p) * grid_.n_nodes();
}

template <int D>
void Simulation<D>::keep_particles_sorted(bool setup) {
  // Particle order (docs/architecture.md): a serial run keeps its particles in memory in the
  // colouring's block order, within a block in id order. Every scatter adds a block's particles
  // in id order whatever their storage order (transfer/colouring.cpp), and every other particle
  // stage works particle by particle or sums exactly, so the results do not change by a bit.
  const std::size_t n = particles_.n();
  // (WLS bodies in contact keep their order: each field's integrator colours a copy of its
  // particles, wls/fields.hpp.)
  if (!config_.simulation.sort_particles || (distributed() && !node_halo_) || wls_fields_ ||
      n < (wls_ ? sort_min_particles_wls : sort_min_particles) || particles_.id.size() != n)
    return;
  // A WLS run colours its particles in the integrator's own cache (wls/integrator.cpp).
  TransferCache<D>& blocks = wls_ && !setup ? wls_->transfer_cache() : cache_;
  if (setup) {
    // No stencils yet: colour blocks of the preferred width (reach 0) in the cache's colouring
    // arrays (given back below).
    cache_.n = cache_.n_owned = n;
    cache_.block_of.assign(n, 0);
    cache_.order.assign(n, 0);
    cache_.reach_lo.setZero();
    cache_.reach_hi.setZero();
    cache_.colouring_valid = false;
    colour_blocks(grid_, particles_, cache_);
    cache_.colouring_valid = false;  // the stencils' reach may ask for wider blocks
  } else if (!blocks.colouring_valid || blocks.order.size() != n) {
    return;
  }
  // Runs of consecutive storage indices in the colouring's order: sorted, a block is one run
  // (and a particle that changed block since splits one).
  const std::vector<std::int32_t>& order = blocks.order;
  std::size_t breaks = 0;
  for (std::size_t k = 1; k < n; ++k) breaks += static_cast<std::size_t>(order[k] != order[k - 1] + 1);
  if (breaks * sort_run >= n) {
    permute_particles(particles_, order);  // the particle stored at k was at order[k]
    tractions_.renumber(order);
    cache_.sorted_storage = true;    // the colouring sorts each block by id (transfer/colouring.cpp)
    cache_.colouring_valid = false;  // block_of and order index the old storage
    if (wls_) {
      wls_->transfer_cache().sorted_storage = true;
      wls_->transfer_cache().colouring_valid = false;
    }
    compute_field_offsets();
    ++particle_sorts_;
  }
  if (setup) {
    // Give the set-up colouring back: allocated now, between the set-up's other arrays, it left
    // the heap laid out so that the first step's stencil arrays raised the peak by about 4 bytes
    // per particle (bench/memory_per_particle.py); the first build allocates them as it would.
    std::vector<std::int32_t>().swap(cache_.block_of);
    std::vector<std::int32_t>().swap(cache_.order);
    cache_.n = cache_.n_owned = 0;
  }
}

template <int D>
std::int64_t Simulation<D>::total_particles() const {
  return distribution_.comm().sum(static_cast<std::int64_t>(n_owned()));
}

template <int D>
void Simulation<D>::set_particles(Particles<D> particles) {
  // Set-up particles that were sorted (keep_particles_sorted): where each was, by id, for the
  // tractions' faces, which go back to id order (the storage order of `particles` below).
  const std::vector<std::int32_t> old_by_id = output_order();
  // The models write n_state() doubles per particle: a checkpoint of another layout (an older
  // Cairn, before mie_gruneisen kept its plastic strain rate) would let them write past it.
  if (particles.n_state_per_particle != particles_.n_state_per_particle)
    throw std::invalid_argument("the checkpoint stores " + std::to_string(particles.n_state_per_particle) +
                                " material state variables per particle, this Cairn's materials keep " +
                                std::to_string(particles_.n_state_per_particle) +
                                " (a checkpoint of another version): start the run again with cairn run");
  particles_ = std::move(particles);
  if (distributed()) {
    distribution_.partition(particles_);
  } else if (!std::is_sorted(particles_.id.begin(), particles_.id.end())) {
    // A checkpoint of a distributed run lists particles rank after rank: back to id order.
    std::vector<std::int32_t> order(particles_.n());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::int32_t a, std::int32_t b) { return particles_.id[a] < particles_.id[b]; });
    reorder_particles(particles_, order);
  }
  if (!old_by_id.empty()) {
    if (old_by_id.size() == particles_.n()) tractions_.renumber(old_by_id);
    cache_.sorted_storage = false;
    cache_.colouring_valid = false;
    if (wls_) {
      wls_->transfer_cache().sorted_storage = false;
      wls_->transfer_cache().colouring_valid = false;
    }
  }
  keep_particles_sorted(true);
  compute_field_offsets();
}

template <int D>
double Simulation<D>::contact_dissipated_energy() const {
  return contact_ ? contact_->dissipated() : 0.0;
}

template <int D>
double Simulation<D>::material_dissipated_energy() const {
  if (std::none_of(damping_time_.begin(), damping_time_.end(), [](double b) { return b > 0.0; })) return 0.0;
  // Exact sums over the owned particles and the ranks, like totals().
  const auto& P = particles_;
  const auto n = static_cast<std::int64_t>(n_owned());
  std::array<ExactSum, 1> sum = exact_sums<1>(n, [&](std::int64_t p, std::array<double, 1>& v) {
    const double* state = P.n_state_per_particle ? &P.state[p * static_cast<std::size_t>(P.n_state_per_particle)] : nullptr;
    v[0] = P.volume0[p] * materials_[P.material[p]]->dissipated_energy_density(state);
  });
  sum_across(distribution_.comm(), sum.data(), 1);
  return sum[0].value();
}

template <int D>
void Simulation<D>::restore_counters(double time, long long step, double external_work, double update_dissipated,
                                     double contact_dissipated, double next_full_mass_time) {
  time_ = time;
  step_ = step;
  external_work_ = external_work;
  dissipated_energy_ = update_dissipated;
  if (contact_) contact_->set_dissipated(contact_dissipated);
  next_full_mass_time_ = next_full_mass_time;
}

template <int D>
std::vector<std::string> Simulation<D>::take_notes() {
  std::vector<std::string> notes = velocity_conditions_.take_notes();
  for (const auto& m : materials_)
    for (auto& note : m->take_notes()) notes.push_back(std::move(note));
  if (!distributed()) return notes;
  const Comm& comm = distribution_.comm();
  if (!comm.any(!notes.empty())) return {};
  // Rank 0 prints: every rank sends its notes there; a conflict seen by several ranks (or at
  // several nodes) is said once, by the pair of conditions it names.
  Comm::Buffers send(static_cast<std::size_t>(comm.size()));
  for (const auto& note : notes) {
    send[0].insert(send[0].end(), note.begin(), note.end());
    send[0].push_back('\0');
  }
  const Comm::Buffers recv = comm.all_to_all(send);
  std::vector<std::string> out;
  if (!comm.is_root()) return out;
  for (const auto& buffer : recv) {
    std::string text;
    for (char c : buffer) {
      if (c != '\0') {
        text.push_back(c);
        continue;
      }
      const std::string pair = text.substr(0, text.find(" both set"));
      if (reported_pairs_.insert(pair).second) out.push_back(text);
      text.clear();
    }
  }
  return out;
}

template <int D>
Simulation<D>::~Simulation() = default;

template <int D>
void Simulation<D>::setup_grid() {
  const auto& g = config_.grid;
  Vec<D> origin, h;
  IVec<D> n_cells;
  std::array<bool, D> periodic{};
  std::vector<long long> cells(D);
  std::vector<bool> wraps(D);
  for (int a = 0; a < D; ++a) {
    origin[a] = g.origin[a];
    h[a] = g.cell_size[a];
    cells[a] = std::llround(g.extent[a] / g.cell_size[a]);
    periodic[a] = wraps[a] = config_.boundary.face[2 * a] == FaceCondition::periodic;
  }
  // WLS's wide weight reaches one node beyond a particle's nearest node.
  const int ghost = std::max(shape_->ghost_layers(), config_.method.integration == "wls" ? 1 : 0);
  check_node_count(config_, cells, wraps, ghost, velocity_fields(config_));
  for (int a = 0; a < D; ++a) n_cells[a] = static_cast<int>(cells[a]);
  grid_ = Grid<D>(origin, n_cells, h, ghost, periodic);
  whole_ = grid_;
}

template <int D>
double Simulation<D>::max_signal_speed() const {
  // Materials whose wave speed does not depend on F are asked once (if they have particles);
  // max |V| is sqrt(max |V|^2), the same number. Maxima over the owned particles, then over the
  // ranks (order-independent).
  const auto n = static_cast<std::int64_t>(n_owned());
  const auto n_materials = static_cast<std::int32_t>(materials_.size());
  double c_max = 0.0;
  const char* varies = wave_speed_varies_.data();  // set up once, not per step
  const double* beta = damping_time_.data();
  const double h = grid_.min_cell_size();
  for (std::int32_t m = 0; m < n_materials; ++m)
    if (!varies[m] && material_in_use_[m])
      c_max = std::max(c_max, damped_signal_speed(materials_[m]->wave_speed(Mat3::Identity()), beta[m], h));
  double v2_max = 0.0;
#pragma omp parallel reduction(max : c_max, v2_max) if (n >= particle_loop_min)
  {
    // Each thread reads the particles it updated (util/parallel.hpp, particle affinity).
    const auto [first, last] = static_range(n, omp_get_thread_num(), omp_get_num_threads());
    for (std::int64_t p = first; p < last; ++p) {
      const std::int32_t m = particles_.material[p];
      if (varies[m])
        c_max = std::max(c_max, damped_signal_speed(materials_[m]->wave_speed(particles_.deformation_gradient[p]),
                                                    beta[m], h));
      v2_max = std::max(v2_max, particles_.velocity[p].squaredNorm());
    }
  }
  double both[2] = {c_max, v2_max};
  distribution_.comm().max(both, 2);
  return both[0] + std::sqrt(both[1]);
}

template <int D>
double Simulation<D>::next_dt() const {
  const auto& s = config_.simulation;
  double dt = s.fixed_dt;
  if (dt <= 0.0 && s.time_step == "nominal") {
    // seed 001 Eq. 35: the wave speed of the undeformed materials, no particle speed.
    double c_max = 0.0;
    for (std::size_t m = 0; m < materials_.size(); ++m)
      c_max = std::max(c_max, damped_signal_speed(materials_[m]->wave_speed(Mat3::Identity()), damping_time_[m],
                                                  grid_.min_cell_size()));
    dt = s.cfl * grid_.min_cell_size() / c_max;
    if (conduction_) dt = std::min(dt, s.cfl * conduction_->stable_dt(particles_, material_density_));
  } else if (dt <= 0.0) {
    dt = s.cfl * grid_.min_cell_size() / max_signal_speed();  // seed 001 Eq. 34
    if (conduction_) dt = std::min(dt, s.cfl * conduction_->stable_dt(particles_, material_density_));
  }
  const double remaining = s.end_time - time_;
  if (remaining > 0.0 && dt > remaining) dt = remaining;
  return dt;
}

namespace {
const char* const stage_names[] = {"stencils", "particles_to_grid", "grid_update",
                                   "full_mass",  "particle_update",   "stress_update"};
}  // namespace

template <int D>
std::vector<std::pair<std::string, double>> Simulation<D>::stage_times() const {
  std::vector<std::pair<std::string, double>> out;
  for (std::size_t k = 0; k < stage_seconds_.size(); ++k) out.emplace_back(stage_names[k], stage_seconds_[k]);
  return out;
}

template <int D>
NodeField<D> Simulation<D>::grid_totals() const {
  if (!contact_) return nodes_;
  const std::int32_t nn = grid_.n_nodes();
  NodeField<D> t;
  t.resize(nn);
  for (std::int32_t i = 0; i < nn; ++i) {
    for (int f = 0; f < n_fields_; ++f) {
      const std::int32_t s = f * nn + i;
      t.mass[i] += nodes_.mass[s];
      t.momentum[i] += nodes_.momentum[s];
      t.force[i] += nodes_.force[s];
      t.velocity_new[i] += nodes_.mass[s] * nodes_.velocity_new[s];
      t.velocity[i] += nodes_.mass[s] * nodes_.velocity[s];
      if (!nodes_.reaction.empty()) t.reaction[i] += nodes_.reaction[s];
    }
    if (t.mass[i] > small_mass_) {
      t.velocity_new[i] /= t.mass[i];
      t.velocity[i] /= t.mass[i];
    } else {
      t.velocity_new[i].setZero();
      t.velocity[i].setZero();
    }
  }
  return t;
}

template <int D>
Totals Simulation<D>::totals() const {
  // Exact sums over the owned particles and the ranks: the same totals for any partition.
  const auto& P = particles_;
  const auto n = static_cast<std::int64_t>(n_owned());
  std::array<ExactSum, 7> sums = exact_sums<7>(n, [&](std::int64_t p, std::array<double, 7>& v) {
    v[0] = 0.5 * P.mass[p] * P.velocity[p].squaredNorm();
    const double* state = P.n_state_per_particle ? &P.state[p * static_cast<std::size_t>(P.n_state_per_particle)] : nullptr;
    v[1] = P.volume0[p] * materials_[P.material[p]]->internal_energy_density(P.deformation_gradient[p], state);
    const Vec3 momentum = to3<D>(P.mass[p] * P.velocity[p]);
    v[2] = momentum[0];
    v[3] = momentum[1];
    v[4] = momentum[2];
    v[5] = P.mass[p];
    v[6] = P.has_temperature ? P.mass[p] * P.temperature[p] : 0.0;
  });
  const Comm& comm = distribution_.comm();
  sum_across(comm, sums.data(), 7);
  Totals t;
  t.kinetic_energy = sums[0].value();
  t.strain_energy = sums[1].value();
  t.momentum = Vec3(sums[2].value(), sums[3].value(), sums[4].value());
  t.mass = sums[5].value();
  if (P.has_temperature) t.mean_temperature = sums[6].value() / t.mass;
  double p_max = -std::numeric_limits<double>::infinity();
#pragma omp parallel for reduction(max : p_max)
  for (std::int64_t p = 0; p < n; ++p)
    p_max = std::max(p_max, -P.kirchhoff_stress[p].trace() / (3.0 * P.deformation_gradient[p].determinant()));
  p_max = comm.max(p_max);
  t.max_pressure = total_particles() > 0 ? p_max : 0.0;
  return t;
}

template class Simulation<1>;
template class Simulation<2>;
template class Simulation<3>;

}  // namespace cairn
