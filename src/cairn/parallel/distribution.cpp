#include "cairn/parallel/distribution.hpp"

#include "cairn/parallel/node_halo.hpp"

#include <algorithm>
#include <numeric>

namespace cairn {

namespace {

/// Positions of `particles` [first, n) in increasing id (a stable sort).
template <int D>
std::vector<std::int32_t> by_id(const Particles<D>& particles, std::size_t first) {
  std::vector<std::int32_t> order(particles.n() - first);
  std::iota(order.begin(), order.end(), static_cast<std::int32_t>(first));
  std::stable_sort(order.begin(), order.end(),
                   [&](std::int32_t a, std::int32_t b) { return particles.id[a] < particles.id[b]; });
  return order;
}

}  // namespace

template <int D>
Distribution<D>::Distribution(const Comm& comm, const Grid<D>& whole)
    : comm_(comm), whole_(whole.whole()) {
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) periodic[a] = whole_.periodic(a);
  decomposition_ = Decomposition<D>(whole_.n_cells(), periodic);
}

template <int D>
IVec<D> Distribution<D>::cell_of(const Vec<D>& x) const {
  const Vec<D> xi = whole_.to_cell_units(x);
  if (!Grid<D>::indexable(xi)) return IVec<D>::Constant(-1);  // left far away: the boundary box
  return decomposition_.domain_cell(whole_.cell_of(x));
}

template <int D>
void Distribution<D>::partition(Particles<D>& particles) {
  if (!active()) {
    n_owned_ = particles.n();
    return;
  }
  std::vector<IVec<D>> cells;
  std::vector<std::int64_t> weights;
  census(particles, cells, weights);
  partition_cells(cells, weights);
  migrate(particles);
}

template <int D>
void Distribution<D>::census(const Particles<D>& particles, std::vector<IVec<D>>& cells,
                             std::vector<std::int64_t>& weights) const {
  cells.resize(particles.n());
  for (std::size_t p = 0; p < particles.n(); ++p) cells[p] = cell_of(particles.position[p]);
  weights.clear();
  if (!weights_.empty())
    for (std::size_t p = 0; p < particles.n(); ++p) weights.push_back(weight_of(particles.material[p]));
}

template <int D>
std::int64_t Distribution<D>::rebalance(Particles<D>& particles, double threshold) {
  if (!active()) return 0;
  std::vector<IVec<D>> cells;
  std::vector<std::int64_t> weights;
  census(particles, cells, weights);
  int depth = 0;
  while ((1 << depth) < comm_.size()) ++depth;
  Decomposition<D> next = decomposition_.rebalanced(comm_, cells, weights, threshold / (2.0 * depth));
  bool same = true;
  for (int r = 0; r < next.n_boxes() && same; ++r)
    same = next.box(r).lo == decomposition_.box(r).lo && next.box(r).hi == decomposition_.box(r).hi;
  if (same) return 0;  // every cut kept: the boxes, neighbours and halos stay as they are
  decomposition_ = std::move(next);
  ++partitions_;
  band_ = -1;
  const std::int64_t moved = comm_.sum(static_cast<std::int64_t>(migrate(particles)));
  ++repartitions_;
  repartition_moved_ += moved;
  repartition_most_moved_ = std::max(repartition_most_moved_, moved);
  return moved;
}

template <int D>
void Distribution<D>::partition_cells(const std::vector<IVec<D>>& cells, const std::vector<std::int64_t>& weights) {
  if (!active()) return;
  std::array<bool, D> periodic{};
  for (int a = 0; a < D; ++a) periodic[a] = whole_.periodic(a);
  decomposition_ = Decomposition<D>::bisect(comm_, whole_.n_cells(), periodic, cells, weights);
  ++partitions_;
  band_ = -1;
}

template <int D>
double Distribution<D>::imbalance(const Particles<D>& particles) const {
  if (!active()) return 1.0;
  std::int64_t mine = 0;
  if (weights_.empty()) mine = static_cast<std::int64_t>(particles.n());
  else
    for (std::size_t p = 0; p < particles.n(); ++p) mine += weight_of(particles.material[p]);
  const std::int64_t most = comm_.max(mine);
  const std::int64_t total = comm_.sum(mine);
  if (total == 0) return 1.0;
  return static_cast<double>(most) * comm_.size() / static_cast<double>(total);
}

template <int D>
std::size_t Distribution<D>::migrate(Particles<D>& particles) {
  return send_to_owners(particles, false);
}

template <int D>
void Distribution<D>::place(Particles<D>& particles) {
  send_to_owners(particles, true);
}

