// The weighted-least-squares particle-in-cell method of seed 001 (Wallstedt & Guilkey) as a
// method of Cairn's one engine: Simulation<D> owns an Integrator when method.integration = "wls"
// and runs its stages in place of the particle-integrated transfers (docs/wls.md):
//
//   build_stencils    W (wide, Eq. 4) and S, G (narrow, Eq. 5-6) of every particle; colouring
//   collect           Sec. 4.1-4.5: particle density, body-force density and Cauchy stress;
//                     node moment matrices and least-squares values (Eq. 7-12); surface flags
//                     and signed distance on the nodes (Eq. 13-17); cut cells with one centroid
//                     point per inside region (Eq. 18, Sec. 3.4); quadrature values (Eq. 19-21);
//                     node mass, external and internal force (Eq. 22-24); averaged internal force
//                     at spurious nodes (Sec. 3.5, 4.5). Results go into the engine's NodeField:
//                     mass m_i, momentum m_i v_i (so that m^-1 p is the least-squares velocity,
//                     Sec. 4.6) and force f_int + f_ext.
//   (the engine)      v+ = v + a dt with velocity conditions, half the first acceleration
//                     (Eq. 25-26, Sec. 4.7)
//   move_particles    Eq. 27-29: V += S a dt, x += S v+ dt, grad V = sum v+ (x) G
//   (the engine)      Eq. 30: F += grad V F dt, stress from the material
//
// Surface particles are the particles with zero initial volume (wls/arrangement.hpp).
// Everything the method keeps between stages lives here; nothing is kept between steps except
// what the particles carry, so checkpoints and restarts need nothing extra.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/grid/grid.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/transfer/cache.hpp"
#include "cairn/wls/cut_cell.hpp"

