#include "cairn/parallel/node_halo.hpp"

#include <algorithm>
#include <numeric>

namespace cairn {

template <int D>
std::vector<std::int32_t> NodeHalo<D>::shared_nodes(const CellBox<D>& a, const CellBox<D>& b, const Grid<D>& whole,
                                                    int margin) {
  const Grid<D> all = whole.whole();
  const Grid<D> mine = box_window(all, a, margin);
  const Grid<D> theirs = box_window(all, b, margin);
  std::vector<std::int32_t> out;
  for (std::int32_t i = 0; i < mine.n_nodes(); ++i) {
    const IVec<D> j = mine.multi_index(i);
    if (theirs.node_index(j) >= 0) out.push_back(all.node_index(j));
  }
  std::sort(out.begin(), out.end());
  return out;
}

template <int D>
void NodeHalo<D>::build(const Comm& comm, const Decomposition<D>& decomposition, const Grid<D>& whole, int margin,
                        int partitions) {
  comm_ = comm;
  rank_ = comm.rank();
  margin_ = margin;
  partitions_ = partitions;
  neighbours_.clear();
  shared_.clear();
  union_.clear();
  union_of_.clear();
  holder_start_.assign(1, 0);
  holders_.clear();
  lower_.clear();
  const Grid<D> all = whole.whole();
  const Grid<D> mine = box_window(all, decomposition.box(rank_), margin);
  n_nodes_ = static_cast<std::size_t>(mine.n_nodes());
  if (!comm.parallel()) return;
  // Each node's place in the whole grid orders the shared lists the same way on both sides.
  const auto n = static_cast<std::int32_t>(n_nodes_);
  std::vector<IVec<D>> index(n_nodes_);
  std::vector<std::int32_t> key(n_nodes_);
  for (std::int32_t i = 0; i < n; ++i) {
    index[static_cast<std::size_t>(i)] = mine.multi_index(i);
    key[static_cast<std::size_t>(i)] = all.node_index(index[static_cast<std::size_t>(i)]);
  }
  auto canonical = [&](std::int32_t a, std::int32_t b) {
    return key[static_cast<std::size_t>(a)] < key[static_cast<std::size_t>(b)];
  };
  // Windows of boxes up to 2 margin + 1 cells apart overlap; neighbours() lists them in
  // increasing rank.
  for (int r : decomposition.neighbours(rank_, 2 * margin + 2)) {
    const Grid<D> other = box_window(all, decomposition.box(r), margin);
    std::vector<std::int32_t> list;
    for (std::int32_t i = 0; i < n; ++i)
      if (other.node_index(index[static_cast<std::size_t>(i)]) >= 0) list.push_back(i);
    if (list.empty()) continue;
    std::sort(list.begin(), list.end(), canonical);
    neighbours_.push_back(r);
    shared_.push_back(std::move(list));
  }
  std::vector<std::int32_t> place(n_nodes_, -1);
  for (const auto& list : shared_)
    for (std::int32_t i : list) place[static_cast<std::size_t>(i)] = 0;
  for (std::int32_t i = 0; i < n; ++i)
    if (place[static_cast<std::size_t>(i)] == 0) {
      place[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(union_.size());
      union_.push_back(i);
    }
  union_of_ = place;  // (-1: a node no other window holds)
  // Per shared node, where each other holder's partial arrives, in increasing rank (CSR).
  std::vector<std::vector<Holder>> of(union_.size());
  for (std::size_t k = 0; k < shared_.size(); ++k)
    for (std::size_t s = 0; s < shared_[k].size(); ++s)
      of[static_cast<std::size_t>(place[static_cast<std::size_t>(shared_[k][s])])].push_back({k, s});
  for (const auto& list : of) {
    std::size_t lower = 0;
    for (const Holder& h : list) {
      lower += neighbours_[h.k] < rank_ ? 1 : 0;
      holders_.push_back(h);
    }
    lower_.push_back(lower);
    holder_start_.push_back(holders_.size());
  }
  send_.assign(neighbours_.size(), {});
  recv_.assign(neighbours_.size(), {});
}

template class NodeHalo<1>;
template class NodeHalo<2>;
template class NodeHalo<3>;

}  // namespace cairn