template <int D>
std::size_t Distribution<D>::send_to_owners(Particles<D>& particles, bool generated) {
  if (!active()) {
    n_owned_ = particles.n();
    return 0;
  }
  const int me = comm_.rank();
  const std::size_t n = particles.n();
  std::vector<std::vector<std::int32_t>> leaving(static_cast<std::size_t>(comm_.size()));
  std::vector<std::int32_t> staying;
  staying.reserve(n);
  for (std::size_t p = 0; p < n; ++p) {
    const Vec<D> xi = whole_.to_cell_units(particles.position[p]);
    // A particle that left the grid stays where it is; its stencil build reports it.
    // (A generated particle goes where the generation's selection would have kept it.)
    const int owner = generated                 ? owner_of(particles.position[p])
                      : Grid<D>::indexable(xi) ? decomposition_.owner(whole_.cell_of(particles.position[p]))
                                               : me;
    if (owner == me) staying.push_back(static_cast<std::int32_t>(p));
    else leaving[static_cast<std::size_t>(owner)].push_back(static_cast<std::int32_t>(p));
  }
  bool any_leaving = staying.size() != n;
  Comm::Buffers send(static_cast<std::size_t>(comm_.size()));
  for (int r = 0; r < comm_.size(); ++r)
    if (!leaving[static_cast<std::size_t>(r)].empty()) pack_particles(particles, leaving[static_cast<std::size_t>(r)], send[static_cast<std::size_t>(r)]);
  // Everyone takes part in the all-to-all, moving or not.
  const Comm::Buffers recv = comm_.all_to_all(send);
  if (any_leaving) reorder_particles(particles, staying);
  const std::size_t kept = particles.n();
  std::size_t arrived = 0;
  for (const auto& buffer : recv)
    if (!buffer.empty()) arrived += unpack_particles(particles, buffer);
  if (!generated) received_ += static_cast<std::int64_t>(arrived);
  // Owned particles in increasing id: the kept ones already are (unless they came from a
  // checkpoint slab or a replicated setup in another order), the arrivals are sorted and merged.
  const bool kept_sorted = std::is_sorted(particles.id.begin(), particles.id.begin() + static_cast<std::ptrdiff_t>(kept));
  if (!keep_storage_order_ && (arrived > 0 || !kept_sorted)) {
    std::vector<std::int32_t> order;
    if (kept_sorted) {
      std::vector<std::int32_t> head(kept);
      std::iota(head.begin(), head.end(), 0);
      const std::vector<std::int32_t> tail = by_id(particles, kept);
      order.resize(particles.n());
      std::merge(head.begin(), head.end(), tail.begin(), tail.end(), order.begin(),
                 [&](std::int32_t a, std::int32_t b) { return particles.id[a] < particles.id[b]; });
    } else {
      order = by_id(particles, 0);
    }
    reorder_particles(particles, order);
  }
  n_owned_ = particles.n();
  return n - kept;
}

template <int D>
Grid<D> Distribution<D>::window(const Grid<D>& whole, int reach) const {
  if (!active()) return whole.whole();
  return box_window(whole, decomposition_.box(comm_.rank()), window_margin(reach));
}

template <int D>
void Distribution<D>::add_ghosts(Particles<D>& particles, int reach) {
  n_owned_ = particles.n();
  if (!active()) return;
  const int band = ghost_band(reach);
  if (band != band_) {
    neighbours_ = decomposition_.neighbours(comm_.rank(), band);
    band_ = band;
  }
  const std::size_t k_max = neighbours_.size();
  send_list_.assign(k_max, {});
  for (std::size_t p = 0; p < n_owned_; ++p) {
    const IVec<D> cell = cell_of(particles.position[p]);
    for (std::size_t k = 0; k < k_max; ++k)
      if (decomposition_.near(neighbours_[k], cell, band)) send_list_[k].push_back(static_cast<std::int32_t>(p));
  }
  Comm::Buffers send(k_max);
  for (std::size_t k = 0; k < k_max; ++k) pack_particles(particles, send_list_[k], send[k]);
  const Comm::Buffers recv = comm_.exchange(neighbours_, send);
  for (const auto& b : send) bytes_sent_ += static_cast<std::int64_t>(b.size());
  std::vector<std::size_t> first(k_max + 1, n_owned_);
  for (std::size_t k = 0; k < k_max; ++k) first[k + 1] = first[k] + unpack_particles(particles, recv[k]);
  // Ghosts sorted by id; remember where each neighbour's ghosts went.
  const std::vector<std::int32_t> ghosts = by_id(particles, n_owned_);
  std::vector<std::int32_t> slot_of(particles.n() - n_owned_);
  for (std::size_t g = 0; g < ghosts.size(); ++g)
    slot_of[static_cast<std::size_t>(ghosts[g]) - n_owned_] = static_cast<std::int32_t>(n_owned_ + g);
  std::vector<std::int32_t> order(n_owned_);
  std::iota(order.begin(), order.end(), 0);
  order.insert(order.end(), ghosts.begin(), ghosts.end());
  reorder_particles(particles, order);
  ghost_slot_.assign(k_max, {});
  for (std::size_t k = 0; k < k_max; ++k)
    for (std::size_t q = first[k]; q < first[k + 1]; ++q) ghost_slot_[k].push_back(slot_of[q - n_owned_]);
  // The serial order of every local particle: owned and ghosts, both sorted, merged by id.
  id_order_.resize(particles.n());
  std::vector<std::int32_t> owned(n_owned_), ghost(particles.n() - n_owned_);
  std::iota(owned.begin(), owned.end(), 0);
  std::iota(ghost.begin(), ghost.end(), static_cast<std::int32_t>(n_owned_));
  std::merge(owned.begin(), owned.end(), ghost.begin(), ghost.end(), id_order_.begin(),
             [&](std::int32_t a, std::int32_t b) { return particles.id[a] < particles.id[b]; });
}

template <int D>
void Distribution<D>::drop_ghosts(Particles<D>& particles) {
  if (!active()) return;
  truncate_particles(particles, n_owned_);
  id_order_.clear();
}

template class Distribution<1>;
template class Distribution<2>;
template class Distribution<3>;

}  // namespace cairn