namespace cairn::wls {

/// Surface particle (beta_p = 1, seed 001 Eq. 13): a sample point of zero initial volume.
template <int D>
inline bool is_surface(const Particles<D>& particles, std::size_t p) {
  return particles.volume0[p] == 0.0;
}

struct Options {
  double trigger_weight = 0.12;  ///< TW of Sec. 3.5
  /// Signed distance of a near-surface node: true = projection of x_surf - x_i on the unit
  /// normal (the text of Sec. 3.3, step 2); false = |x_surf - x_i| with the sign (Eq. 17 as printed).
  bool projected_distance = false;
  /// Spurious-node internal force (Sec. 3.5, 4.5): true = mean of the neighbours' internal
  /// force per unit mass, times the node's mass; false = mean of the neighbours' internal force.
  bool average_per_mass = true;
  /// Spurious-node internal force: false = replaced by the neighbours' mean (Sec. 3.5, 4.5, as
  /// above); true = the node's own integral Eq. 24 like every other node (docs/wls.md).
  bool integrated_spurious_force = false;
  /// Values at the integration points (Eq. 19-21): true = each well-conditioned corner's planar
  /// fit evaluated at the point (Eq. 10 at r = x_q - x_i), so linear fields are reproduced also
  /// where some corners are spurious; false = the corners' node values c0 (Eq. 19-21 as printed).
  bool fitted_point_values = false;
  /// Stress at the integration points: true = the transpose of the quadrature gradient's
  /// transfer (point_values = "adjoint", docs/wls.md departure 15): sigma_q = sum_k S_kq N_k / W_k
  /// with N_k = sum_p S_kp V_p sigma_p / s_p and W_k = sum_q S_kq V_q, so that the internal
  /// force's power equals the particles' stress power; density and body force as above.
  bool adjoint_point_stress = false;
  /// Velocity of a spurious node: true = mean of its well-conditioned neighbours' planar velocity
  /// fits evaluated at the node (linear fields reproduced); false = its constant fit c0 (Sec. 3.5
  /// as printed: a weighted mean of particle velocities about a cell away).
  bool extrapolated_spurious_velocity = false;
  /// Face 2*axis + side is a mirror plane of the body (a symmetry face the body reaches, or with
  /// every_symmetry_face_mirrors any symmetry face): node flags count the mirror image and
  /// surface positions of nodes on it lie in it.
  std::array<bool, 6> mirror{};
  /// method.mirror_planes = "all": every symmetry face is a mirror plane, also one the body
  /// meets later (a frictionless wall: the body meets its mirror image there; docs/wls.md,
  /// departure 14); false = only faces the body reaches at the start.
  bool every_symmetry_face_mirrors = true;
  /// Particle velocity gradient: true = from the integration points (sum_k v+_k (x) G_kq at each
  /// region, S V-averaged to the nodes, S-interpolated to the particle; docs/wls.md); false =
  /// Eq. 29 as printed (sum_i v+_i (x) G_ip), whose strain rate is not the power conjugate of
  /// Eq. 24: a free body gains energy at small steps (docs/wls.md, departure 4).
  bool quadrature_gradient = true;
  /// Particle velocity gradient (method.velocity_gradient = "transpose", docs/wls.md departure
  /// 17): the transpose of the stress transfer of Eq. 19-21 (the node fits, then the point values
  /// at the integration points), normalised: L_p = sum_q V_q T_qp L_q / sum_q V_q T_qp, where
  /// sigma_q = sum_p T_qp sigma_p and L_q = sum_k v+_k (x) G_kq. The particles then store the power
  /// Eq. 24's internal force takes from the grid wherever sum_q V_q T_qp = V_p. Surface particles
  /// and particles whose sum_q V_q T_qp is not within a factor transpose_band of V_p take the
  /// quadrature gradient. quadrature_gradient is false with it.
  bool transpose_gradient = false;
  double thickness = 1.0;          ///< out-of-plane thickness in 2D (volumes and masses)
  /// method.filter_acceleration: the step filters the grid velocity increments (docs/wls.md).
  bool filter_acceleration = false;
  /// method.hourglass_damping: the fraction of each full cell's hourglass velocity the step
  /// removes (docs/wls.md); 0 = seed 001 as printed.
  double hourglass_damping = 0.0;
  /// Particle velocity update: false = Eq. 27 as printed, V_p += sum S_ip (v+_i - v_i) (FLIP);
  /// true = V_p = sum S_ip v+_i (PIC, seed 002 Eq. 1.66 without damping; docs/wls.md).
  bool pic_velocity = false;
  /// particle_velocity = "xpic" (docs/wls.md, departure 18): the number of terms k of the XPIC(k)
  /// projection from which Eq. 27's FLIP increment starts, sum S u_k with u_k the k-term series
  /// of the fitted velocity (wls/xpic.cpp); 0 = off, 1 = PIC.
  int xpic_order = 0;
  /// Velocity of the surface particles (zero mass) before Eq. 27's increment: false = their own
  /// (as printed); true = the S-weighted planar velocity fits (Eq. 10) of the well-conditioned
  /// corners of their cell at their position, so that a massless point keeps no velocity of its
  /// own for the next fits to read (docs/wls.md, departure 16).
  bool fitted_surface_velocity = false;
  /// Nodes without mass in a particle's Eq. 27-28 (S_ip > 0: corners of its cell that no
  /// integration region reaches): false = they take, for the particle, the S-weighted mean of the
  /// corners with mass (the partition of unity kept; docs/wls.md, departure 12); true = their
  /// zero velocity and acceleration enter the sums (as printed).
  bool massless_corners_included = false;
  /// method.energy_budget: move_particles sums grid_work() and transfer_energy() (docs/wls.md,
  /// "Energy budget"); off, both stay zero and the step does not pay for the sums.
  bool energy_budget = false;
};

/// Loads on parts of the body's surface (tractions on particle faces, bc/traction.hpp), which
/// the integrator spreads over the nodes consistently with its internal force (docs/wls.md,
/// "Tractions"). A group is one loaded part with one outward direction: the faces of one
/// traction with one normal axis and side.
template <int D>
struct SurfaceLoads {
  std::vector<Vec<D>> centre;       ///< current centre of each loaded face
  std::vector<Vec<D>> face_force;   ///< its force T A_s
  std::vector<std::int32_t> group;  ///< its group
  std::vector<Vec<D>> force;        ///< per group: the sum of its faces' forces
  std::vector<Vec<D>> normal;       ///< per group: the sum of its faces' outward normals times area
  /// Empty faces and n_groups zero groups (keeps the storage).
  void reset(std::size_t n_groups) {
    centre.clear();
    face_force.clear();
    group.clear();
    force.assign(n_groups, Vec<D>::Zero());
    normal.assign(n_groups, Vec<D>::Zero());
  }
};

/// The Options the [method] keys of the WLS method give (wls/options.cpp, where they are
/// declared); mirror planes and thickness are the engine's to set.
Options options(const MethodConfig& method);

/// One integration region: the inside part of a cut or full cell (Sec. 3.4) and its values.
template <int D>
struct Region {
  std::int32_t cell = 0;  ///< linear cell index (x fastest) of the cell holding it
  double volume = 0.0;    ///< V_q (times the thickness in 2D)
  Vec<D> centroid = Vec<D>::Zero();
  double density = 0.0;   ///< rho_q (Eq. 19)
  Vec<D> force_density = Vec<D>::Zero();  ///< f_q^ext (Eq. 20)
  Eigen::Matrix<double, D, D> stress = Eigen::Matrix<double, D, D>::Zero();  ///< sigma_q (Eq. 21)
};

template <int D>
class Integrator {
 public:
  Integrator(const Grid<D>& grid, const Options& options);
  [[nodiscard]] const Options& options() const { return options_; }
  /// The particles' stencils and cell-block colouring of the last build_stencils (the engine
  /// keeps a large run's particles in the colouring's block order: Simulation::keep_particles_sorted).
  [[nodiscard]] TransferCache<D>& transfer_cache() { return cache_; }

