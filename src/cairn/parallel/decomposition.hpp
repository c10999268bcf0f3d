// Domain decomposition of the grid's cells into one box per rank (docs/parallel.md).
//
// Recursive coordinate bisection over the particle distribution: the cells [0, n_cells) are
// split along their longest axis at the cell plane that divides the particles' weight (their
// count, or their cost: docs/parallel.md, "Load balance") in proportion to the ranks on either
// side (a global histogram of weight per cell slab, summed over the ranks), and each half is
// split again until every rank has a box. A rebalance keeps the tree (its axes) and moves only
// the cuts whose halves are out of balance by more than a tolerance, so that particles change
// rank only where the balance needs it. Particles are owned by the
// rank whose box holds their cell; nodes by the rank whose box holds the cell they are the lower
// corner of (Grid::owns). Every rank computes the same boxes from the same global histograms.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cairn/math/types.hpp"
#include "cairn/parallel/comm.hpp"

namespace cairn {

/// Cells [lo, hi) along each axis.
template <int D>
struct CellBox {
  IVec<D> lo = IVec<D>::Zero();
  IVec<D> hi = IVec<D>::Zero();
  [[nodiscard]] long long n_cells() const {
    long long n = 1;
    for (int a = 0; a < D; ++a) n *= hi[a] - lo[a];
    return n;
  }
};

template <int D>
class Decomposition {
 public:
  /// One box holding every cell (a serial run).
  Decomposition() = default;
  Decomposition(const IVec<D>& n_cells, const std::array<bool, D>& periodic);

  /// Bisect the cells into `n_boxes` boxes (0: one per rank of `comm`) so that each holds about
  /// the same weight; `cells` are the cells of this rank's particles (any cell: cells beyond a
  /// face count for the boundary cell, periodic axes wrap) and `weights` their integer weights
  /// (empty: 1 each, i.e. particle counts). Collective: the histograms are summed over `comm`,
  /// and every rank computes the same boxes; integer sums make them independent of how the
  /// particles are spread over the ranks. Throws std::invalid_argument when the grid has fewer
  /// cells than boxes.
  static Decomposition bisect(const Comm& comm, const IVec<D>& n_cells, const std::array<bool, D>& periodic,
                              const std::vector<IVec<D>>& cells, const std::vector<std::int64_t>& weights = {},
                              int n_boxes = 0);
  /// The same tree (cut axes, boxes per side) with each cut moved only where its two sides are
  /// out of balance: a cut is kept when the weight per box on either side is within
  /// `tolerance` (a fraction) of the mean of the pair, else moved to the balancing plane.
  /// Arguments and collectiveness as for bisect.
  [[nodiscard]] Decomposition rebalanced(const Comm& comm, const std::vector<IVec<D>>& cells,
                                         const std::vector<std::int64_t>& weights, double tolerance) const;

  [[nodiscard]] int n_boxes() const { return static_cast<int>(boxes_.size()); }
  [[nodiscard]] const CellBox<D>& box(int rank) const { return boxes_[static_cast<std::size_t>(rank)]; }
  /// The cell inside the domain that stands for `cell`: wrapped on periodic axes, clamped onto
  /// the boundary cells on the others.
  [[nodiscard]] IVec<D> domain_cell(IVec<D> cell) const;
  /// Rank owning `cell` (any cell, as domain_cell).
  [[nodiscard]] int owner(const IVec<D>& cell) const;
  /// Whether `cell` (a domain cell) lies in box `rank` widened by `width` cells on every side,
  /// wrapping periodic axes.
  [[nodiscard]] bool near(int rank, const IVec<D>& cell, int width) const;
  /// Ranks other than `rank` whose boxes lie less than `width` cells from box `rank` (symmetric).
  [[nodiscard]] std::vector<int> neighbours(int rank, int width) const;

 private:
  struct Cut {
    int axis = -1;  ///< -1: a leaf
    int at = 0;     ///< cells below `at` go to `below`
    int below = -1, above = -1;
    int rank = 0;   ///< leaves: the rank
  };
  static Decomposition build(const Comm& comm, int n_boxes, const IVec<D>& n_cells,
                             const std::array<bool, D>& periodic, const std::vector<IVec<D>>& cells,
                             const std::vector<std::int64_t>& weights, const Decomposition* previous,
                             double tolerance);
  IVec<D> n_cells_ = IVec<D>::Ones();
  std::array<bool, D> periodic_{};
  std::vector<CellBox<D>> boxes_{CellBox<D>{IVec<D>::Zero(), IVec<D>::Ones()}};
  std::vector<Cut> cuts_{Cut{}};
};

}  // namespace cairn
