// Multimaterial contact (seed 004; docs/contact.md).
//
// In multimaterial mode every field (a material or a body, [contact] mode) extrapolates to its
// own nodal mass and momentum (seed 004 Eq. 5-6). The simulation stores the fields of one node
// side by side: slot = field * n_nodes + node, and every transfer of the step adds the particle's
// field offset to its stencil's nodes, so that it reads and writes the particle's own field. A node that sees
// two or more fields is a contact node. Contact<D> finds those nodes, their normals and
// separations once per step (prepare), and corrects a nodal field for contact (correct):
//   - after the extrapolation of momenta: p^a = p^a0 + dp^a, kept as dv^a = dp^a / m^a (Eq. 26);
//   - after the momentum update: p^a+ = p^a0+ + dp^a+, whose dp^a+ / dt is the contact force
//     (Eq. 30-31, 33: f^aC,1), so that a^a = (v^a+ - v^a) / dt (Eq. 34, option 1);
//   - on re-extrapolated momenta of USL+/USAVG+ before their stress update.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

#include "cairn/contact/law.hpp"
#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/parallel/exact_sum.hpp"
#include "cairn/parallel/node_halo.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/transfer/cache.hpp"

namespace cairn {

template <int D>
class Contact {
 public:
  Contact(const Config& config, const Grid<D>& grid, const Particles<D>& particles, double small_mass);
  ~Contact();

  [[nodiscard]] int n_fields() const { return static_cast<int>(field_names_.size()); }
  [[nodiscard]] const std::vector<std::string>& field_names() const { return field_names_; }
  /// Field of particle p (its material or body index).
  [[nodiscard]] std::int32_t field_of(const Particles<D>& particles, std::size_t p) const {
    return by_body_ ? particles.body[p] : particles.material[p];
  }
  /// The initial edges of particle p's inscribed ellipse/ellipsoid in the LR separation (Eq. 25,
  /// R_0 half of them): its domain, or none for a particle of zero volume (a WLS surface
  /// particle, a point on the body's surface; docs/wls.md, "Contact").
  [[nodiscard]] static Vec<D> edges(const Particles<D>& particles, std::size_t p) {
    return particles.volume0[p] == 0.0 ? Vec<D>::Zero() : particles.size0[p];
  }

  /// Find the contact nodes and their normals and separations from the fields' masses
  /// (slots) and the particles (seed 004 Sec. 2.3, 3.1).
  void prepare(const Particles<D>& particles, const TransferCache<D>& cache, const std::vector<double>& mass);

  enum class Pass { extrapolated, updated, stress };
  /// Correct `values` (momenta when `momentum`, else velocities; slots) at the contact nodes.
  /// `dv` (slots, zeroed by the caller), when given, receives dp / m at the changed contact
  /// nodes (extrapolated pass); `dv_impulse` (likewise) the part of it that comes from
  /// non-bonded (contact) laws. The updated pass records the
  /// contact forces dp / dt per field pair and the number of nodes in contact.
  void correct(const std::vector<double>& mass, std::vector<Vec<D>>& values, bool momentum, Pass pass,
               double time, double dt, std::vector<Vec<D>>* dv, std::vector<Vec<D>>* dv_impulse = nullptr);

