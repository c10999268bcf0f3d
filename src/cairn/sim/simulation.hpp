// Simulation<D>: owns the state of one run (grid, node fields, particles, materials, transfer
// cache) and advances it by explicit steps. The step is a list of named stages that follow seed
// 000 Table 1; the run loop with outputs lives in run/engine.hpp.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "cairn/bc/expression.hpp"
#include "cairn/bc/grid_conditions.hpp"
#include "cairn/bc/traction.hpp"
#include "cairn/bc/velocity_conditions.hpp"
#include "cairn/contact/contact.hpp"
#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/parallel/distribution.hpp"
#include "cairn/parallel/node_halo.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/schemes/scheme.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/thermal/conduction.hpp"
#include "cairn/transfer/cache.hpp"
#include "cairn/util/failure.hpp"
#include "cairn/util/parallel.hpp"

namespace cairn {

namespace wls {
template <int D>
class Integrator;
template <int D>
class Fields;
}
struct StressTiming;

/// Global sums reported in history.csv.
struct Totals {
  double kinetic_energy = 0.0;
  double strain_energy = 0.0;
  Vec3 momentum = Vec3::Zero();
  double mass = 0.0;
  double mean_temperature = 0.0;  ///< mass-weighted particle temperature
  double max_pressure = 0.0;      ///< largest particle pressure -tr(sigma)/3
};

template <int D>
class Simulation {
 public:
  /// Build grid, materials and particles from a validated config. Throws std::invalid_argument
  /// for inputs that pass key validation but cannot be set up (e.g. a body with no particle).
  /// With a `comm` of several ranks the run is distributed (docs/parallel.md): every rank sets
  /// up the whole run, then keeps its share of the particles and a window of the grid; the
  /// constructor and step() are then collective.
  explicit Simulation(const Config& config, const Comm& comm = Comm::serial());
  ~Simulation();
  Simulation(const Simulation&) = delete;  // (its step hooks hold `this`)
  Simulation& operator=(const Simulation&) = delete;

  // ---- one explicit step (seed 000 Table 1) -------------------------------------------------
  /// dt from the CFL rule (seed 001 Eq. 34) or the fixed step, not beyond end_time.
  [[nodiscard]] double next_dt() const;
  /// Advance by dt: the stages below in the order the stress-update timing asks for.
  void step(double dt);

  void build_stencils();  ///< shapes: S_pi, G_pi into the cache; colouring
  /// Tasks 1-2: m = S^T M and p = S^T M V (plus the APIC affine term), and/or
  /// f = -G^T V0 tau + S^T M B.
  void particles_to_grid(bool mass_and_momentum = true, bool forces = true);
  void update_grid(double dt);      ///< Task 3: p+ = p + f dt, v = m^-1 p, v+ = m^-1 p+, conditions
  /// The stress update of USL/USAVG run inside the particle update's loop: grad V of `velocity`
  /// (a grid field) with time step dt.
  struct StressPass {
    const std::vector<Vec<D>>* velocity = nullptr;
    double dt = 0.0;
  };
  /// Task 4: the scheme's A and VV move the particles; with a stress pass, Task 5 follows each
  /// particle's move in the same loop.
  void update_particles(double dt, StressPass stress = {});
  /// Task 5: grad V = sum v_i (x) G_pi from `grid_velocity`, dF = exp(grad V dt), F <- dF F.
  void update_stresses(const std::vector<Vec<D>>& grid_velocity, double dt);

  /// out = m~_k^-1 m in, the k-term full mass matrix inverse (seed 000 Eq. 1) applied to
  /// in = m^-1 q, with velocity conditions by the selected method (seed 000 Sec. 2.4).
  void full_mass_velocity(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out, int k);
  /// out = S+ S in: grid -> particles -> grid with the lumped reverse map (seed 000 Sec. 2.1).
  /// out = S+ S in, then finish(i, out_i) in the same node loop (the caller's use of the result).
  /// Its node loops visit `slots` only (every slot with mass must lie in it; the others keep
  /// what they held).
  template <class Finish>
  void lumped_projection(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out, Finish&& finish,
                         SlotRange slots);
  void lumped_projection(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out);
  void lumped_projection_distributed(const std::vector<Vec<D>>& in, std::vector<Vec<D>>& out);

