// Velocity conditions on grid nodes from the [boundary] faces: `fixed` holds every component at
// zero on the face nodes and the ghost nodes beyond; `symmetry` holds the normal component;
// `periodic` is handled by the grid's wrap and needs nothing here.
//
// apply() is used on both grid velocities of a step (v = m^-1 p and v+ = m^-1 p+) so that the
// particle update sees consistent values; on v+ it also records the reaction force
// m (v_b - v^UL) / dt of seed 000 Sec. 2.4.
#pragma once

#include <cstdint>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/io/config.hpp"

namespace cairn {

template <int D>
class GridConditions {
 public:
  GridConditions() = default;
  GridConditions(const BoundaryConfig& boundary, const Grid<D>& grid);

  /// Impose the conditions on one velocity field; if `reaction` is given, add
  /// m (v_imposed - v_before) / dt to it.
  void apply(std::vector<Vec<D>>& velocity, const std::vector<double>& mass,
             std::vector<Vec<D>>* reaction, double dt) const;

  /// The step's use: impose on v = m^-1 p and on v+ = m^-1 p+ (recording reactions from v+).
  void apply_step(NodeField<D>& nodes, double dt) const {
    apply(nodes.velocity, nodes.mass, nullptr, dt);
    apply(nodes.velocity_new, nodes.mass, &nodes.reaction, dt);
  }

  [[nodiscard]] bool empty() const { return nodes_.empty(); }
  [[nodiscard]] const std::vector<std::int32_t>& nodes() const { return nodes_; }

 private:
  std::vector<std::int32_t> nodes_;  ///< controlled nodes
  std::vector<std::uint8_t> mask_;   ///< bit a set: component a held at zero
};

}  // namespace cairn