  /// W, S and G of every particle over the 3^D nodes around its nearest node. Throws
  /// SimulationFailure when a particle left the grid.
  void build_stencils(const Grid<D>& grid, const Particles<D>& particles);

  /// Sec. 4.1-4.5 into `nodes` (mass, momentum, force; velocities and reactions cleared) and,
  /// when given, the external part of the force into `node_body_force`. `density0[m]` is the
  /// reference density of material m; `body_acceleration` (b_p, or null) the body force.
  void collect(const Grid<D>& grid, const Particles<D>& particles, const std::vector<double>& density0,
               const std::vector<Vec<D>>* body_acceleration, NodeField<D>& nodes,
               std::vector<Vec<D>>* node_body_force, bool surface_loads = false);
  /// The loads the engine fills before collect(..., surface_loads = true).
  [[nodiscard]] SurfaceLoads<D>& surface_loads() { return loads_; }
  /// Node forces of the surface loads of the last collect (zero without loads).
  [[nodiscard]] const std::vector<Vec<D>>& surface_force() const { return surface_force_; }

  /// Eq. 27-29 from v = nodes.velocity and v+ = nodes.velocity_new: V += S (v+ - v) (or, with
  /// Options::pic_velocity, V = S v+), x += S v+ dt, and the velocity gradient into particle_velocity_gradient(): Eq. 29
  /// (sum v+ (x) G_ip) or, with Options::quadrature_gradient, the S-interpolated node means of the
  /// integration points' gradients. `held` (per node, bit a: a velocity condition set component
  /// a; null: none) keeps the conditions' values at corners without mass (departure 12).
  /// `impulse` (per node, or null): the contact's first correction as an impulse on the
  /// particles (contact.first_correction = "impulse", docs/contact.md): V' = V + sum S dv_c,
  /// from which Eq. 27's increment proceeds.
  void move_particles(const Grid<D>& grid, const NodeField<D>& nodes, Particles<D>& particles, double dt,
                      const std::vector<std::uint8_t>* held = nullptr, const std::vector<Vec<D>>* impulse = nullptr);