  /// The grid passed to the constructor now stores another window (a distributed run).
  void grid_changed();
  /// A node-halo run (parallel.halo = "nodes"): each rank holds its own particles only, and the
  /// grid is a window whose shared nodes `halo` sums. prepare() then sums the contact node arrays
  /// it scatters (AG gradients, CP/DF positions) through it and brings every point cloud the
  /// particles of the other ranks that reach the node (docs/parallel.md, "Contact under the node
  /// halo"). Null: every particle of a cloud is on this rank (serial, or the particle halo).
  void use_halo(NodeHalo<D>* halo) { halo_ = halo; }
  /// Sum the updated pass's forces and counts over the ranks (collective; call once per step
  /// after the updated pass, also in a serial run, before reading the three values below).
  void reduce(const Comm& comm);
  /// Kinetic energy taken from the fields by the contact corrections so far, over all ranks
  /// (frictional and impact losses; docs/contact.md, "Energy"): the change of sum m |v|^2 / 2
  /// at the contact nodes by every updated pass, and by the extrapolated pass when
  /// count_first_correction(true) says that its change reaches the particle velocities.
  [[nodiscard]] double dissipated() const { return dissipated_; }
  void set_dissipated(double value) { dissipated_ = value; }
  /// release = "separation": the field pairs the last updated pass held in contact (pair_key,
  /// sorted; empty with release = "gap"), for checkpoints; restore_record() takes them back
  /// (keys from the record of any rank count: a key of a node outside this rank's window is
  /// never looked up). InputError-free: the caller checks the keys against record_key_end().
  [[nodiscard]] std::vector<std::int64_t> record() const;
  void restore_record(const std::vector<std::int64_t>& keys);
  /// One past the largest pair key of this grid and field count.
  [[nodiscard]] std::int64_t record_key_end() const;
  /// Every rank's record on every rank (collective; after a repartition, so that a node moving
  /// to another rank keeps its pairs).
  void share_record(const Comm& comm);
  void count_first_correction(bool yes) { energy_from_first_ = yes; }
  /// The nodal velocities at the start of the step (slots), whose mean with the corrected
  /// updated velocities weighs the second correction's impulse (as the external work is weighed).
  void set_start_velocity(const std::vector<Vec<D>>* v) { start_velocity_ = v; }
  /// What the last updated pass did at one contact node for one field pair (trace(true)).
  struct NodeTrace {
    enum State : std::int8_t { bonded, no_normal, separating, gap_open, stick, slip };
    std::int32_t node = 0;
    std::int32_t a = 0, b = 0;      ///< fields alpha, beta (b = -1: the others lumped)
    State state = no_normal;
    Vec3 normal = Vec3::Zero();     ///< from alpha to beta
    double separation = 0.0;
    double area = 0.0;
    Vec3 dp0 = Vec3::Zero();        ///< the stick change of alpha, m_red (v_b - v_a)
    Vec3 dp = Vec3::Zero();         ///< the change the law gave alpha (beta got -dp)
  };
  /// Record every interaction of the updated pass (a diagnostic: verification/rolling_cylinder).
  void trace(bool on) { tracing_ = on; }
  [[nodiscard]] const std::vector<NodeTrace>& last_trace() const { return trace_; }
  /// Nodes that see two or more fields (last prepare), over all ranks.
  [[nodiscard]] std::size_t contact_nodes() const { return contact_total_; }
  /// Nodes where the last updated pass changed the momenta, over all ranks.
  [[nodiscard]] std::size_t active_nodes() const { return active_total_; }
  /// Pairs (a, b), a < b, reported in history: force on a from b of the last updated pass.
  [[nodiscard]] const std::vector<std::pair<int, int>>& pairs() const { return pairs_; }
  [[nodiscard]] const std::vector<Vec3>& pair_forces() const { return pair_force_; }
  /// Unit contact normal per grid node (zero away from contact nodes), for grid snapshots.
  void node_normals(std::vector<Vec3>& out) const;
  [[nodiscard]] bool corrects_extrapolation() const { return twice_; }
  /// first_correction = "impulse": the first correction's contact (non-bonded) change acts on
  /// the particle velocities (docs/contact.md, "Chatter").
  [[nodiscard]] bool impulse() const { return impulse_; }
  /// Cost counters: seconds in prepare (contact nodes, clouds, normals, separations), of which
  /// in the normal and separation fits, seconds in correct, and contact nodes summed over steps.
  [[nodiscard]] double prepare_seconds() const { return prepare_seconds_; }
  [[nodiscard]] double fit_seconds() const { return fit_seconds_; }
  [[nodiscard]] double correct_seconds() const { return correct_seconds_; }
  [[nodiscard]] long long node_steps() const { return node_steps_; }
  [[nodiscard]] bool xpic_correction() const { return xpic_correction_; }