  /// Seconds spent per pipeline stage so far (name, seconds), in pipeline order.
  [[nodiscard]] std::vector<std::pair<std::string, double>> stage_times() const;

  // ---- state ----------------------------------------------------------------------------------
  [[nodiscard]] const Config& config() const { return config_; }
  /// The grid this rank stores: the whole grid in a serial run, a window of it on a rank of a
  /// distributed run (Grid::window).
  [[nodiscard]] const Grid<D>& grid() const { return grid_; }
  /// The ranks of the run and this rank's share (docs/parallel.md).
  [[nodiscard]] const Comm& comm() const { return distribution_.comm(); }
  [[nodiscard]] const Distribution<D>& distribution() const { return distribution_; }
  /// How this rank shares nodes with the others: "nodes", "particles", or "" on one rank.
  [[nodiscard]] std::string halo() const { return !distributed() ? "" : node_halo_ ? "nodes" : "particles"; }
  /// Bytes this rank has sent in halo exchanges (node sums, or ghost copies and refreshes).
  [[nodiscard]] std::int64_t halo_bytes() const {
    return node_halo_ ? halo_.bytes_sent() : distribution_.ghost_bytes_sent();
  }
  /// Of them, the bytes of the particles of contact nodes (a node halo with contact).
  [[nodiscard]] std::int64_t halo_cloud_bytes() const { return node_halo_ ? halo_.message_bytes_sent() : 0; }
  /// Seconds this rank has spent in node-halo sums, and in their exchanges (0 for the particle
  /// halo).
  [[nodiscard]] double halo_seconds() const { return node_halo_ ? halo_.seconds() : 0.0; }
  [[nodiscard]] double halo_wait_seconds() const { return node_halo_ ? halo_.wait_seconds() : 0.0; }
  /// Largest particle count of a rank over the mean count at the start of the last step (1 on
  /// one rank).
  [[nodiscard]] double imbalance() const { return imbalance_; }
  /// Particles of all ranks (collective on several ranks).
  [[nodiscard]] std::int64_t total_particles() const;
  /// Replace the particles with `particles` (a restart: on several ranks, any share of the
  /// checkpoint's particles per rank) and redistribute them (collective).
  void set_particles(Particles<D> particles);
  /// Node fields; in multimaterial mode field f of node i is entry f * n_nodes + i.
  [[nodiscard]] const NodeField<D>& nodes() const { return nodes_; }
  /// The WLS method's state (method.integration = "wls", docs/wls.md), or null.
  [[nodiscard]] const wls::Integrator<D>* wls() const { return wls_.get(); }
  [[nodiscard]] wls::Integrator<D>* wls() { return wls_.get(); }
  /// WLS bodies in contact (docs/wls.md, "Contact"): one integrator per contact field, wls()
  /// being field 0's; null without [contact].
  [[nodiscard]] const wls::Fields<D>* wls_fields() const { return wls_fields_.get(); }
  /// The WLS energy budget's sums (docs/wls.md, "Energy budget"), over every contact field.
  [[nodiscard]] double wls_grid_work() const;
  [[nodiscard]] double wls_transfer_energy() const;
  void restore_wls_energy_budget(double grid_work, double transfer_energy);
  /// Multimaterial contact ([contact] mode), or null in single-field mode.
  [[nodiscard]] const Contact<D>* contact() const { return contact_.get(); }
  [[nodiscard]] Contact<D>* contact() { return contact_.get(); }
  /// Node fields summed over the material fields (mass, momentum, velocity_new as m-weighted
  /// mean); the node fields themselves in single-field mode. For grid snapshots.
  [[nodiscard]] NodeField<D> grid_totals() const;
  [[nodiscard]] Particles<D>& particles() { return particles_; }
  [[nodiscard]] const Particles<D>& particles() const { return particles_; }
  [[nodiscard]] const TransferCache<D>& cache() const { return cache_; }
  [[nodiscard]] const std::vector<std::unique_ptr<Material>>& materials() const { return materials_; }
  [[nodiscard]] double time() const { return time_; }
  [[nodiscard]] long long step_count() const { return step_; }
  /// Work done on the particles by body forces and velocity conditions so far.
  [[nodiscard]] double external_work() const { return external_work_; }
  /// Energy dissipated so far: by the particle update (seed 002 Eq. 1.47-1.50), by contact
  /// corrections (friction and impact losses, Contact::dissipated) and by damped materials.
  [[nodiscard]] double dissipated_energy() const {
    return dissipated_energy_ + contact_dissipated_energy() + material_dissipated_energy();
  }
  /// The materials' part of dissipated_energy(): the work of their viscous stresses
  /// (Material::dissipated_energy_density, kept per particle; 0 when no material is damped).
  [[nodiscard]] double material_dissipated_energy() const;
  /// The particle update's part of dissipated_energy().
  [[nodiscard]] double update_dissipated_energy() const { return dissipated_energy_; }
  /// The contact corrections' part of dissipated_energy() (0 without contact).
  [[nodiscard]] double contact_dissipated_energy() const;
  /// Time of the next full-mass step of periodic FMPM/XPIC (method.full_mass_cfl > 0).
  [[nodiscard]] double next_full_mass_time() const { return next_full_mass_time_; }
  void restore_counters(double time, long long step, double external_work, double update_dissipated,
                        double contact_dissipated, double next_full_mass_time);
  [[nodiscard]] Totals totals() const;

