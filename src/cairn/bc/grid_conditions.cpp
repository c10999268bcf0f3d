#include "cairn/bc/grid_conditions.hpp"

#include "cairn/util/parallel.hpp"

namespace cairn {

template <int D>
GridConditions<D>::GridConditions(const BoundaryConfig& boundary, const Grid<D>& grid, FaceBasis basis)
    : acceleration_(boundary.acceleration) {
  const IVec<D> n = grid.n_cells();
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    const IVec<D> j = grid.multi_index(i);
    std::uint8_t held = 0, negate = 0;
    bool ghost_of_fixed = false;
    IVec<D> source = j;
    for (int a = 0; a < D; ++a) {
      for (int side = 0; side < 2; ++side) {
        const FaceCondition c = boundary.face[2 * a + side];
        if (c == FaceCondition::free || c == FaceCondition::periodic) continue;
        // Distance beyond the face in nodes: 0 on the face, > 0 for ghost nodes.
        const int beyond = side == 0 ? -j[a] : j[a] - n[a];
        if (beyond < 0) continue;
        if (basis == FaceBasis::open_knot && beyond > 0) continue;  // extra interior functions
        if (c == FaceCondition::fixed) {
          held |= static_cast<std::uint8_t>((1u << D) - 1u);
          ghost_of_fixed |= beyond > 0;
        } else if (beyond == 0) {
          held |= static_cast<std::uint8_t>(1u << a);  // symmetry: normal component on the face
        } else {
          negate |= static_cast<std::uint8_t>(1u << a);  // symmetry ghost: mirror across the face
          source[a] = side == 0 ? -j[a] : 2 * n[a] - j[a];
        }
      }
    }
    if (negate && !ghost_of_fixed) {
      const std::int32_t s = grid.node_index(source);
      if (s >= 0) mirrors_.push_back({i, s, negate});
      else held |= static_cast<std::uint8_t>((1u << D) - 1u);  // mirror image not stored: hold it
    }
    if (held) {
      nodes_.push_back(i);
      mask_.push_back(held);
    }
  }
  mirrored_.resize(mirrors_.size());
}

template <int D>
void GridConditions<D>::apply(std::vector<Vec<D>>& velocity, const std::vector<double>& mass,
                              std::vector<Vec<D>>* reaction, double dt, std::int32_t offset) const {
  const auto n_held = static_cast<std::int64_t>(nodes_.size());
#pragma omp parallel for schedule(static) if (n_held >= parallel_min_items)
  for (std::int64_t k = 0; k < n_held; ++k) {
    const std::int32_t i = nodes_[k] + offset;
    for (int a = 0; a < D; ++a) {
      if (!(mask_[k] & (1u << a))) continue;
      // seed 000 Sec. 2.4: a^(b) dt = (v^(b) - v^UL . n) n; the reaction is m a^(b)
      if (reaction) (*reaction)[i][a] += mass[i] * (0.0 - velocity[i][a]) / dt;
      velocity[i][a] = 0.0;
    }
  }
  // Held components first; then all mirror images are read before any is written, so the result
  // does not depend on the order of the lists.
  const auto n_mirrors = static_cast<std::int64_t>(mirrors_.size());
#pragma omp parallel for schedule(static) if (n_mirrors >= parallel_min_items)
  for (std::int64_t k = 0; k < n_mirrors; ++k) {
    const Mirror& m = mirrors_[k];
    Vec<D> v = velocity[m.source + offset];
    for (int a = 0; a < D; ++a)
      if (m.negate & (1u << a)) v[a] = -v[a];
    mirrored_[k] = v;
  }
#pragma omp parallel for schedule(static) if (n_mirrors >= parallel_min_items)
  for (std::int64_t k = 0; k < n_mirrors; ++k) {
    const std::int32_t i = mirrors_[k].node + offset;
    if (reaction) (*reaction)[i] += mass[i] * (mirrored_[k] - velocity[i]) / dt;
    velocity[i] = mirrored_[k];
  }
}

template class GridConditions<1>;
template class GridConditions<2>;
template class GridConditions<3>;

}  // namespace cairn
