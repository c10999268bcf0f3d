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
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/wls/integrator.hpp"

namespace cairn {

namespace {

/// Exact sums of N terms over p in [0, n): term(p, out) sets out[0..N), every thread adds into
/// its own accumulators, merged exactly, so the result does not depend on the thread count or,
/// summed across ranks, on the partition (parallel/exact_sum.hpp).
template <int N, class Fn>
std::array<ExactSum, N> exact_sums(std::int64_t n, Fn&& term) {
  std::array<ExactSum, N> total;
#pragma omp parallel
  {
    std::array<ExactSum, N> local;
    std::array<double, N> values{};
#pragma omp for schedule(static)
    for (std::int64_t p = 0; p < n; ++p) {
      term(p, values);
      for (int k = 0; k < N; ++k) local[k].add(values[k]);
    }
#pragma omp critical(cairn_exact_sums)
    for (int k = 0; k < N; ++k) total[k] += local[k];
  }
  return total;
}

}  // namespace

template <int D>
Simulation<D>::Simulation(const Config& config, const Comm& comm) : config_(config), mode_(config.simulation.mode) {
  if (config_.simulation.threads > 0) omp_set_num_threads(config_.simulation.threads);
  for (const auto& mc : config_.materials) materials_.push_back(make_material(mc));
  ShapeContext ctx{config_.method, D};
  shape_ = make_shape_family<D>(ctx);
  scheme_ = SchemeRegistry<D>::instance().create("update scheme", config_.method.update, config_.method);
  flip_ = SchemeRegistry<D>::instance().create("update scheme", "flip", config_.method);
  const std::string& su = config_.method.stress_update;
  timing_ = su == "usf" ? Timing::usf
            : su == "usavg" ? Timing::usavg
            : su == "usl+" ? Timing::usl_plus
            : su == "usavg+" ? Timing::usavg_plus
                             : Timing::usl;
  setup_grid();
  int n_state = 0;
  for (const auto& m : materials_) n_state = std::max(n_state, m->n_state());
  particles_.n_state_per_particle = n_state;
  particles_.has_affine = scheme_->affine();
  particles_.has_temperature = config_.thermal.conduction;
  for (const auto& m : materials_) particles_.has_temperature |= m->uses_temperature();
  check_memory<D>(config_, grid_, velocity_fields(config_), n_state, shape_->ghost_layers() + 1, comm.size());
  if (comm.parallel()) {
    // Per-rank generation (docs/parallel.md): every rank walks the bodies' particles twice and
    // stores none of them the first time, only the cells of every size-th one (a census whose
    // histograms, summed over the ranks, are those of all particles), bisects the domain by
    // them, and stores only the particles of its own box the second time.
    distribution_ = Distribution<D>(comm, whole_);
    const auto rank = static_cast<std::int64_t>(comm.rank()), ranks = static_cast<std::int64_t>(comm.size());
    std::vector<IVec<D>> census;
    const ParticleSelection<D> count = [&](std::int64_t id, std::int32_t, const Vec<D>&, const Vec<D>& x) {
      if (id % ranks == rank) census.push_back(distribution_.cell_of(x));
      return false;
    };
    create_particles<D>(config_, grid_, materials_, mode_, particles_, &count);
    distribution_.partition_cells(census);
    std::vector<IVec<D>>().swap(census);
    const ParticleSelection<D> mine = [&](std::int64_t, std::int32_t, const Vec<D>&, const Vec<D>& x) {
      return distribution_.owner_of(x) == comm.rank();
    };
    create_particles<D>(config_, grid_, materials_, mode_, particles_, &mine);
    distribution_.adopt(particles_);
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
  }
  // Scratch node arrays only where the step uses them: full-mass expansions (FMPM, XPIC and
  // their blends) and the second stress-update velocity of USF/USAVG/USL+/USAVG+.
  node_scratch_ = scheme_->full_mass() != FullMass::none || timing_ != Timing::usl;
  // Conditions and tractions select their nodes and faces on the whole grid and every particle
  // (the faces gathered from every rank), so that a selection holding none is refused the same
  // way on any number of ranks.
  conditions_ = GridConditions<D>(config_.boundary, grid_, shape_->face_basis());
  velocity_conditions_ = VelocityConditions<D>(config_, grid_, conditions_);
  if (comm.parallel() && !config_.tractions.empty()) {
    // A face is exposed when its body has no particle in the lattice site across it, which may
    // belong to another rank: a third walk over the bodies records which of those sites hold a
    // particle.
    std::vector<std::unordered_set<std::int64_t>> across(config_.bodies.size()), occupied(config_.bodies.size());
    for (std::size_t p = 0; p < particles_.n(); ++p)
      for (int a = 0; a < D; ++a)
        for (int sign = -1; sign <= 1; sign += 2)
          across[particles_.body[p]].insert(Tractions<D>::lattice_site(particles_.reference_position[p],
                                                                      grid_.origin(), particles_.size0[p], a, sign));
    const ParticleSelection<D> sites = [&](std::int64_t, std::int32_t body, const Vec<D>& X, const Vec<D>&) {
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
    create_particles<D>(config_, grid_, materials_, mode_, none, &sites);
    tractions_ = Tractions<D>(config_, grid_, particles_, shape_->particle_domain(), occupied, comm);
  } else {
    tractions_ = Tractions<D>(config_, grid_, particles_, shape_->particle_domain());
  }

  if (config_.method.integration == "wls") {
    // The WLS method (seed 001) replaces the particle transfers; features that act through
    // them are not defined for it.
    const char* unsupported = D == 1                          ? "a 1D simulation"
                              : config_.contact.enabled()     ? "[contact]"
                              : config_.thermal.conduction    ? "[thermal] conduction"
                              : !config_.tractions.empty()    ? "[[traction]]"
                              : !config_.walls.empty()        ? "[[wall]]"
                                                              : nullptr;
    for (int a = 0; a < D && !unsupported; ++a)
      if (grid_.periodic(a)) unsupported = "periodic faces";
    if (unsupported)
      throw std::invalid_argument(std::string("method.integration = \"wls\" does not support ") + unsupported +
                                  " (docs/wls.md)");
    wls::Options o;
    o.trigger_weight = config_.method.trigger_weight;
    o.projected_distance = config_.method.surface_distance == "projection";
    o.average_per_mass = config_.method.spurious_force == "per_mass";
    o.quadrature_gradient = config_.method.velocity_gradient == "quadrature";
    // A symmetry face is a mirror plane of the body when the body reaches it at the start
    // (a particle within half a cell); otherwise it is a frictionless wall (docs/wls.md).
    for (int f = 0; f < 2 * D; ++f) {
      if (config_.boundary.face[f] != FaceCondition::symmetry) continue;
      const int a = f / 2;
      const double plane = f % 2 ? grid_.extent_max()[a] : grid_.origin()[a];
      for (std::size_t p = 0; p < particles_.n() && !o.mirror[f]; ++p)
        o.mirror[f] = std::abs(particles_.position[p][a] - plane) < 0.5 * grid_.cell_size()[a];
    }
    o.thickness = config_.simulation.thickness;
    wls_ = std::make_unique<wls::Integrator<D>>(grid_, o);
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
    grid_ = distribution_.window(whole_, reach_);
  }
  keep_particles_sorted(true);
  allocate_nodes();
  if (wls_) {
    // The initial node fields and integration regions, so that output at t = 0 shows them.
    wls_->build_stencils(grid_, particles_);
    compute_body_forces();
    wls_->collect(grid_, particles_, material_density_, body_force_.empty() ? nullptr : &body_acceleration_,
                  nodes_, body_force_.empty() ? nullptr : &node_body_force_);
  }
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
template <class Fn>
void Simulation<D>::collectively(Fn&& fn) {
  if (!distributed()) {
    fn();
    return;
  }
  const Comm& comm = distribution_.comm();
  constexpr std::int64_t none = std::numeric_limits<std::int64_t>::max();
  std::int64_t key = none;
  std::string message, quantity;
  try {
    fn();
  } catch (const SimulationFailure& f) {
    const SimulationFailure named = named_by_id(f);
    key = named.particle();
    message = named.what();
    quantity = named.quantity();
  }
  const std::int64_t first = comm.min(key);
  if (first == none) return;
  const auto root = static_cast<int>(comm.min(key == first ? std::int64_t{comm.rank()} : std::int64_t{comm.size()}));
  comm.broadcast(message, root);
  comm.broadcast(quantity, root);
  distribution_.drop_ghosts(particles_);
  throw SimulationFailure(first, quantity, message);
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
  if (!config_.simulation.sort_particles || distributed() || wls_ || n < sort_min_particles ||
      particles_.id.size() != n)
    return;
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
  } else if (!cache_.colouring_valid || cache_.order.size() != n) {
    return;
  }
  // Runs of consecutive storage indices in the colouring's order: sorted, a block is one run
  // (and a particle that changed block since splits one).
  const std::vector<std::int32_t>& order = cache_.order;
  std::size_t breaks = 0;
  for (std::size_t k = 1; k < n; ++k) breaks += static_cast<std::size_t>(order[k] != order[k - 1] + 1);
  if (breaks * sort_run >= n) {
    permute_particles(particles_, order);  // the particle stored at k was at order[k]
    tractions_.renumber(order);
    cache_.sorted_storage = true;    // the colouring sorts each block by id (transfer/colouring.cpp)
    cache_.colouring_valid = false;  // block_of and order index the old storage
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
  }
  keep_particles_sorted(true);
  compute_field_offsets();
}

template <int D>
double Simulation<D>::contact_dissipated_energy() const {
  return contact_ ? contact_->dissipated() : 0.0;
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
  for (std::int32_t m = 0; m < n_materials; ++m)
    if (!varies[m] && material_in_use_[m]) c_max = std::max(c_max, materials_[m]->wave_speed(Mat3::Identity()));
  double v2_max = 0.0;
#pragma omp parallel reduction(max : c_max, v2_max) if (n >= particle_loop_min)
  {
    // Each thread reads the particles it updated (util/parallel.hpp, particle affinity).
    const auto [first, last] = static_range(n, omp_get_thread_num(), omp_get_num_threads());
    for (std::int64_t p = first; p < last; ++p) {
      const std::int32_t m = particles_.material[p];
      if (varies[m]) c_max = std::max(c_max, materials_[m]->wave_speed(particles_.deformation_gradient[p]));
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
    for (const auto& m : materials_) c_max = std::max(c_max, m->wave_speed(Mat3::Identity()));
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
using StageClock = std::chrono::steady_clock;
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
void Simulation<D>::step(double dt) {
  if (wls_) {
    wls_step(dt);
    return;
  }
  auto clock = StageClock::now();
  auto lap = [&](int stage) {
    const auto now = StageClock::now();
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
  build_stencils();
  lap(0);
  const bool stress_first = timing_ == Timing::usf || timing_ == Timing::usavg || timing_ == Timing::usavg_plus;
  if (stress_first) {
    // USF / USAVG: update stresses from v = m^-1 p (m~_k^-1 p under FMPM) before the forces.
    particles_to_grid(true, false);
    velocity_conditions_.prepare(grid_, contact_ ? totals_ : nodes_, small_mass_, time_, dt);
    lap(1);
    stress_velocity_from_momentum(nodes_.momentum, fmpm_velocities);
    lap(3);
    update_stresses(nodes_.velocity_work, timing_ == Timing::usf ? dt : 0.5 * dt);
    refresh_ghosts(particles_.kirchhoff_stress);  // the forces below read the ghosts' stresses
    lap(5);
    particles_to_grid(false, true);
  } else {
    particles_to_grid(true, true);
    velocity_conditions_.prepare(grid_, contact_ ? totals_ : nodes_, small_mass_, time_, dt);
  }
  lap(1);
  update_grid(dt);
  lap(2);
  if (use_full_mass_) {
    // seed 000 Task 3: v+ = m~_k^-1 p+ (FMPM) or v = m~_k^-1 p (XPIC, blends).
    full_mass_velocity(need == FullMass::of_updated ? nodes_.velocity_new : nodes_.velocity,
                       nodes_.velocity_full, k);
    if (contact_ && contact_->xpic_correction()) {
      subtract_contact_term(nodes_.velocity_full, k);
      // The dv term comes after the conditions that full_mass_velocity imposed: impose them
      // again, so that a held node that is also a contact node keeps its condition.
      if (config_.method.velocity_bc_method != "lumped")
        impose_conditions(nodes_.velocity_full, need == FullMass::of_updated ? VelocityConditions<D>::When::end
                                                                              : VelocityConditions<D>::When::start);
    }
  }
  lap(3);
  if (timing_ == Timing::usl || timing_ == Timing::usavg) {
    // The stress update reads the same stencils and grid velocities as the particle update, so
    // it runs in the same particle loop (stencil data read once; its time counts as
    // particle_update).
    update_particles(dt, StressPass{fmpm_velocities ? &nodes_.velocity_full : &nodes_.velocity_new,
                                    timing_ == Timing::usl ? dt : 0.5 * dt});
  } else {
    update_particles(dt);
  }
  lap(4);
  switch (timing_) {
    case Timing::usf:
    case Timing::usl:
    case Timing::usavg:
      break;
    case Timing::usl_plus:
    case Timing::usavg_plus:
      // Re-extrapolate the updated particle momenta before the last stress update.
      refresh_ghosts(particles_.velocity);
      reextrapolate_momentum();
      lap(1);
      stress_velocity_from_momentum(grid_term_, fmpm_velocities);
      lap(3);
      update_stresses(nodes_.velocity_work, timing_ == Timing::usl_plus ? dt : 0.5 * dt);
      break;
  }
  lap(5);
  if (conduction_) {
    refresh_ghosts(particles_.temperature, particles_.has_temperature ? 1 : 0);
    std::function<void(std::vector<Vec<D>>&)> share_flux;
    if (distributed()) share_flux = [this](std::vector<Vec<D>>& flux) { refresh_ghosts(flux); };
    conduction_->step(cache_, particles_, dt, share_flux);
  }
}

template <int D>
void Simulation<D>::wls_step(double dt) {
  auto clock = StageClock::now();
  auto lap = [&](int stage) {
    const auto now = StageClock::now();
    stage_seconds_[stage] += std::chrono::duration<double>(now - clock).count();
    clock = now;
  };
  step_dt_ = dt;
  wls_->build_stencils(grid_, particles_);
  lap(0);
  // Sec. 4.1-4.5: node mass, least-squares velocity (as m v) and forces.
  compute_body_forces();
  const bool has_body_force = !body_force_.empty();
  wls_->collect(grid_, particles_, material_density_, has_body_force ? &body_acceleration_ : nullptr, nodes_,
                has_body_force ? &node_body_force_ : nullptr);
  velocity_conditions_.prepare(grid_, nodes_, small_mass_, time_, dt);
  lap(1);
  update_grid(dt);  // Eq. 25-26 with the conditions; half the first acceleration (Sec. 4.7)
  if (config_.method.filter_acceleration) {
    wls_->filter_acceleration(grid_, nodes_);
    impose_conditions(nodes_.velocity_new, VelocityConditions<D>::When::end);
  }
  lap(2);
  wls_->move_particles(grid_, nodes_, particles_, dt);  // Eq. 27-29 (or the quadrature gradient)
  lap(4);
  // Eq. 30: F <- (I + grad V dt) F, then the material.
  const auto n = static_cast<std::int64_t>(particles_.n());
  std::int64_t first_bad = -1;
  std::string what;
#pragma omp parallel for schedule(static)
  for (std::int64_t p = 0; p < n; ++p) {
    Mat3 L = Mat3::Zero();  // the integrator keeps grad V_p (Eq. 29 or the quadrature gradient)
    L.template topLeftCorner<D, D>() = wls_->particle_velocity_gradient()[p];
    const Mat3 dF = Mat3::Identity() + L * dt;
    if (const char* bad = update_particle(static_cast<std::size_t>(p), L, dF, dt)) {
#pragma omp critical(cairn_failure)
      if (first_bad < 0 || p < first_bad) {
        first_bad = p;
        what = bad;
      }
    }
  }
  if (first_bad >= 0) particle_failure(first_bad, what);
  lap(5);
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
void Simulation<D>::distribute_and_build() {
  const Comm& comm = distribution_.comm();
  // Particles that crossed into another box move there; the imbalance is measured on the
  // result, and beyond the threshold the boxes are bisected anew (docs/parallel.md).
  distribution_.migrate(particles_);
  imbalance_ = distribution_.imbalance(particles_.n());
  if (imbalance_ - 1.0 > config_.simulation.rebalance_threshold) distribution_.partition(particles_);
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
    std::int64_t reach[2 * D];
    for (int a = 0; a < D; ++a) {
      reach[a] = cache_.reach_lo[a];
      reach[D + a] = cache_.reach_hi[a];
    }
    comm.max(reach, 2 * D);
    std::int64_t needed = 0;
    for (auto r : reach) needed = std::max(needed, r);
    if (needed > reach_) {
      reach_ = static_cast<int>(needed);
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
    for (int a = 0; a < D; ++a) {
      cache_.reach_lo[a] = static_cast<int>(reach[a]);
      cache_.reach_hi[a] = static_cast<int>(reach[D + a]);
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
  if (body_force_constant_) return;  // particles_to_grid reads body_force_value_
  body_acceleration_.resize(particles_.n());
#pragma omp parallel
  {
    auto& expr = *body_force_[omp_get_thread_num()];
#pragma omp for schedule(static)
    for (std::int64_t p = 0; p < n; ++p)
      body_acceleration_[p] = expr(particles_.position[p], particles_.reference_position[p], time_);
  }
}

namespace {
/// Node position relative to the particle, taking the periodic wrap into account.
template <int D>
Vec<D> node_offset(const Grid<D>& grid, std::int32_t node, const Vec<D>& x) {
  Vec<D> d = grid.node_position(node) - x;
  for (int a = 0; a < D; ++a) {
    if (!grid.periodic(a)) continue;
    const double L = grid.n_cells()[a] * grid.cell_size()[a];
    d[a] -= L * std::round(d[a] / L);
  }
  return d;
}
}  // namespace

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
            const Vec<D> dx = node_offset(grid_, node, P.position[p]);
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
  // Tractions on particle faces join the grid forces (seed 000 Sec. 2.4, first equation).
  if (forces)
    collectively([&] {
      tractions_.add_forces(grid_, particles_, *shape_, time_ + 0.5 * step_dt_, nodes_.force,
                            contact_ ? &field_offset_ : nullptr);
    });
  if (mass_and_momentum && contact_) {
    // Multimaterial: contact nodes, normals and separations of this step, then the first
    // correction p^a = p^a0 + dp^a kept as dv^a (seed 004 Eq. 26).
    contact_->prepare(particles_, cache_, nodes_.mass);
    // dv^a is zero wherever this step's first correction does not set it (nodes that were
    // contact nodes last step included).
    for_each_node(n_slots(), [&](std::int32_t i) {
      contact_dv_[i].setZero();
      contact_impulse_[i].setZero();
    });
    if (contact_->corrects_extrapolation())
      contact_->correct(nodes_.mass, nodes_.momentum, true, Contact<D>::Pass::extrapolated, time_, step_dt_,
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
  }
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
      // or not (seed 001 Sec. 4.6); without mass there is no acceleration.
      nodes_.velocity[i] = nodes_.velocity_new[i] = wls_->node_velocity()[i];
    } else {
      nodes_.velocity[i].setZero();
      nodes_.velocity_new[i].setZero();
    }
  });
  // Second contact correction, on the updated momenta: dp^a+ / dt is the contact force and the
  // acceleration is (v^a+ - v^a) / dt with the corrected v^a (seed 004 Eq. 30-34).
  if (contact_) {
    contact_->correct(nodes_.mass, nodes_.velocity_new, false, Contact<D>::Pass::updated, time_, dt, nullptr);
    contact_->reduce(distribution_.comm());
  }
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
  if (!tractions_.empty()) {
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

template <int D>
template <class Finish>
void Simulation<D>::lumped_projection(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out, Finish&& finish,
                                      SlotRange slots) {
  // S+ S u: U_p = sum_i S_pi u_i, then (S+ U)_i = sum_p M_p S_pi U_p / m_i (seed 000 Sec. 2.1).
  if (!distributed()) {
    // One pass: each particle's U_p is formed and scattered while its stencil is at hand (`in`
    // is only read, so the colour sweep may gather it; the same sums in the same order).
    for_each_node(slots, [&](std::int32_t i) { out[i].setZero(); });
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
  if (contact_)  // the re-extrapolated momenta obey contact too (same normals and separations)
    contact_->correct(nodes_.mass, grid_term_, true, Contact<D>::Pass::stress, time_, step_dt_, nullptr);
}

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
          const Vec<D> d = node_offset(grid_, node, x_old);
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
  F = dF * F;
  update_stress_of(p, L, dF, dt);
  const double J = F.determinant();
  if (!particles_.velocity[p].allFinite()) return "velocity";
  if (!particles_.position[p].allFinite()) return "position";
  if (!(J > 0.0)) return "det F";
  if (!particles_.kirchhoff_stress[p].allFinite()) return "stress";
  return nullptr;
}

template <int D>
void Simulation<D>::particle_failure(std::int64_t first_bad, const std::string& what) const {
  const auto p = static_cast<std::size_t>(first_bad);
  std::string value;
  if (what == "det F") value = "det F = " + failure_number(particles_.deformation_gradient[p].determinant());
  else value = what + " is not finite";
  throw SimulationFailure(first_bad, what,
                          "particle " + std::to_string(first_bad) + " (body " +
                              std::to_string(particles_.body[p]) + "): " + value);
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