  // ---- loads and velocity conditions (docs/boundary-conditions.md) ---------------------------
  /// [[velocity]] node sets and [[wall]] moving walls (names, reactions, wall positions).
  [[nodiscard]] const GridConditions<D>& grid_conditions() const { return conditions_; }
  [[nodiscard]] const VelocityConditions<D>& velocity_conditions() const { return velocity_conditions_; }
  [[nodiscard]] VelocityConditions<D>& velocity_conditions() { return velocity_conditions_; }
  [[nodiscard]] const Tractions<D>& tractions() const { return tractions_; }
  /// Notes raised by the step since the last call (e.g. two conditions on one node), each once;
  /// on several ranks gathered by rank 0 (collective), empty on the others.
  std::vector<std::string> take_notes();

  // ---- particle order (docs/architecture.md, "Particle order") ------------------------------
  /// Serial runs of at least this many particles keep them in memory in the colouring's
  /// cell-block order (simulation.sort_particles): a scatter then reads each block's particles
  /// as one run of memory instead of one short run per row of cells (3D linear block of 64 000
  /// particles: particles-to-grid 1.75x faster, docs/performance.md). Smaller runs fit the
  /// caches in any order.
  static constexpr std::size_t sort_min_particles = 32768;
  /// The same for WLS runs, whose step reads about four times the bytes per particle (stencils
  /// with wide weights and offsets, the fitted fields' rows: docs/performance-notes.md, "WLS step").
  static constexpr std::size_t sort_min_particles_wls = 8192;
  /// They are sorted again when the colouring's block order falls apart into runs of
  /// consecutive particles shorter than this on average.
  static constexpr std::size_t sort_run = 32;
  /// Storage indices of the particles in id order, or empty when storage order is id order or
  /// the run is distributed (output writes particles in this order, so that files list them as a
  /// serial run in creation order does). Computed on each call (4 bytes per particle).
  [[nodiscard]] std::vector<std::int32_t> output_order() const {
    std::vector<std::int32_t> order;
    if (!distributed() && cache_.sorted_storage) storage_in_id_order(particles_, order);
    return order;
  }
  /// How often this run sorted its particles (the setup's sort included).
  [[nodiscard]] long long particle_sorts() const { return particle_sorts_; }

