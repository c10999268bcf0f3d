#include "cairn/bc/grid_conditions.hpp"

namespace cairn {

template <int D>
GridConditions<D>::GridConditions(const BoundaryConfig& boundary, const Grid<D>& grid) {
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    const IVec<D> j = grid.multi_index(i);
    std::uint8_t mask = 0;
    for (int a = 0; a < D; ++a) {
      for (int side = 0; side < 2; ++side) {
        const FaceCondition c = boundary.face[2 * a + side];
        const bool beyond = side == 0 ? j[a] <= 0 : j[a] >= grid.n_cells()[a];
        if (!beyond || c == FaceCondition::free || c == FaceCondition::periodic) continue;
        mask |= (c == FaceCondition::fixed) ? static_cast<std::uint8_t>((1u << D) - 1u)
                                            : static_cast<std::uint8_t>(1u << a);
      }
    }
    if (mask) {
      nodes_.push_back(i);
      mask_.push_back(mask);
    }
  }
}

template <int D>
void GridConditions<D>::apply(std::vector<Vec<D>>& velocity, const std::vector<double>& mass,
                              std::vector<Vec<D>>* reaction, double dt) const {
  const auto n = static_cast<std::int64_t>(nodes_.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t k = 0; k < n; ++k) {
    const std::int32_t i = nodes_[k];
    for (int a = 0; a < D; ++a) {
      if (!(mask_[k] & (1u << a))) continue;
      // seed 000 Sec. 2.4: a^(b) dt = (v^(b) - v^UL . n) n; the reaction is m a^(b)
      if (reaction) (*reaction)[i][a] += mass[i] * (0.0 - velocity[i][a]) / dt;
      velocity[i][a] = 0.0;
    }
  }
}

template class GridConditions<1>;
template class GridConditions<2>;
template class GridConditions<3>;

}  // namespace cairn