 private:
  struct Interaction {
    std::int32_t a = 0;   ///< field alpha
    std::int32_t b = -1;  ///< field beta; -1: every other field lumped (Eq. 50)
    std::int32_t law = 0; ///< index into laws_
    Vec3 normal = Vec3::Zero();   ///< unit, from alpha to beta
    double separation = -1.0;     ///< < 0: touching
    double area = 0.0;
  };
  void geometry(std::size_t c, const Particles<D>& particles, const std::vector<double>& mass,
                std::vector<Vec3>& cloud_x, std::vector<signed char>& cloud_c, std::vector<std::int32_t>& cloud_p,
                std::vector<double>& cloud_w, Interaction& it) const;
  /// The point clouds (cloud_begin_, cloud_, cloud_weight_) of the contact nodes: this rank's
  /// particles whose stencil holds the node, and under a node halo the other ranks' (ghosts_).
  void build_clouds(const Particles<D>& particles, const TransferCache<D>& cache);
  /// Node halo: send each neighbour the particles whose stencils reach the contact nodes it
  /// shares with this window, receive its own into ghosts_; per received stencil entry, its
  /// contact node, cloud reference and weight (collective with the neighbours).
  void exchange_cloud_particles(const Particles<D>& particles, const TransferCache<D>& cache,
                                std::vector<std::int32_t>& entry_node, std::vector<std::int32_t>& entry_ref,
                                std::vector<double>& entry_weight);
  /// A cloud entry's particle: p >= 0 one of this rank's, -1 - g ghost g (node halo).
  [[nodiscard]] const Vec<D>& cloud_position(const Particles<D>& particles, std::int32_t ref) const {
    return ref >= 0 ? particles.position[static_cast<std::size_t>(ref)] : ghosts_.position[static_cast<std::size_t>(-1 - ref)];
  }
  [[nodiscard]] std::int32_t cloud_field(const Particles<D>& particles, std::int32_t ref) const {
    return ref >= 0 ? field_of(particles, static_cast<std::size_t>(ref)) : ghosts_.field[static_cast<std::size_t>(-1 - ref)];
  }
  [[nodiscard]] std::int64_t cloud_id(const Particles<D>& particles, std::int32_t ref) const {
    return ref >= 0 ? particles.id[static_cast<std::size_t>(ref)] : ghosts_.id[static_cast<std::size_t>(-1 - ref)];
  }
  /// h_n = |(n_a h_a)|: the cell's width along unit n (the cell size for square cells).
  [[nodiscard]] double cell_width(const Vec3& n) const;
  [[nodiscard]] double contact_area(const Vec3& n) const;
  [[nodiscard]] int law_of(int a, int b) const { return pair_law_[static_cast<std::size_t>(a * n_fields() + b)]; }
  [[nodiscard]] double edge_distance(double s) const;  ///< DF: d(s) of a field on the -n side
  /// release = "separation": the pair (a, b) at a node, keyed by the node's domain multi-index
  /// (the same on every rank and window); b = -1 the lumped others.
  [[nodiscard]] std::int64_t pair_key(std::int32_t node, int a, int b) const;

  const Grid<D>* grid_;
  ContactConfig cfg_;
  bool by_body_ = false;
  bool twice_ = true;
  bool xpic_correction_ = true;
  bool impulse_ = false;
  bool release_by_separation_ = false;  ///< release = "separation"
  /// release = "separation": the pairs the last updated pass held in contact (read by both passes
  /// of this step), and those this step's updated pass holds (pair_key).
  std::unordered_set<std::int64_t> in_contact_, in_contact_next_;
  double small_mass_ = 0.0;
  std::int32_t n_nodes_ = 0;
  std::vector<std::string> field_names_;
  std::vector<std::unique_ptr<ContactLaw>> laws_;
  std::vector<int> pair_law_;  ///< n_fields^2 law indices
  Vec3 specified_ = Vec3::Zero();
  bool need_clouds_ = false, need_gradient_ = false, need_position_ = false;