 private:
  /// Sort the particles into the block order of a colouring when they are out of it: `setup`
  /// colours them first (no stencils yet), a step start uses the last step's colouring.
  void keep_particles_sorted(bool setup);
  /// A serial run's failure names the particle by its id, as an unsorted run does.
  [[nodiscard]] SimulationFailure named_by_id(const SimulationFailure& f) const;
  /// Multimaterial: field_offset_ of every particle.
  void compute_field_offsets();
  void setup_grid();
  /// Size every node-indexed structure for grid_ (the setup, and a distributed run's windows).
  void allocate_nodes();
  /// Store `window` as grid_ when it differs (a distributed run), reallocating the node arrays.
  void set_window(const Grid<D>& window);
  /// A distributed step's start: imbalance, repartition, migration; then ghosts, window and
  /// stencils until the stencils fit the window.
  void distribute_and_build();
  /// A node-halo step's start: migration and stencils of the owned particles on a window one
  /// reach (and a cell, for traction faces) beyond the box, then the halo's shared nodes.
  void distribute_nodes_and_build();
  /// Both: migration, the imbalance, and a repartition beyond simulation.rebalance_threshold.
  void migrate_and_rebalance();
  /// The bisection's weight of a particle of each material (parallel.balance = "cost": the
  /// model's measured cost or the material's balance_cost, in thousandths; else none).
  [[nodiscard]] std::vector<std::int64_t> material_weights() const;
  /// The largest stencil reach over the ranks (collective): when it exceeds reach_, reach_ takes
  /// it and true is returned (the windows must widen); otherwise the cache records it.
  bool widened_to_global_reach();
  /// This rank's window for a node halo at the current reach.
  [[nodiscard]] Grid<D> node_window() const {
    return box_window(whole_, distribution_.decomposition().box(distribution_.comm().rank()), reach_ + 1);
  }
  /// Named points of the step where optional features attach (their set-up calls on()):
  /// after the internal forces (tractions), after mass and momentum (contact's nodes, normals and
  /// first correction), before the grid velocity conditions (contact's second correction), after
  /// the full-mass expansion (multimaterial XPIC/FMPM's contact term), at the end (conduction).
  enum class StepPoint { after_forces, after_momentum, before_conditions, after_full_mass, end_of_step };
  void on(StepPoint point, std::function<void(double dt)> hook) { hooks_[static_cast<int>(point)].push_back(std::move(hook)); }
  void run_hooks(StepPoint point, double dt) {
    for (const auto& hook : hooks_[static_cast<int>(point)]) hook(dt);
  }
  /// The node fields velocity conditions select their nodes by: the totals over the material
  /// fields in multimaterial mode, the one field otherwise.
  [[nodiscard]] const NodeField<D>& condition_fields() const { return contact_ ? totals_ : nodes_; }
  /// The stages of step() after its set-up (ghosts are dropped by step() however they end).
  template <class Lap>
  void step_stages(double dt, FullMass need, bool fmpm_velocities, int k, Lap& lap);
  /// Run `fn`; if it throws a SimulationFailure on any rank, throw the one of the lowest
  /// particle id on every rank, naming the particle by id (collective on several ranks).
  template <class Fn>
  void collectively(Fn&& fn);
  /// A distributed run: owners send the ghost copies the current values of a per-particle array.
  template <class T>
  void refresh_ghosts(std::vector<T>& values, int width = 1) {
    if (!node_halo_) distribution_.refresh(values, width);
  }
  /// A node-halo run (parallel.halo): sum node arrays (n_slots() entries each) over the ranks
  /// sharing their nodes; a no-op otherwise (one rank, or ghost particles).
  template <class... T>
  void sum_halo(std::vector<T>&... arrays) {
    if (node_halo_) halo_.sum(n_fields_, arrays...);
  }
  [[nodiscard]] bool distributed() const { return distribution_.active(); }
  /// Particles this rank updates: all local ones outside a step, the owned ones during it.
  [[nodiscard]] std::size_t n_owned() const { return distributed() ? distribution_.n_owned() : particles_.n(); }
  void compute_body_forces();
  /// The material's stress update of particle p into its stored stress (plane stress included).
  void update_stress_of(std::size_t p, const Mat3& L, const Mat3& dF, double dt);
  /// Task 5 for particle p from its velocity gradient: F, the stress and the failure checks
  /// (returns what is not finite or not positive, or nullptr).
  const char* update_stress_at(std::int64_t p, const Eigen::Matrix<double, D, D>& L_D, double dt, bool increments);
  /// What of particle p is not finite (velocity, position, stress) or det F <= 0, or nullptr.
  [[nodiscard]] const char* failed_quantity(std::size_t p) const;
  [[nodiscard]] bool uses_increments() const;  ///< any material reads MaterialPoint::L or dF
  static void record_failure(std::int64_t p, const char* bad, std::int64_t& first_bad, std::string& what);
  [[nodiscard]] double max_signal_speed() const;
  /// Grid velocity for a stress update from the momenta in nodes_.velocity_work's source: m^-1 q
  /// with conditions, or m~_k^-1 q for FMPM.
  void stress_velocity_from_momentum(const std::vector<Vec<D>>& momentum, bool full_mass);
  void reextrapolate_momentum();  ///< USL+/USAVG+: q = S^T M V^(n+1) into grid_term_
  /// One step of the WLS method (seed 001 Sec. 4, wls/step.hpp): its collection replaces the
  /// particle transfers; the grid update, conditions and material updates are the engine's,
  /// which WlsStages hands it.
  void wls_step(double dt);
  class WlsStages;
  /// F <- dF F and the material stress of particle p; the failing quantity's name, or null.
  const char* update_particle(std::size_t p, const Mat3& L, const Mat3& dF, double dt);
  /// Throw SimulationFailure for particle p and the quantity update_particle named.
  [[noreturn]] void particle_failure(std::int64_t p, const std::string& what) const;
  /// Multimaterial XPIC/FMPM: out -= m~_(k-1)^-1 m dv^a (seed 004 Eq. 37, seed 000 Eq. 5).
  void subtract_contact_term(std::vector<Vec<D>>& out, int k);
  /// Entries of the node arrays: n_nodes, times the number of fields in multimaterial mode.
  [[nodiscard]] std::int32_t n_slots() const { return grid_.n_nodes() * n_fields_; }
  /// The storage range from the first to the last node slot with mass (one field, one rank;
  /// the whole grid otherwise).
  [[nodiscard]] SlotRange occupied_slots() const;
  /// Offset of particle p's field in the node arrays (multimaterial mode; 0 otherwise).
  [[nodiscard]] std::int32_t field_offset(std::int64_t p) const { return contact_ ? field_offset_[p] : 0; }
  /// Every velocity condition ([boundary] faces, then [[velocity]], then [[wall]]) on one field,
  /// with the values of the start or the end of the step.
  void impose_conditions(std::vector<Vec<D>>& velocity, typename VelocityConditions<D>::When when);