  /// Kinetic-energy budget of the steps so far (docs/wls.md, "Energy budget"), summed over the
  /// move_particles calls with Options::energy_budget (zero without): grid_work = the grid's kinetic energy change from v to v+ (the work of
  /// the node forces; held components do no work), transfer_energy = the particles' kinetic
  /// energy change (Eq. 27-28) beyond it. The particles' kinetic energy has changed by their sum,
  /// so energy_error - transfer_energy is the work of the forces that neither the particles'
  /// strain energy nor the external work accounts for.
  [[nodiscard]] double grid_work() const { return grid_work_; }
  [[nodiscard]] double transfer_energy() const { return transfer_energy_; }
  /// Both sums from a checkpoint.
  void restore_energy_budget(double grid_work, double transfer_energy) {
    grid_work_ = grid_work;
    transfer_energy_ = transfer_energy;
  }

  /// Storage for the components the velocity conditions set per node (bit a: component a), which
  /// the engine fills each step for move_particles (wls/step.cpp).
  [[nodiscard]] std::vector<std::uint8_t>& held_components() { return held_; }

  /// Options::xpic_order = k: the particles' XPIC(k) velocities sum S u_k for the next
  /// move_particles, u_(j+1) = v + u_j - F(S u_j) from u_1 = v (the node velocities, the fits of
  /// this step's collect) at the nodes inside the body (seed 000 Sec. 2.2 with the fit F of
  /// Eq. 7-11 for m^-1 S^T M; wls/xpic.cpp).
  void xpic_projection(const Grid<D>& grid, const std::vector<double>& mass, const std::vector<Vec<D>>& v);

  /// v+ = v + (planar W m-weighted fit of v+ - v over each node and its neighbours with mass),
  /// method.filter_acceleration (docs/wls.md); the caller imposes the velocity conditions again.
  void filter_acceleration(const Grid<D>& grid, NodeField<D>& nodes);

  /// v+ less Options::hourglass_damping times the hourglass part of v+ in every cell whose
  /// corners all carry mass (momentum kept; docs/wls.md); the caller imposes the conditions again.
  void damp_hourglass(const Grid<D>& grid, NodeField<D>& nodes);

  // ---- inspection (tests, snapshots) ----------------------------------------------------------
  [[nodiscard]] const std::vector<double>& signed_distance() const { return distance_; }
  /// 1 where the node's least-squares fit is well conditioned (alpha_i of Eq. 19-21).
  [[nodiscard]] const std::vector<std::uint8_t>& well_conditioned() const { return alpha_; }
  /// Nodes that had particles in their support but were reduced to the constant fit.
  [[nodiscard]] long long spurious_nodes() const { return n_spurious_; }
  [[nodiscard]] const std::vector<Region<D>>& regions() const { return regions_; }
  /// Least-squares node values of the last collect (Eq. 11): velocity, density, stress.
  [[nodiscard]] const std::vector<Vec<D>>& node_velocity() const { return velocity_; }
  [[nodiscard]] const std::vector<double>& node_density() const { return density_; }
  [[nodiscard]] const std::vector<Eigen::Matrix<double, D, D>>& node_stress() const { return stress_; }
  /// beta_i of Eq. 13 (with the mirror images across symmetry planes).
  [[nodiscard]] double node_flag(std::int32_t i) const { return sums_[i].beta; }
  /// Gradient (Eq. 12) of the velocity fit of node i from the last collect; zero where reduced,
  /// and zero unless the options read the velocity fit's slopes (extrapolated_spurious_velocity
  /// or fitted_surface_velocity; fitted_point_values alone reads the other fields' slopes).
  [[nodiscard]] Eigen::Matrix<double, D, D> velocity_gradient_fit(std::int32_t i) const;
  /// Moment matrix M of node i (Eq. 9, r in cells) from the last collect.
  [[nodiscard]] Eigen::Matrix<double, D + 1, D + 1> moment_matrix(std::int32_t i) const;
  /// grad V_p of every particle from the last move_particles (the F and stress update's L).
  [[nodiscard]] const std::vector<Eigen::Matrix<double, D, D>>& particle_velocity_gradient() const {
    return particle_gradient_;
  }
  /// For transpose_gradient: particle p's sum_q V_q T_qp L_q over the integration points of the
  /// last move_particles, and in `weight` sum_q V_q T_qp (T_qp: particle p's weight in the stress
  /// sigma_q of Eq. 19-21, L_q the grid velocity gradient at q). Summed over every particle,
  /// sum_p sigma_p : G_p is the power sum_q V_q sigma_q : L_q of Eq. 24's forces.
  [[nodiscard]] Eigen::Matrix<double, D, D> transposed_gradient_sum(std::size_t p, double& weight) const;
  /// A particle takes the transposed gradient when its weight lies within this factor of V_p.
  static constexpr double transpose_band = 4.0;

