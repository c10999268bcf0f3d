#include "cairn/parallel/decomposition.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace cairn {

template <int D>
Decomposition<D>::Decomposition(const IVec<D>& n_cells, const std::array<bool, D>& periodic)
    : n_cells_(n_cells), periodic_(periodic), boxes_{CellBox<D>{IVec<D>::Zero(), n_cells}} {}

template <int D>
IVec<D> Decomposition<D>::domain_cell(IVec<D> cell) const {
  for (int a = 0; a < D; ++a) {
    if (periodic_[a]) {
      cell[a] %= n_cells_[a];
      if (cell[a] < 0) cell[a] += n_cells_[a];
    } else {
      cell[a] = std::clamp(cell[a], 0, n_cells_[a] - 1);
    }
  }
  return cell;
}

template <int D>
int Decomposition<D>::owner(const IVec<D>& cell) const {
  const IVec<D> c = domain_cell(cell);
  int k = 0;
  while (cuts_[static_cast<std::size_t>(k)].axis >= 0) {
    const Cut& cut = cuts_[static_cast<std::size_t>(k)];
    k = c[cut.axis] < cut.at ? cut.below : cut.above;
  }
  return cuts_[static_cast<std::size_t>(k)].rank;
}

template <int D>
bool Decomposition<D>::near(int rank, const IVec<D>& cell, int width) const {
  const CellBox<D>& b = box(rank);
  for (int a = 0; a < D; ++a) {
    const int span = b.hi[a] - b.lo[a] + 2 * width;
    if (periodic_[a]) {
      if (span >= n_cells_[a]) continue;
      int d = (cell[a] - (b.lo[a] - width)) % n_cells_[a];
      if (d < 0) d += n_cells_[a];
      if (d >= span) return false;
    } else if (cell[a] < b.lo[a] - width || cell[a] >= b.hi[a] + width) {
      return false;
    }
  }
  return true;
}

template <int D>
std::vector<int> Decomposition<D>::neighbours(int rank, int width) const {
  // Boxes a and b are neighbours when a widened by `width` meets b: they are less than `width`
  // cells apart, the same test both ways, so the lists are symmetric.
  std::vector<int> out;
  const CellBox<D>& mine = box(rank);
  for (int r = 0; r < n_boxes(); ++r) {
    if (r == rank) continue;
    const CellBox<D>& other = box(r);
    bool meet = true;
    for (int a = 0; a < D && meet; ++a) {
      const int lo = mine.lo[a] - width, hi = mine.hi[a] + width;
      if (periodic_[a]) {
        if (hi - lo >= n_cells_[a]) continue;
        // other's interval [olo, ohi) meets [lo, hi) modulo n
        bool any = false;
        for (int shift = -1; shift <= 1 && !any; ++shift) {
          const int olo = other.lo[a] + shift * n_cells_[a], ohi = other.hi[a] + shift * n_cells_[a];
          any = olo < hi && ohi > lo;
        }
        meet = any;
      } else {
        meet = other.lo[a] < hi && other.hi[a] > lo;
      }
    }
    if (meet) out.push_back(r);
  }
  return out;
}

template <int D>
Decomposition<D> Decomposition<D>::bisect(const Comm& comm, const IVec<D>& n_cells,
                                          const std::array<bool, D>& periodic, const std::vector<IVec<D>>& cells,
                                          const std::vector<std::int64_t>& weights, int n_boxes) {
  return build(comm, n_boxes > 0 ? n_boxes : comm.size(), n_cells, periodic, cells, weights, nullptr, 0.0);
}

template <int D>
Decomposition<D> Decomposition<D>::rebalanced(const Comm& comm, const std::vector<IVec<D>>& cells,
                                              const std::vector<std::int64_t>& weights, double tolerance) const {
  return build(comm, n_boxes(), n_cells_, periodic_, cells, weights, this, tolerance);
}