  // per step
  std::vector<std::int32_t> nodes_;        ///< contact nodes
  std::vector<std::int32_t> contact_of_;   ///< grid node -> index into nodes_ or -1
  std::vector<std::int32_t> field_begin_;  ///< CSR: fields present at contact node c
  std::vector<std::int32_t> fields_;
  std::vector<std::int32_t> cloud_begin_;  ///< CSR: particles whose stencil holds contact node c
  std::vector<std::int32_t> cloud_;
  std::vector<std::int32_t> id_order_;    ///< sorted serial runs: particles in id order (scratch)
  std::vector<double> cloud_weight_;       ///< S_ip of each cloud entry (lr_weights = "shape")
  std::vector<std::int32_t> inter_begin_;  ///< CSR: interactions of contact node c
  std::vector<Interaction> inter_;
  std::vector<Vec<D>> gradient_;  ///< AG: sum_p G_ip V_p per slot (Eq. 11)
  std::vector<Vec<D>> position_;  ///< CP/DF: S+ X per slot (Eq. 11), relative to the node
  /// Node halo: the other ranks' particles in this rank's point clouds, what the fits read of
  /// them (F and the initial size only for LR separations).
  struct Ghosts {
    std::vector<std::int64_t> id;
    std::vector<std::int32_t> field;
    std::vector<Vec<D>> position;
    std::vector<Mat3> deformation_gradient;
    std::vector<Vec<D>> size0;
    void clear() {
      id.clear();
      field.clear();
      position.clear();
      deformation_gradient.clear();
      size0.clear();
    }
  };
  NodeHalo<D>* halo_ = nullptr;
  Ghosts ghosts_;
  // build_clouds' scratch, kept between steps (no allocation in a step once the largest has run):
  // the other ranks' cloud entries (contact node, cloud reference, weight), each cloud's next
  // free place, and one cloud's (id, place) order with its references and weights while sorted.
  std::vector<std::int32_t> ghost_node_, ghost_ref_, cloud_cursor_, sort_refs_;
  std::vector<double> ghost_weight_, sort_weights_;
  std::vector<std::pair<std::int64_t, std::int32_t>> sort_order_;
  /// exchange_cloud_particles' scratch: one particle's stencil entries at shared contact nodes
  /// (neighbour k, row in the shared list, weight).
  struct HaloEntry {
    std::size_t k;
    std::int32_t row;
    double S;
  };
  std::vector<HaloEntry> halo_entries_;
  bool need_radius_ = false;  ///< LR separations read each cloud particle's F and initial size
  Comm::Buffers cloud_send_;  ///< node halo: per neighbour, kept between steps

  // DF table: extrapolated centre offset s -> edge distance d, both in cells, increasing
  std::vector<double> df_s_, df_d_;

  // output of the updated pass
  std::vector<std::pair<int, int>> pairs_;
  std::vector<Vec3> pair_force_;
  std::vector<ExactSum> pair_force_sum_;  ///< this rank's share, 3 per pair
  std::size_t active_total_ = 0, contact_total_ = 0;
  std::vector<int> pair_index_;  ///< n_fields^2 -> index into pairs_
  std::size_t active_ = 0;
  ExactSum energy_change_;        ///< this rank's energy change since the last reduce()
  double dissipated_ = 0.0;
  bool energy_from_first_ = false;
  const std::vector<Vec<D>>* start_velocity_ = nullptr;
  bool tracing_ = false;
  std::vector<NodeTrace> trace_;
  double prepare_seconds_ = 0.0, fit_seconds_ = 0.0, correct_seconds_ = 0.0;
  long long node_steps_ = 0;
};

}  // namespace cairn