 private:
  static constexpr int n_basis = D + 1;
  static constexpr int n_moment = (D + 1) * (D + 2) / 2;
  static constexpr int n_stress = D * (D + 1) / 2;
  /// Fields fitted per node: velocity (D), density (1), stress (D(D+1)/2), body-force density (D).
  static constexpr int n_fields = 2 * D + 1 + n_stress;
  /// Fields per row of the sums, padded to pairs (the scatter adds two fields at a time).
  static constexpr int n_row = n_fields + n_fields % 2;
  /// Position of stress component (a, b) among the n_stress fitted ones: diagonal first, then
  /// (in 3D) yz, xz, xy; in 2D xy.
  static constexpr int voigt(int a, int b) {
    if (a == b) return a;
    if constexpr (D == 2) return 2;
    return 3 + (3 - a - b);  // (1,2) -> 3, (0,2) -> 4, (0,1) -> 5
  }

  void fit_nodes(const Grid<D>& grid);
  /// Multi-index of cell c (linear, axis 0 fastest): D - 1 divisions, the last axis the quotient.
  [[nodiscard]] IVec<D> cell_index(std::int32_t c) const {
    IVec<D> j;
    for (int a = 0; a + 1 < D; ++a) {
      j[a] = c % n_cells_[a];
      c /= n_cells_[a];
    }
    j[D - 1] = c;
    return j;
  }
  /// Coefficient c (0: the value, 1 + a: the slope along a, in cells) of field k's fit at node i.
  [[nodiscard]] double coefficient(std::int32_t i, int k, int c) const {
    return coef_[(static_cast<std::size_t>(i) * n_coef_ + c) * n_row + k];
  }
  /// Field k's planar fit at node i (seed 001 Eq. 10) evaluated at r = (x - x_i) / h, in cells; its value
  /// c0 where the slopes are not formed (n_coef_ = 1) or the fit is reduced (zero slopes).
  [[nodiscard]] double fit_at(std::int32_t i, int k, const Vec<D>& r) const {
    double v = coefficient(i, k, 0);
    if (n_coef_ > 1)
      for (int a = 0; a < D; ++a) v += coefficient(i, k, 1 + a) * r[a];
    return v;
  }
  void extrapolate_spurious_velocity(const Grid<D>& grid);
  void refine_distance(const Grid<D>& grid);
  void build_regions(const Grid<D>& grid);
  void integrate(const Grid<D>& grid, bool body_force, NodeField<D>& nodes, std::vector<Vec<D>>* node_body_force,
                 bool surface_loads);
  void spread_surface_loads(const Grid<D>& grid);
  /// fn(region index) for every integration region, one colour of cells after the other: the
  /// regions of one colour's cells share no corner node, so fn may add to its corners' nodes.
  template <class Fn>
  void for_each_region_coloured(Fn&& fn) const {
    for (const std::vector<std::int32_t>& cells : colour_cells_) {
      const auto n = static_cast<std::int64_t>(cells.size());
#pragma omp parallel for schedule(static)
      for (std::int64_t k = 0; k < n; ++k) {
        const std::int32_t c = cells[static_cast<std::size_t>(k)];
        for (std::int32_t r = cell_begin_[c]; r < cell_begin_[c + 1]; ++r) fn(r);
      }
    }
  }
  /// The grid velocity gradient at region r's point, sum_k v_k (x) G_kq over its cell's corners.
  [[nodiscard]] Eigen::Matrix<double, D, D> point_gradient(std::int32_t r, const std::vector<Vec<D>>& v) const {
    Eigen::Matrix<double, D, D> L = Eigen::Matrix<double, D, D>::Zero();
    for (int k = 0; k < (1 << D); ++k) L += v[corners_[r].node[k]] * corners_[r].G[k].transpose();
    return L;
  }
  /// One pass over the integration regions for the particles' gradients: the quadrature
  /// gradient's S V-weighted node means of L_q and, with transpose_gradient, transposed_gradient_sum's
  /// node sums A_kc = sum_q (V_q / s_q) S_kq beta_c(x_q - x_k) L_q over the points whose value reads
  /// node k's fit, folded with its fit rows: B_ke = sum_c (M_k^-1)_ce A_kc (basis function e).
  void gradient_sums(const Grid<D>& grid, const std::vector<Vec<D>>& v_new);
  void adjoint_point_stress(const Grid<D>& grid, const Particles<D>& particles);
  /// The fitted velocity at x of a particle with stencil (axis_node, axis_S) (move_particles).
  Vec<D> fitted_velocity(const Grid<D>& grid, const std::int32_t* axis_node, const double* axis_S, const Vec<D>& x,
                         const Vec<D>& otherwise) const;

