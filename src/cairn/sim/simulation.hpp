// Simulation<D>: owns the state of one run (grid, node fields, particles, materials, transfer
// cache) and advances it by explicit steps. The step is a list of named stages that follow seed
// 000 Table 1; the run loop with outputs lives in sim/run.hpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cairn/bc/expression.hpp"
#include "cairn/bc/grid_conditions.hpp"
#include "cairn/grid/grid.hpp"
#include "cairn/io/config.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/particles/particles.hpp"
#include "cairn/schemes/scheme.hpp"
#include "cairn/shapes/shape_family.hpp"
#include "cairn/transfer/cache.hpp"

namespace cairn {

/// Global sums reported in history.csv.
struct Totals {
  double kinetic_energy = 0.0;
  double strain_energy = 0.0;
  Vec3 momentum = Vec3::Zero();
  double mass = 0.0;
};

template <int D>
class Simulation {
 public:
  /// Build grid, materials and particles from a validated config. Throws std::invalid_argument
  /// for inputs that pass key validation but cannot be set up (e.g. a body with no particle).
  explicit Simulation(const Config& config);
  ~Simulation();

  // ---- one explicit step (seed 000 Table 1) -------------------------------------------------
  /// dt from the CFL rule (seed 001 Eq. 34) or the fixed step, not beyond end_time.
  [[nodiscard]] double next_dt() const;
  /// Advance by dt: the stages below in order.
  void step(double dt);

  void build_stencils();                 ///< shapes: S_pi, G_pi into the cache; colouring
  void particles_to_grid();              ///< Tasks 1-2: m, p, f = -G^T V0 tau + S^T M B
  void update_grid(double dt);           ///< Task 3: p+ = p + f dt, v = m^-1 p, v+ = m^-1 p+, BCs
  void update_particles(double dt);      ///< Task 4: the update scheme moves the particles
  void update_stresses(double dt);       ///< Task 5: grad V = sum v+ (x) G, dF = exp(grad V dt)

  // ---- state ----------------------------------------------------------------------------------
  [[nodiscard]] const Config& config() const { return config_; }
  [[nodiscard]] const Grid<D>& grid() const { return grid_; }
  [[nodiscard]] const NodeField<D>& nodes() const { return nodes_; }
  [[nodiscard]] Particles<D>& particles() { return particles_; }
  [[nodiscard]] const Particles<D>& particles() const { return particles_; }
  [[nodiscard]] const TransferCache<D>& cache() const { return cache_; }
  [[nodiscard]] const std::vector<std::unique_ptr<Material>>& materials() const { return materials_; }
  [[nodiscard]] double time() const { return time_; }
  [[nodiscard]] long long step_count() const { return step_; }
  /// Work done on the particles by body forces and velocity conditions so far.
  [[nodiscard]] double external_work() const { return external_work_; }
  void restore_counters(double time, long long step, double external_work) {
    time_ = time;
    step_ = step;
    external_work_ = external_work;
  }
  [[nodiscard]] Totals totals() const;

 private:
  void setup_grid();
  void compute_body_forces();
  Mat3 stress_for(std::size_t p, const Mat3& L, double dt);

  Config config_;
  Mode mode_;
  Grid<D> grid_;
  NodeField<D> nodes_;
  std::vector<Vec<D>> node_body_force_;  ///< S^T M B part of f, for the external-work tally
  Particles<D> particles_;
  TransferCache<D> cache_;
  std::vector<std::unique_ptr<Material>> materials_;
  std::unique_ptr<ShapeFamily<D>> shape_;
  std::unique_ptr<UpdateScheme<D>> scheme_;
  std::vector<std::unique_ptr<ExpressionVector<D>>> body_force_;  ///< one per thread
  bool body_force_constant_ = false;
  Vec<D> body_force_value_ = Vec<D>::Zero();
  std::vector<Vec<D>> body_acceleration_;  ///< b_p of this step
  GridConditions<D> conditions_;           ///< velocity conditions from [boundary]
  double small_mass_ = 0.0;
  double time_ = 0.0;
  long long step_ = 0;
  double external_work_ = 0.0;
};

/// Fill `particles` from the [[body]] tables (sim/bodies.cpp).
template <int D>
void create_particles(const Config& config, const Grid<D>& grid,
                      const std::vector<std::unique_ptr<Material>>& materials, Mode mode,
                      Particles<D>& particles);

}  // namespace cairn