template <int D>
Decomposition<D> Decomposition<D>::build(const Comm& comm, int n_boxes, const IVec<D>& n_cells,
                                         const std::array<bool, D>& periodic, const std::vector<IVec<D>>& cells,
                                         const std::vector<std::int64_t>& weights, const Decomposition* previous,
                                         double tolerance) {
  if (previous && previous->n_boxes() != n_boxes) previous = nullptr;
  Decomposition d(n_cells, periodic);
  long long total_cells = 1;
  for (int a = 0; a < D; ++a) total_cells *= n_cells[a];
  if (total_cells < n_boxes)
    throw std::invalid_argument("the grid has " + std::to_string(total_cells) + " cells, fewer than the " +
                                std::to_string(n_boxes) + " MPI ranks");
  if (!weights.empty() && weights.size() != cells.size())
    throw std::invalid_argument("domain decomposition: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(cells.size()) + " cells");
  std::vector<IVec<D>> local(cells.size());
  for (std::size_t p = 0; p < cells.size(); ++p) local[p] = d.domain_cell(cells[p]);
  auto weight = [&](std::size_t p) -> std::int64_t { return weights.empty() ? 1 : weights[p]; };
  d.boxes_.assign(static_cast<std::size_t>(n_boxes), CellBox<D>{});
  d.cuts_.clear();

  // Depth first; every rank walks the same tree, so the histogram reductions match up. The
  // rank ranges of the nodes do not depend on the particles, so node k of a rebalanced tree is
  // node k of the previous one.
  std::function<int(const CellBox<D>&, int, int)> split = [&](const CellBox<D>& box, int r0, int r1) -> int {
    const int node = static_cast<int>(d.cuts_.size());
    d.cuts_.emplace_back();
    if (r1 - r0 == 1) {
      d.boxes_[static_cast<std::size_t>(r0)] = box;
      d.cuts_[static_cast<std::size_t>(node)].rank = r0;
      return node;
    }
    const int n_below = (r1 - r0) / 2, n_above = r1 - r0 - n_below;
    // An axis can be cut when it leaves enough cells on both sides for their ranks.
    auto min_width = [&](int a, int ranks) {
      const long long slab = box.n_cells() / (box.hi[a] - box.lo[a]);  // cells per unit of width
      return static_cast<int>((ranks + slab - 1) / slab);
    };
    auto can_cut = [&](int a) { return box.hi[a] - box.lo[a] >= min_width(a, n_below) + min_width(a, n_above); };
    // The previous tree's axis when it can still be cut, else the longest axis that can.
    const Cut* old = previous ? &previous->cuts_[static_cast<std::size_t>(node)] : nullptr;
    int axis = -1;
    if (old && old->axis >= 0 && can_cut(old->axis)) {
      axis = old->axis;
    } else {
      for (int a = 0; a < D; ++a)
        if (can_cut(a) && (axis < 0 || box.hi[a] - box.lo[a] > box.hi[axis] - box.lo[axis])) axis = a;
    }
    if (axis < 0) throw std::invalid_argument("domain decomposition: a box cannot be split among its ranks");
    const int lo = box.lo[axis], width = box.hi[axis] - lo;
    std::vector<std::int64_t> histogram(static_cast<std::size_t>(width), 0);
    for (std::size_t p = 0; p < local.size(); ++p) {
      const IVec<D>& c = local[p];
      bool in = true;
      for (int a = 0; a < D && in; ++a) in = c[a] >= box.lo[a] && c[a] < box.hi[a];
      if (in) histogram[static_cast<std::size_t>(c[axis] - lo)] += weight(p);
    }
    comm.sum(histogram.data(), width);
    std::int64_t total = 0;
    for (auto h : histogram) total += h;
    const int first = lo + min_width(axis, n_below);
    const int last = box.hi[axis] - min_width(axis, n_above);
    // The cut whose share below is closest to n_below / (r1 - r0) of the weight (of the cells
    // when the box holds none); ties go to the lower plane.
    auto share_below = [&](int at, std::int64_t below) {
      return total > 0 ? static_cast<double>(below) / static_cast<double>(total) : static_cast<double>(at - lo) / width;
    };
    const double target = static_cast<double>(n_below) / (r1 - r0);
    int best = first;
    double best_error = -1.0, kept_share = -1.0;
    std::int64_t below = 0;
    for (int c = lo; c < first; ++c) below += histogram[static_cast<std::size_t>(c - lo)];
    for (int at = first; at <= last; ++at) {
      const double share = share_below(at, below);
      const double error = std::abs(share - target);
      if (best_error < 0.0 || error < best_error) {
        best_error = error;
        best = at;
      }
      if (old && old->axis == axis && old->at == at) kept_share = share;
      if (at < box.hi[axis]) below += histogram[static_cast<std::size_t>(at - lo)];
    }
    // A rebalance keeps the previous cut while the weight per box on each side stays within
    // the tolerance of the pair's mean: share / target and (1 - share) / (1 - target).
    if (kept_share >= 0.0 && std::max(kept_share / target, (1.0 - kept_share) / (1.0 - target)) <= 1.0 + tolerance)
      best = old->at;
    CellBox<D> box_below = box, box_above = box;
    box_below.hi[axis] = best;
    box_above.lo[axis] = best;
    const int child_below = split(box_below, r0, r0 + n_below);
    const int child_above = split(box_above, r0 + n_below, r1);
    Cut& cut = d.cuts_[static_cast<std::size_t>(node)];
    cut.axis = axis;
    cut.at = best;
    cut.below = child_below;
    cut.above = child_above;
    return node;
  };
  split(CellBox<D>{IVec<D>::Zero(), n_cells}, 0, n_boxes);
  return d;
}

template class Decomposition<1>;
template class Decomposition<2>;
template class Decomposition<3>;

}  // namespace cairn
