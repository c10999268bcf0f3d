// One rank's share of a distributed run (docs/parallel.md): its box of cells, the particles it
// owns, the ghost copies of other ranks' particles it needs, and the exchanges between them.
//
// Ghost particles, not node sums. Each rank adds, at every node it reads, the contributions of
// its own particles and of copies ("ghosts") of every other particle whose stencil reaches that
// node, in increasing particle id within each colouring block: the order a serial run uses. So
// node values are not summed across ranks at all; they come out bit-identical to the serial
// run's. The price is that the ghosts' per-particle values the step scatters must be current:
// the owners send them (refresh) after every gather whose result is scattered again (full-mass
// sweeps, the stresses of USF, the velocities of USL+, the heat fluxes of conduction).
//
// Widths, for stencils reaching r cells beyond the particle's cell (the shape family's reach, at
// most): a rank reads nodes up to R = r + 1 beyond its box (the +1: traction faces of point
// families sit up to a cell from their particle). A node there receives from particles up to
// R + r + 2 cells away, hence ghosts come from a band of B = 2 r + 3 cells around the box, and
// the rank stores the nodes those ghosts reach: a window of W = B + r + 2 nodes beyond the box.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/parallel/decomposition.hpp"
#include "cairn/parallel/particle_transfer.hpp"
#include "cairn/particles/particles.hpp"

namespace cairn {

template <int D>
class Distribution {
 public:
  /// A serial run: one rank owning everything.
  Distribution() = default;
  /// A run over the ranks of `comm` on the grid `whole` (geometry only).
  Distribution(const Comm& comm, const Grid<D>& whole);

  [[nodiscard]] const Comm& comm() const { return comm_; }
  /// Whether there is more than one rank (otherwise every method below is a no-op).
  [[nodiscard]] bool active() const { return comm_.parallel(); }
  [[nodiscard]] const Decomposition<D>& decomposition() const { return decomposition_; }
  /// Number of partitions so far (the start-up one, then each repartition that changed a box).
  [[nodiscard]] int partitions() const { return partitions_; }
  /// Particles this rank has received from other ranks so far (migration and partitions).
  [[nodiscard]] std::int64_t received() const { return received_; }

  /// Weigh a particle of material m by weights[m] in the bisection and the imbalance (its cost,
  /// docs/parallel.md "Load balance"); empty (the default): every particle weighs 1, the boxes
  /// balance particle counts.
  void set_material_weights(std::vector<std::int64_t> weights) { weights_ = std::move(weights); }
  [[nodiscard]] std::int64_t weight_of(std::int32_t material) const {
    return weights_.empty() ? 1 : weights_[static_cast<std::size_t>(material)];
  }
  /// Bisect the domain among the ranks by the cells of all particles and send each particle to
  /// its owner (collective). `particles` holds this rank's particles (any subset: all of them
  /// after a replicated setup, a slab of a checkpoint, the current owned set).
  void partition(Particles<D>& particles);
  /// A repartition of the owned `particles` that moves as few as it can: the bisection tree is
  /// kept and a cut moves only where its sides are out of balance by more than threshold / (2 L)
  /// (L: the tree's depth, so that the kept cuts compound to about threshold / 2), then the
  /// particles that changed box migrate (collective). Returns the particles that changed rank,
  /// over all ranks.
  std::int64_t rebalance(Particles<D>& particles, double threshold);
  /// Repartitions so far that changed a box, the particles they moved (over all ranks) and the
  /// most one moved.
  [[nodiscard]] int repartitions() const { return repartitions_; }
  [[nodiscard]] std::int64_t repartition_moved() const { return repartition_moved_; }
  [[nodiscard]] std::int64_t repartition_most_moved() const { return repartition_most_moved_; }
  /// Bisect the domain by the cells `cells` (this rank's part of a census of every particle, any
  /// split of it over the ranks: the bisection sums the ranks' histograms) and their `weights`
  /// (empty: 1 each) without moving particles: per-rank generation then creates each rank's
  /// particles in place (collective).
  void partition_cells(const std::vector<IVec<D>>& cells, const std::vector<std::int64_t>& weights = {});
  /// The cell that decides the owner of a particle at x (cells beyond a face count for the
  /// boundary cell, periodic axes wrap; far outside the grid: the boundary box).
  [[nodiscard]] IVec<D> cell_of(const Vec<D>& x) const;
  /// The rank whose box holds the particle at x.
  [[nodiscard]] int owner_of(const Vec<D>& x) const { return decomposition_.owner(cell_of(x)); }
  /// Largest weight of a rank's `particles` (all of them owned) over the mean weight: with unit
  /// weights the largest particle count over the mean count (1 for a serial run; collective).
  [[nodiscard]] double imbalance(const Particles<D>& particles) const;
  /// Send the particles that left this rank's box to their owners and take in those that
  /// entered it; the owned particles stay in increasing id (collective), unless
  /// keep_storage_order(true): then the staying particles keep their storage order and the
  /// arrivals follow them (the node halo, whose storage is sorted by cell block). Returns the
  /// particles that left this rank.
  std::size_t migrate(Particles<D>& particles);
  /// After per-rank generation (partition_cells, then each rank's particles): take the
  /// generated `particles` as this rank's own, sending those outside its box (a rank's share of
  /// a body not split by boxes: sim/bodies.cpp) to the rank owner_of names, in increasing id
  /// (collective; not counted in received()).
  void place(Particles<D>& particles);
  void keep_storage_order(bool keep) { keep_storage_order_ = keep; }

