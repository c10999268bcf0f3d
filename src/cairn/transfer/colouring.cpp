#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

#include "cairn/transfer/transfer.hpp"

namespace cairn {

template <int D>
void colour_blocks(const Grid<D>& grid, const Particles<D>& particles, TransferCache<D>& cache) {
  // Blocks along each axis must be wider than reach_lo + reach_hi cells so that blocks two apart
  // (same colour) touch disjoint nodes. Cells are split evenly, so every block has at least the
  // minimum width even when the block count does not divide the cell count.
  constexpr int preferred_width = 8;
  IVec<D> n_blocks, n_colours;
  for (int a = 0; a < D; ++a) {
    const int min_width = std::max(preferred_width, cache.reach_lo[a] + cache.reach_hi[a] + 2);
    n_blocks[a] = std::max(1, grid.n_cells()[a] / min_width);
    if (n_blocks[a] == 1) {
      n_colours[a] = 1;
    } else if (grid.periodic(a) && n_blocks[a] % 2 == 1) {
      n_colours[a] = 3;  // odd ring: the last block takes a third colour
    } else {
      n_colours[a] = 2;
    }
  }
  const int total_blocks = n_blocks.prod();
  const int total_colours = n_colours.prod();
  const auto n = static_cast<std::int64_t>(cache.n);

  auto block_along = [&](int a, int c) {
    const int nc = grid.n_cells()[a];
    if (grid.periodic(a)) {
      c %= nc;
      if (c < 0) c += nc;
    }
    const long long b = static_cast<long long>(c) * n_blocks[a] / nc;
    return static_cast<int>(std::clamp<long long>(b, 0, n_blocks[a] - 1));
  };

  // Block of each cell along each axis, tabulated (no division per particle) for the cells of
  // the grid and a margin of ghost cells on each side; cells beyond it use block_along.
  constexpr int margin = 8;
  std::array<std::vector<std::int32_t>, D> table;
  for (int a = 0; a < D; ++a) {
    const int nc = grid.n_cells()[a];
    table[a].resize(static_cast<std::size_t>(nc + 2 * margin));
    for (int c = -margin; c < nc + margin; ++c) table[a][c + margin] = block_along(a, c);
  }
  const IVec<D> n_cells = grid.n_cells();

  // The sort below depends only on block_of (and the id order), so when no particle changed
  // block since the last colouring with the same blocks, the last result stands.
  const bool same_blocks = cache.colouring_valid && cache.id_order.empty() && cache.colouring_blocks == n_blocks &&
                           cache.colouring_colours == n_colours;
  // Binning and a stable counting sort in one team (util/parallel.hpp, particle affinity): each
  // thread bins the particles it built, counts its share of the sort's sequence (storage order,
  // or a distributed run's id order) per block, and places them after the earlier threads'
  // shares of each block. The result is the serial sort's for any thread count.
  const bool in_id_order = !cache.id_order.empty();
  const auto n_seq = in_id_order ? static_cast<std::int64_t>(cache.id_order.size()) : n;
  int changed = same_blocks ? 0 : 1;
#pragma omp parallel if (n >= particle_loop_min)
  {
    const int t = omp_get_thread_num(), T = omp_get_num_threads();
    const auto [first, last] = static_range(n, t, T);
    int changed_t = 0;
    for (std::int64_t p = first; p < last; ++p) {
      const IVec<D> cell = grid.cell_of(particles.position[p]);  // as the families' reach
      int id = 0, mult = 1;
      for (int a = 0; a < D; ++a) {
        const int c = cell[a];
        id += (c >= -margin && c < n_cells[a] + margin ? table[a][c + margin] : block_along(a, c)) * mult;
        mult *= n_blocks[a];
      }
      changed_t |= static_cast<int>(cache.block_of[p] != id);
      cache.block_of[p] = id;
    }
    if (changed_t) {
#pragma omp atomic write
      changed = 1;
    }
#pragma omp barrier
    int any_changed;
#pragma omp atomic read
    any_changed = changed;
    if (any_changed) {  // the same for every thread
      const auto [first_k, last_k] = in_id_order ? static_range(n_seq, t, T) : std::pair{first, last};
      const auto particle_at = [&](std::int64_t k) { return in_id_order ? cache.id_order[k] : static_cast<std::int32_t>(k); };
      // Each thread's counts in a row padded to 64 bytes (neighbouring rows share at most one
      // cache line).
      const std::size_t row = (static_cast<std::size_t>(total_blocks) + 15) / 16 * 16;
#pragma omp single
      cache.cursor.assign(T * row, 0);
      std::int32_t* cursor = cache.cursor.data() + t * row;
      for (std::int64_t k = first_k; k < last_k; ++k) ++cursor[cache.block_of[particle_at(k)]];
#pragma omp barrier
#pragma omp single
      {
        // Block b's particles: thread 0's share, then thread 1's, ... (cursor becomes each
        // thread's first place in the block).
        cache.block_begin.resize(total_blocks + 1);
        std::int32_t at = 0;
        for (int b = 0; b < total_blocks; ++b) {
          cache.block_begin[b] = at;
          for (int u = 0; u < T; ++u) {
            std::int32_t& c = cache.cursor[u * row + b];
            const std::int32_t count = c;
            c = at;
            at += count;
          }
        }
        cache.block_begin[total_blocks] = at;
      }
      for (std::int64_t k = first_k; k < last_k; ++k) {
        const std::int32_t p = particle_at(k);
        cache.order[cursor[cache.block_of[p]]++] = p;
      }
    }
  }
  if (!changed) return;
  cache.colouring_valid = true;
  cache.colouring_blocks = n_blocks;
  cache.colouring_colours = n_colours;

  // Within a block, particles in increasing id (storage order, or the id order of a distributed
  // run's owned and ghost particles), so that every node adds them in the serial order.
  if (cache.sorted_storage) {
    // Particles kept in block order, by id within a block (Simulation::keep_particles_sorted):
    // a block's list, taken in storage order, is a few runs of increasing id, its own particles
    // and those that entered it from each neighbouring block since the last sort. Merging the
    // runs puts it in id order (nothing to do for a block nobody entered).
    const auto by_id = [&](std::int32_t a, std::int32_t b) { return particles.id[a] < particles.id[b]; };
    std::vector<std::int32_t>& runs = cache.id_runs;
    for (int b = 0; b < total_blocks; ++b) {
      std::int32_t* first = cache.order.data() + cache.block_begin[b];
      const std::int32_t m = cache.block_begin[b + 1] - cache.block_begin[b];
      runs.assign(1, 0);
      for (std::int32_t k = 1; k < m; ++k)
        if (by_id(first[k], first[k - 1])) runs.push_back(k);
      runs.push_back(m);
      while (runs.size() > 2) {
        std::size_t kept = 1;
        for (std::size_t r = 0; r + 2 < runs.size(); r += 2) {
          std::inplace_merge(first + runs[r], first + runs[r + 1], first + runs[r + 2], by_id);
          runs[kept++] = runs[r + 2];
        }
        if (runs.size() % 2 == 0) runs[kept++] = runs.back();  // an odd run count: the last one waits
        runs.resize(kept);
      }
    }
  }

  cache.colour_blocks.resize(total_colours);
  for (auto& list : cache.colour_blocks) list.clear();
  for (int b = 0; b < total_blocks; ++b) {
    if (cache.block_begin[b + 1] == cache.block_begin[b]) continue;  // empty block
    int rem = b, colour = 0, mult = 1;
    for (int a = 0; a < D; ++a) {
      const int k = rem % n_blocks[a];
      rem /= n_blocks[a];
      int c = k % 2;
      if (n_colours[a] == 3 && k == n_blocks[a] - 1) c = 2;
      if (n_colours[a] == 1) c = 0;
      colour += c * mult;
      mult *= n_colours[a];
    }
    cache.colour_blocks[colour].push_back(b);
  }
  // Where each block's middle lies among its colour's particles in particle order: a scatter
  // gives thread t of T the blocks around the t-th T-quantile, which hold about the particles of
  // its static_range (util/parallel.hpp, particle affinity) and about 1/T of the colour's work.
  // The blocks themselves stay in index order (node arrays are then walked in storage order).
  // Only the affinity schedule reads the ranks.
  if (n > affinity_max_particles) return;
  const auto middle = [&](std::int32_t b) { return cache.order[(cache.block_begin[b] + cache.block_begin[b + 1]) / 2]; };
  const auto size = [&](std::int32_t b) { return std::int64_t{cache.block_begin[b + 1] - cache.block_begin[b]}; };
  cache.colour_rank.resize(total_colours);
  auto& by_middle = cache.by_middle;
  for (int c = 0; c < total_colours; ++c) {
    const auto& list = cache.colour_blocks[c];
    by_middle.resize(list.size());
    std::iota(by_middle.begin(), by_middle.end(), 0);
    std::sort(by_middle.begin(), by_middle.end(),
              [&](std::int32_t i, std::int32_t j) { return middle(list[i]) < middle(list[j]); });
    auto& rank = cache.colour_rank[c];
    rank.assign(list.size() + 1, 0);
    std::int64_t before = 0;
    for (const std::int32_t k : by_middle) {
      rank[k] = 2 * before + size(list[k]);
      before += size(list[k]);
    }
    rank[list.size()] = 2 * before;
  }
}

template void colour_blocks<1>(const Grid<1>&, const Particles<1>&, TransferCache<1>&);
template void colour_blocks<2>(const Grid<2>&, const Particles<2>&, TransferCache<2>&);
template void colour_blocks<3>(const Grid<3>&, const Particles<3>&, TransferCache<3>&);

}  // namespace cairn