  Options options_;
  Vec<D> h_;
  IVec<D> n_cells_;
  std::array<bool, D> periodic_{};  ///< the grid wraps the axis (positions are not wrapped)
  bool any_periodic_ = false;
  TransferCache<D> cache_;             ///< tensor layout, width 3: node offsets, S and G per axis
  /// n x D: x_p - x_n in cells along each axis, n the particle's nearest node (in [-0.5, 0.5)):
  /// wide_stencil forms its wide weights and offsets from it.
  std::vector<double> local_;
  /// Particle p's wide weights W (seed 001 Eq. 4, h = 1) and offsets r = x_p - x_i in cells of the nodes
  /// nearest - 1, nearest, nearest + 1 along each axis (3 per axis, axis-major): recomputed from
  /// local_ where they are read rather than stored (D doubles per particle instead of 6 D; the same bits:
  /// x_p - x_i = (x_p - x_n) + (n - i) rounds the same real number, x_p - x_n being exact).
  [[gnu::always_inline]] void wide_stencil(std::size_t p, double* axis_W, double* axis_r) const {
    const double* local = &local_[p * D];
    for (int a = 0; a < D; ++a) {
      const double r1 = local[a];
      const double r0 = r1 + 1.0, r2 = r1 - 1.0;
      axis_r[3 * a] = r0;
      axis_r[3 * a + 1] = r1;
      axis_r[3 * a + 2] = r2;
      // Eq. 4 with h = 1 on each node's known branch (wide_weight(r, 1) to the bit; at r = -0.5
      // both branches give 0.5, at r = -1.5 both give 0).
      const double w0 = 1.5 - std::abs(r0), w2 = 1.5 - std::abs(r2);
      axis_W[3 * a] = w0 * w0 / 2.0;
      axis_W[3 * a + 1] = 0.75 - r1 * r1;
      axis_W[3 * a + 2] = w2 * w2 / 2.0;
    }
  }
  std::vector<double> particle_fields_;///< n x n_row per-particle values of the step
  // node accumulators and results
  /// What each stencil entry adds to its node in the moment pass, in one place (one cache line in
  /// 2D): the moment matrix M of Eq. 9 (packed upper triangle), the largest W (Sec. 3.5) and the
  /// flag sum beta_i (Eq. 13).
  struct alignas(D == 2 ? 64 : 32) NodeSums {
    std::array<double, n_moment> moment;
    double max_weight;
    double beta;
  };
  std::vector<NodeSums> sums_;
  std::vector<std::int32_t> count_;
  std::vector<Vec<D>> surface_sum_;    ///< sum S x over surface particles
  std::vector<double> surface_weight_; ///< sum S over surface particles
  std::vector<Vec<D>> velocity_;
  std::vector<double> density_;
  std::vector<Vec<D>> force_density_;
  std::vector<Eigen::Matrix<double, D, D>> stress_;
  std::vector<Eigen::Matrix<double, D, D>> node_stress_power_;  ///< N_k of adjoint_point_stress
  std::vector<double> node_volume_;                           ///< W_k of adjoint_point_stress
  std::vector<std::uint8_t> held_;  ///< held_components()
  /// n_nodes x n_coef_ x n_basis: the first n_coef_ rows of each node's M^-1 (Eq. 10).
  std::vector<double> inverse_rows_;
  /// n_nodes x n_coef_ x n_row (field fastest): c = M^-1 l of each field (Eq. 10), r in cells
  /// (during collect's fits, the loads l of the fields whose slopes are read).
  std::vector<double> coef_;
  int n_coef_ = 1;  ///< coefficients fitted: 1 (the values) or n_basis (with the slopes)
  std::vector<std::uint8_t> alpha_;
  std::vector<std::uint8_t> live_;     ///< a particle reached the node at its last fit
  std::vector<double> distance_;
  std::vector<Vec<D>> internal_force_;
  SurfaceLoads<D> loads_;
  std::vector<Vec<D>> surface_vector_;  ///< a_i = sum_q G_iq V_q (the surface integral of S_i n)
  std::vector<Vec<D>> surface_force_;   ///< node forces of the surface loads
  std::vector<std::int32_t> load_stamp_;  ///< scratch of spread_surface_loads
  std::vector<std::int32_t> load_nodes_;
  long long n_spurious_ = 0;
  double grid_work_ = 0.0;        ///< grid_work()
  double transfer_energy_ = 0.0;  ///< transfer_energy()
  // cells
  std::vector<std::int32_t> cell_begin_;  ///< n_cells_total + 1 offsets into regions_
  std::vector<std::vector<std::int32_t>> colour_cells_;  ///< the cells by colour (constructor)
  std::vector<Region<D>> regions_;
  /// Per region its cell's corner nodes (bit a of k: upper along a) and their S, G at the point.
  struct Corners {
    std::array<std::int32_t, (1 << D)> node;
    std::array<double, (1 << D)> S;
    std::array<Vec<D>, (1 << D)> G;
  };
  std::vector<Corners> corners_;
  /// The corners whose fits give a region's values (Eq. 19-21: the well-conditioned ones, or all
  /// where none is; bit k for corner k), and in `sum` their sum of S_kq: the rule build_regions'
  /// two passes apply (TransposedGradientSumsAreThePowerOfTheForces fails where they differ).
  [[nodiscard]] unsigned value_corners(const Corners& corner, double& sum) const {
    unsigned mask = 0;
    sum = 0.0;
    for (int k = 0; k < (1 << D); ++k)
      if (alpha_[corner.node[k]]) {
        mask |= 1U << k;
        sum += corner.S[k];
      }
    if (sum > 0.0) return mask;
    for (int k = 0; k < (1 << D); ++k) sum += corner.S[k];
    return (1U << (1 << D)) - 1;
  }
  /// n_nodes x n_basis: B_ke (gradient_sums), its D x D entries (column-major) and last the same
  /// sum without L_q (the weight), side by side for the gather.
  using TransposeSum = Eigen::Matrix<double, D * D + 1, 1>;
  std::vector<TransposeSum, Eigen::aligned_allocator<TransposeSum>> transpose_sum_;
  std::vector<Eigen::Matrix<double, D, D>> node_gradient_;    ///< its S V-weighted node means
  std::vector<double> node_gradient_weight_;                  ///< sum S V around each node
  std::vector<Eigen::Matrix<double, D, D>> particle_gradient_;  ///< grad V_p (move_particles)
  std::vector<Vec<D>> filtered_;                              ///< scratch of filter_acceleration
  /// out_p = sum S_ip u_i over the corners of particle p's cell (Eq. 5).
  void interpolate(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& out) const;
  std::vector<Vec<D>> xpic_node_;      ///< u_j (xpic_projection)
  std::vector<Vec<D>> xpic_fit_;       ///< F(S u_j)
  std::vector<Vec<D>> xpic_particle_;  ///< S u_j; after xpic_projection the particles' S u_k
};

/// The integration regions as points for a snapshot (ParaView): position = centroid, volume0 =
/// V_q, mass = rho_q V_q, Cauchy stress sigma_q (F = I, so it is also the "Kirchhoff" stress),
/// body = linear cell index, material = number of the region within its cell.
template <int D>
Particles<D> region_points(const Integrator<D>& integrator);

}  // namespace cairn::wls