  /// Ghost band B and window margin W for stencils of reach r (see above).
  [[nodiscard]] static int ghost_band(int reach) { return 2 * reach + 3; }
  [[nodiscard]] static int window_margin(int reach) { return ghost_band(reach) + reach + 2; }
  /// The part of `whole` this rank stores for stencils of reach r, owning its box.
  [[nodiscard]] Grid<D> window(const Grid<D>& whole, int reach) const;

  /// Append to `particles` (its first n_owned() entries owned) copies of the other ranks'
  /// particles in the ghost band, sorted by id, and record who sends which for refresh()
  /// (collective).
  void add_ghosts(Particles<D>& particles, int reach);
  /// Remove the ghosts again (the end of a step).
  void drop_ghosts(Particles<D>& particles);
  [[nodiscard]] std::size_t n_owned() const { return n_owned_; }
  /// Bytes this rank has sent in ghost copies and their refreshes so far.
  [[nodiscard]] std::int64_t ghost_bytes_sent() const { return bytes_sent_; }
  /// Every local particle (owned and ghost) in increasing id: the serial order.
  [[nodiscard]] const std::vector<std::int32_t>& id_order() const { return id_order_; }
  /// Owners send their current `values` (width entries per particle) to the ghosts' copies. Each
  /// side knows the sizes (the ghosts a neighbour holds of this rank are its send list), so the
  /// messages go in one round into buffers kept between calls.
  template <class T>
  void refresh(std::vector<T>& values, int width = 1) const {
    if (!active() || width == 0) return;
    const std::size_t row = static_cast<std::size_t>(width);
    refresh_send_.resize(neighbours_.size());
    refresh_recv_.resize(neighbours_.size());
    for (std::size_t k = 0; k < neighbours_.size(); ++k) {
      refresh_send_[k].clear();
      pack_values(values, width, send_list_[k], refresh_send_[k]);
      refresh_recv_[k].resize(ghost_slot_[k].size() * row * sizeof(T));
      bytes_sent_ += static_cast<std::int64_t>(refresh_send_[k].size());
    }
    comm_.exchange_sized(neighbours_, refresh_send_, refresh_recv_);
    for (std::size_t k = 0; k < neighbours_.size(); ++k) {
      const std::vector<char>& in = refresh_recv_[k];
      std::size_t offset = 0;
      for (std::int32_t slot : ghost_slot_[k]) {
        std::memcpy(static_cast<void*>(values.data() + static_cast<std::size_t>(slot) * row), in.data() + offset,
                    row * sizeof(T));
        offset += row * sizeof(T);
      }
    }
  }

 private:
  /// The cells of `particles` and, with material weights, their weights.
  void census(const Particles<D>& particles, std::vector<IVec<D>>& cells, std::vector<std::int64_t>& weights) const;
  /// migrate(), or with `generated` place(): owners by owner_of, arrivals not counted.
  std::size_t send_to_owners(Particles<D>& particles, bool generated);
  mutable Comm::Buffers refresh_send_, refresh_recv_;  ///< refresh(): per neighbour, kept
  Comm comm_ = Comm::serial();
  Grid<D> whole_;
  Decomposition<D> decomposition_;
  int partitions_ = 0;
  int repartitions_ = 0;
  std::int64_t repartition_moved_ = 0, repartition_most_moved_ = 0;
  std::vector<std::int64_t> weights_;  ///< per material; empty: 1
  std::int64_t received_ = 0;
  std::size_t n_owned_ = 0;
  int band_ = -1;                                  ///< ghost band of the neighbour list
  std::vector<int> neighbours_;                    ///< ranks exchanging ghosts with this one
  std::vector<std::vector<std::int32_t>> send_list_;   ///< per neighbour: owned particles sent
  std::vector<std::vector<std::int32_t>> ghost_slot_;  ///< per neighbour: where its ghosts are
  std::vector<std::int32_t> id_order_;
  mutable std::int64_t bytes_sent_ = 0;
  bool keep_storage_order_ = false;
};

}  // namespace cairn
