// A moving wall normal to x, y or z (seed 000 Sec. 2.5, Fig. 1B, Eq. 4).
//
// The wall has a position x_wall(t), a velocity v_b(t) along its axis and a gradient grad v_b.
// Each step it controls the axis component of the grid velocity on
//   - every node inside the material within depth d (cells) of the wall, 0 <= depth <= d h, and
//   - every node outside the wall that carries mass
// (nodes without mass, e.g. beside the body along the wall, carry no velocity and are skipped),
// setting v_i = v_b + grad v_b (x_i - x_wall). The gradient is given (an expression in t), zero,
// or estimated by Eq. 4 from the velocities m^-1 p extrapolated to nodes 1 and 2 of Fig. 1B (the
// last uncontrolled and the first controlled node inside the material, or the two shallowest
// inside nodes when no inside node is controlled):
//     grad v_b = (dv1 dx1 + dv2 dx2) / (dx1^2 + dx2^2),  dv = v - v_b,  dx = x - x_wall.
// In 2D and 3D the wall is a row or plane of nodes; Eq. 4 is applied per line of nodes along the
// axis and the lines are averaged with the weights m1 + m2 of their two nodes (one line in 1D is
// exactly Eq. 4). The wall moves with v_b: x_wall += (v_b(t) + v_b(t + dt)) dt / 2.
//
// The start-of-step values use v_b(t), the gradient at t and x_wall(t); the end-of-step values
// v_b(t + dt), the gradient at t + dt (the same estimate for `estimate`) and x_wall(t + dt), on
// the node set chosen at the start of the step.
#pragma once

#include <string>
#include <vector>

#include "cairn/bc/prescribed_velocity.hpp"
#include "cairn/bc/time_function.hpp"
#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/parallel/comm.hpp"

namespace cairn {

template <int D>
class MovingWall {
 public:
  /// Throws std::invalid_argument naming the wall when an expression is bad or the wall's axis is
  /// periodic.
  MovingWall(const WallConfig& config, const Grid<D>& grid, const Constants& constants);

  /// Choose this step's controlled nodes, the gradient and the start/end values, and append them
  /// to `out` with owner index `owner`. Throws SimulationFailure when the wall has left the grid.
  /// The estimated gradient sums over the lines of nodes `grid` owns and over the ranks of
  /// `comm` (collective when it has more than one).
  void prepare(const Grid<D>& grid, const NodeField<D>& nodes, double small_mass, double t, double dt,
               std::int32_t owner, std::vector<PrescribedVelocity<D>>& out, const Comm& comm = Comm::serial());
  /// The step is done: the wall moves to its end-of-step position.
  void finish_step() { position_ = position_end_; }

  [[nodiscard]] const std::string& name() const { return config_.name; }
  [[nodiscard]] int axis() const { return config_.axis; }
  [[nodiscard]] double position() const { return position_; }
  void set_position(double x) { position_ = position_end_ = x; }
  /// Velocity and gradient used at the start of the last prepared step.
  [[nodiscard]] double velocity() const { return velocity_start_; }
  [[nodiscard]] double gradient() const { return gradient_start_; }

 private:
  WallConfig config_;
  TimeFunction velocity_, gradient_;
  double position_ = 0.0, position_end_ = 0.0;
  double velocity_start_ = 0.0, gradient_start_ = 0.0;
};

}  // namespace cairn