  Config config_;
  Mode mode_;
  Grid<D> whole_;  ///< the whole grid (geometry)
  Grid<D> grid_;   ///< the stored grid: whole_, or this rank's window of it
  Distribution<D> distribution_;
  bool node_halo_ = false;  ///< several ranks exchanging node sums (parallel.halo = nodes)
  NodeHalo<D> halo_;
  int reach_ = 1;             ///< stencil reach the window and ghost band are sized for
  double imbalance_ = 1.0;
  std::set<std::string> reported_pairs_;  ///< rank 0 of a distributed run: conflicts noted
  bool node_scratch_ = false;  ///< the step uses velocity_full / velocity_work and grid_term_
  NodeField<D> nodes_;
  std::vector<Vec<D>> node_body_force_;  ///< S^T M B part of f, for the external-work tally
  Particles<D> particles_;
  TransferCache<D> cache_;
  std::vector<std::unique_ptr<Material>> materials_;
  std::unique_ptr<ShapeFamily<D>> shape_;
  std::unique_ptr<UpdateScheme<D>> scheme_;
  std::unique_ptr<UpdateScheme<D>> flip_;
  std::unique_ptr<Conduction<D>> conduction_;  ///< [thermal] conduction = true
  std::vector<double> material_density_;  ///< periodic FMPM/XPIC: the steps between full-mass ones
  std::vector<char> material_in_use_;     ///< whether any particle has material m
  std::vector<char> wave_speed_varies_;   ///< Material::wave_speed_varies of material m
  std::vector<double> damping_time_;      ///< Material::damping_time of material m
  const StressTiming* timing_ = nullptr;  ///< method.stress_update (sim/stress_timing.hpp)
  /// The features attached to the step's named points (StepPoint), in attachment order.
  std::array<std::vector<std::function<void(double dt)>>, 5> hooks_;
  bool use_full_mass_ = false;             ///< this step computes nodes_.velocity_full
  std::vector<Vec<D>> grid_term_, grid_proj_;  ///< scratch of the full-mass expansion
  std::vector<Vec<D>> particle_vec_;       ///< scratch: grid values at particles (FMPM/XPIC)
  double dissipated_energy_ = 0.0;
  double step_dt_ = 0.0;
  double next_full_mass_time_ = 0.0;
  std::array<double, 6> stage_seconds_{};
  std::vector<std::unique_ptr<ExpressionVector<D>>> body_force_;  ///< one per thread
  bool body_force_constant_ = false;
  Vec<D> body_force_value_ = Vec<D>::Zero();
  std::vector<Vec<D>> body_acceleration_;  ///< b_p of this step (body forces that vary)
  GridConditions<D> conditions_;           ///< velocity conditions from [boundary]
  VelocityConditions<D> velocity_conditions_;  ///< [[velocity]] and [[wall]]
  Tractions<D> tractions_;                 ///< [[traction]]
  /// Which values a full-mass expansion of nodes_.velocity_work re-imposes (USF: start, USL+: end).
  typename VelocityConditions<D>::When work_when_ = VelocityConditions<D>::When::start;
  double small_mass_ = 0.0;
  std::unique_ptr<Contact<D>> contact_;      ///< multimaterial mode ([contact] mode != none)
  std::unique_ptr<wls::Integrator<D>> wls_;  ///< method.integration = "wls"
  std::unique_ptr<wls::Fields<D>> wls_fields_;  ///< WLS with [contact]: the fields' integrators
  int n_fields_ = 1;
  std::vector<Vec<D>> contact_dv_;           ///< dv^a of the first correction (slots)
  std::vector<Vec<D>> contact_impulse_;      ///< its non-bonded part, an impulse on the particles (slots)
  NodeField<D> totals_;                      ///< multimaterial: mass and momentum summed over fields
  std::vector<std::int32_t> field_offset_;   ///< multimaterial: field * n_nodes per particle
  double time_ = 0.0;
  long long step_ = 0;
  double external_work_ = 0.0;
  long long particle_sorts_ = 0;
};

/// Which generated particles a rank stores (per-rank generation, docs/parallel.md): called for
/// every particle the bodies generate on this rank, in creation order, with its id (its number in
/// a serial run), body, reference position X and position x, and whether it is this rank's share
/// of a body that is not split by boxes (`in_share`: a body off the plain lattice, see
/// GenerationShare; no other rank makes it, wherever it lies); true stores it. The checks of the
/// generation (empty bodies, overlaps) count over every rank, so they decide alike.
template <int D>
using ParticleSelection =
    std::function<bool(std::int64_t id, std::int32_t body, const Vec<D>& X, const Vec<D>& x, bool in_share)>;

/// Per-rank generation: the ranks of `comm` split the lattice points of the plain lattice bodies
/// (no point file or mesh elements, no radial arrangement, no WLS surface particles, no
/// displacement), so that each runs the inside tests of only its own points. Without a
/// decomposition (the census that decides it) rank r takes the r-th block of lattice rows;
/// with one, the points in the cells of its box, widened by `margin` cells. Of every other body
/// rank r makes the r-th block of its candidates (lattice points, then seeds), in both walks
/// (`in_share`). A margin makes neighbouring ranks test the same points: such a walk only
/// selects (the ids it passes mean nothing), skips the generation's checks, which a walk without
/// a margin has made, and walks the other bodies whole.
template <int D>
struct GenerationShare {
  const Comm* comm = nullptr;
  const Decomposition<D>* decomposition = nullptr;
  int margin = 0;
};

/// Fill `particles` from the [[body]] tables (sim/bodies.cpp): all of them, or those `select`
/// keeps (ids as in a serial run), generated whole or, with `share` on several ranks, per rank.
template <int D>
void create_particles(const Config& config, const Grid<D>& grid,
                      const std::vector<std::unique_ptr<Material>>& materials, Mode mode,
                      Particles<D>& particles, const ParticleSelection<D>* select = nullptr,
                      const GenerationShare<D>* share = nullptr);

}  // namespace cairn
