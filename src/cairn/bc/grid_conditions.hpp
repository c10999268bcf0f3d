// Velocity conditions on grid nodes from the [boundary] faces (seed 003 Sec. 3.4):
//   fixed     (Dirichlet, zero velocity) every component of the face nodes and of the ghost nodes
//             beyond the face is held at zero (seed 003 Sec. 3.4.2: ghost nodes are treated like
//             the boundary nodes);
//   symmetry  the normal component of the face nodes is held at zero; a ghost node beyond the
//             face takes the velocity of the node mirrored across the face with the normal
//             component negated (seed 003 Sec. 3.4.2), so that wide stencils see the mirror image;
//   periodic  handled by the grid's wrap, nothing here;
//   free      nothing.
// For open-knot boundary splines (FaceBasis::open_knot) only the face value is constrained: it
// belongs to the one basis function that is non-zero on the face, so the condition holds exactly
// on the face, and the ghost slots hold interior functions that stay free.
//
// Acceleration at constrained nodes ([boundary] acceleration): the particle update uses
// S (v+ - v) as the velocity increment, so the option decides what v is there:
//   zero             v and v+ are both constrained: no acceleration at held components (default);
//   velocity_change  only v+ is constrained and v keeps the projected m^-1 p, so the increment is
//                    the velocity change to the prescribed value (seed 003 Eq. 30).
// apply() imposes every condition on one velocity field; when `reaction` is given it adds the
// force m (v_after - v_before) / dt that the conditions exert (seed 000 Sec. 2.4).
#pragma once

#include <cstdint>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/shapes/shape_family.hpp"

namespace cairn {

template <int D>
class GridConditions {
 public:
  GridConditions() = default;
  GridConditions(const BoundaryConfig& boundary, const Grid<D>& grid,
                 FaceBasis basis = FaceBasis::ghost_nodes);

  /// Impose the conditions on one velocity field; if `reaction` is given, add
  /// m (v_imposed - v_before) / dt to it. `offset` shifts every node index (the field of a
  /// multimaterial run: entries field * n_nodes + node).
  void apply(std::vector<Vec<D>>& velocity, const std::vector<double>& mass,
             std::vector<Vec<D>>* reaction, double dt, std::int32_t offset = 0) const;

  /// The step's use: impose on v+ = m^-1 p+ (recording reactions) and, with the default
  /// acceleration option `zero`, also on v = m^-1 p.
  void apply_step(NodeField<D>& nodes, double dt, std::int32_t offset = 0) const {
    if (acceleration_ == BoundaryAcceleration::zero) apply(nodes.velocity, nodes.mass, nullptr, dt, offset);
    apply(nodes.velocity_new, nodes.mass, &nodes.reaction, dt, offset);
  }

  [[nodiscard]] bool empty() const { return nodes_.empty() && mirrors_.empty(); }
  /// Nodes with held components (face nodes, ghost nodes beyond fixed faces).
  [[nodiscard]] const std::vector<std::int32_t>& nodes() const { return nodes_; }
  /// Bit a set: component a of nodes()[k] is held at zero.
  [[nodiscard]] const std::vector<std::uint8_t>& masks() const { return mask_; }

  /// A ghost node beyond a symmetry face that copies its mirror image.
  struct Mirror {
    std::int32_t node;    ///< the ghost node
    std::int32_t source;  ///< the node mirrored across every symmetry face the ghost lies beyond
    std::uint8_t negate;  ///< bit a set: component a is negated (normal of a crossed face)
  };
  [[nodiscard]] const std::vector<Mirror>& mirrors() const { return mirrors_; }

 private:
  std::vector<std::int32_t> nodes_;  ///< constrained nodes
  std::vector<std::uint8_t> mask_;   ///< bit a set: component a held at zero
  std::vector<Mirror> mirrors_;
  mutable std::vector<Vec<D>> mirrored_;  ///< scratch: mirror values read before any is written
  BoundaryAcceleration acceleration_ = BoundaryAcceleration::zero;
};

}  // namespace cairn
