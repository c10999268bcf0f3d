// The reference explicit FEM of seed 001 Appendix A: linear triangles with one-point
// integration, lumped mass (Eq. A2), internal forces from the Cauchy stress of the element's
// deformation gradient (Eq. A3-A4), nodal accelerations with the body force (Eq. A1) and the
// central-difference update (Eq. A5-A6), written as velocity Verlet (docs/fem.md).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cairn/bc/expression.hpp"
#include "cairn/bc/time_function.hpp"
#include "cairn/fem/mesh.hpp"
#include "cairn/config/config.hpp"
#include "cairn/materials/material.hpp"

namespace cairn::fem {

/// A velocity condition on a node set: the component along `direction` is `velocity(t)`.
struct NodeCondition {
  std::string name;                ///< "" for [boundary] faces (no history column)
  std::vector<std::int32_t> nodes;
  Vec<2> direction = Vec<2>::UnitX();
  std::shared_ptr<TimeFunction> velocity;  ///< value along direction, a function of t
};

struct FemTotals {
  double kinetic_energy = 0.0, strain_energy = 0.0, mass = 0.0, max_pressure = 0.0;
  Vec3 momentum = Vec3::Zero();
};

class Solver {
 public:
  /// Builds the mesh the config describes (fem.mesh_file or fem.shape), the material, the
  /// lumped masses, the node conditions and the initial state. Throws InputError for a bad mesh.
  explicit Solver(const Config& config);
  /// The same with a given mesh (tests), which is checked first.
  Solver(const Config& config, TriangleMesh mesh);

  /// Eq. 34 with the smallest element altitude of the current mesh as h, or simulation.dt.
  [[nodiscard]] double next_dt() const;
  /// One step of Eq. A5-A6 (velocity Verlet: half kick, drift, forces, half kick). Throws
  /// SimulationFailure (element index) when an element inverts or a value is not finite.
  void step(double dt);

  [[nodiscard]] FemTotals totals() const;
  [[nodiscard]] double time() const { return time_; }
  [[nodiscard]] long long step_count() const { return step_; }
  [[nodiscard]] double external_work() const { return external_work_; }
  /// With fem.exact_displacement: max over nodes of |x - X - u_exact(X, t)| now (seed 001
  /// Eq. 38), and its maximum over every step so far; 0 without.
  [[nodiscard]] double displacement_error() const { return error_now_; }
  [[nodiscard]] double displacement_error_max() const { return error_max_; }
  [[nodiscard]] bool has_exact_displacement() const { return exact_ != nullptr; }

  [[nodiscard]] const TriangleMesh& mesh() const { return mesh_; }
  [[nodiscard]] const std::vector<Vec<2>>& positions() const { return x_; }
  [[nodiscard]] const std::vector<Vec<2>>& velocities() const { return v_; }
  [[nodiscard]] const std::vector<Vec<2>>& accelerations() const { return a_; }
  [[nodiscard]] const std::vector<double>& masses() const { return mass_; }
  [[nodiscard]] const std::vector<Mat3>& deformation_gradients() const { return F_; }
  [[nodiscard]] const std::vector<Mat3>& kirchhoff_stresses() const { return tau_; }
  [[nodiscard]] const std::vector<double>& reference_volumes() const { return volume0_; }
  [[nodiscard]] const Material& material() const { return *material_; }
  /// Sum of the condition forces on the nodes of each named [[velocity]] condition (last step).
  [[nodiscard]] const std::vector<NodeCondition>& conditions() const { return conditions_; }
  [[nodiscard]] std::vector<Vec<2>> reactions() const;

  /// Restart: the state a checkpoint holds.
  struct State {
    double time = 0.0, external_work = 0.0, error_now = 0.0, error_max = 0.0;
    long long step = 0;
    std::vector<Vec<2>> x, v, a, b, reaction;  ///< b: body force; reaction: condition forces
    std::vector<Mat3> F, tau;
    std::vector<double> element_state, temperature;
  };
  [[nodiscard]] State state() const;
  /// Throws std::invalid_argument when the sizes do not match this mesh.
  void restore(const State& s);

 private:
  void setup();
  /// Stress of every element at the current positions (v_ is the velocity that moved them).
  void update_stresses(double dt);
  /// a = f_int / M + b (Eq. A1) at the current state, then the conditions; the condition
  /// forces go to reaction_.
  void compute_accelerations();
  void apply_conditions(std::vector<Vec<2>>& v, double t) const;
  [[nodiscard]] double condition_velocity(const NodeCondition& c, double t) const;
  [[nodiscard]] Vec<2> body_force(std::size_t i, double t);

  Config config_;
  TriangleMesh mesh_;
  std::unique_ptr<Material> material_;
  Mode mode_ = Mode::plane_strain;
  double thickness_ = 1.0;
  // nodes
  std::vector<Vec<2>> x_, v_, a_, b_, reaction_;
  std::vector<double> mass_;
  std::vector<std::int32_t> node_first_, node_elem_;  ///< CSR node -> (element * 3 + local)
  // elements
  std::vector<Eigen::Matrix<double, 2, 3>> grad0_;  ///< reference shape-function gradients (columns)
  std::vector<double> volume0_;
  std::vector<Mat3> F_, tau_;
  std::vector<double> element_state_, temperature_;
  std::vector<Vec<2>> element_force_;  ///< 3 per element
  int n_state_ = 0;
  // loads and conditions
  std::unique_ptr<ExpressionVector<2>> body_force_, exact_;
  double error_now_ = 0.0, error_max_ = 0.0;
  void measure_error();
  std::vector<NodeCondition> conditions_;
  double time_ = 0.0, external_work_ = 0.0;
  long long step_ = 0;
};

}  // namespace cairn::fem
