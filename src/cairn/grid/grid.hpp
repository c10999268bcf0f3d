// Regular Cartesian background grid with ghost layers and optional periodic wrap per axis.
//
// Node multi-indices j run over [0, n_cells] along each axis for the domain nodes; non-periodic
// axes also store `ghost_layers` extra nodes on each side (j < 0 and j > n_cells) so that wide
// stencils (B-splines, GIMP) near the faces have somewhere to go. A periodic axis stores n_cells
// nodes and wraps j modulo n_cells. The grid owns geometry only; node values live in NodeField.
//
// A rank of a distributed run (docs/parallel.md) stores a window of this grid: window() keeps
// the geometry (origin, cell size, cell counts, periodic axes: everything in the domain's own
// numbering) but stores only a box of nodes, and says which cells the rank owns. node_index()
// and multi_index() translate between the domain numbering and the window's storage, so code
// written for the whole grid works on a window unchanged; owns() picks the nodes a rank counts
// in global sums, so that every node is counted by exactly one rank.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "cairn/math/types.hpp"

namespace cairn {

template <int D>
class Grid {
 public:
  Grid() = default;
  Grid(const Vec<D>& origin, const IVec<D>& n_cells, const Vec<D>& cell_size, int ghost_layers,
       const std::array<bool, D>& periodic)
      : origin_(origin), n_cells_(n_cells), h_(cell_size), ghost_(ghost_layers), periodic_(periodic) {
    for (int a = 0; a < D; ++a) {
      stored_[a] = periodic_[a] ? n_cells_[a] : n_cells_[a] + 1 + 2 * ghost_;
      first_[a] = periodic_[a] ? 0 : -ghost_;
      own_hi_[a] = n_cells_[a];
    }
    set_strides();
  }

  /// The same grid storing only the nodes [first, first + count) per axis (domain numbering;
  /// clipped to the stored ghost layers of a non-periodic axis; a periodic axis whose count
  /// reaches n_cells stores the whole ring) and owning the cells [own_lo, own_hi).
  [[nodiscard]] Grid window(IVec<D> first, IVec<D> count, const IVec<D>& own_lo, const IVec<D>& own_hi) const {
    Grid g = *this;
    for (int a = 0; a < D; ++a) {
      if (periodic_[a]) {
        if (count[a] >= n_cells_[a]) {
          first[a] = 0;
          count[a] = n_cells_[a];
        }
      } else {
        const int lo = std::max(first[a], -ghost_);
        const int hi = std::min(first[a] + count[a], n_cells_[a] + 1 + ghost_);
        first[a] = lo;
        count[a] = std::max(hi - lo, 0);
      }
      g.first_[a] = first[a];
      g.stored_[a] = count[a];
      g.own_lo_[a] = own_lo[a];
      g.own_hi_[a] = own_hi[a];
    }
    g.set_strides();
    return g;
  }
  /// The whole grid (every node stored, every cell owned) with this grid's geometry.
  [[nodiscard]] Grid whole() const { return Grid(origin_, n_cells_, h_, ghost_, periodic_); }
  /// Whether this grid stores every node (a serial run, or a rank owning the whole domain).
  [[nodiscard]] bool is_whole() const {
    const Grid w = whole();
    for (int a = 0; a < D; ++a)
      if (first_[a] != w.first_[a] || stored_[a] != w.stored_[a]) return false;
    return true;
  }

  [[nodiscard]] const Vec<D>& origin() const { return origin_; }
  [[nodiscard]] const Vec<D>& cell_size() const { return h_; }
  [[nodiscard]] double min_cell_size() const { return h_.minCoeff(); }
  [[nodiscard]] const IVec<D>& n_cells() const { return n_cells_; }
  [[nodiscard]] int ghost_layers() const { return ghost_; }
  [[nodiscard]] bool periodic(int axis) const { return periodic_[axis]; }
  [[nodiscard]] std::int32_t n_nodes() const { return n_total_; }
  [[nodiscard]] int stored_nodes(int axis) const { return stored_[axis]; }
  /// Domain multi-index of the first stored node along `axis` (-ghost_layers for the whole grid
  /// on a non-periodic axis, 0 on a periodic one).
  [[nodiscard]] int first_node(int axis) const { return first_[axis]; }
  /// Cells [own_lo, own_hi) owned by this rank (every cell for the whole grid).
  [[nodiscard]] const IVec<D>& own_lo() const { return own_lo_; }
  [[nodiscard]] const IVec<D>& own_hi() const { return own_hi_; }
  [[nodiscard]] double cell_volume() const { return h_.prod(); }
  /// Upper corner of the domain.
  [[nodiscard]] Vec<D> extent_max() const { return origin_ + (n_cells_.template cast<double>().cwiseProduct(h_)); }

  /// Storage index of the node with multi-index j, wrapping periodic axes; -1 if the node lies
  /// beyond the stored ghost layers (the stencil left the grid).
  [[nodiscard]] std::int32_t node_index(const IVec<D>& j) const {
    std::int32_t idx = 0;
    for (int a = 0; a < D; ++a) {
      const std::int32_t c = axis_index(a, j[a]);
      if (c < 0) return -1;
      idx += c;
    }
    return idx;
  }

  /// Contribution of axis `a`, multi-index component j, to the storage index (wrapping a
  /// periodic axis); -1 when j lies beyond the stored ghost layers. The storage index of a node
  /// is the sum of its axes' contributions.
  [[nodiscard]] std::int32_t axis_index(int a, int j) const {
    j -= first_[a];
    if (periodic_[a]) {
      j %= n_cells_[a];
      if (j < 0) j += n_cells_[a];
    }
    if (j < 0 || j >= stored_[a]) return -1;
    return j * stride_[a];
  }

  /// Multi-index (domain numbering, may be negative for ghost nodes; in [0, n_cells) on a
  /// periodic axis) of a stored node.
  [[nodiscard]] IVec<D> multi_index(std::int32_t idx) const {
    // idx in [0, n_nodes()), axis 0 fastest: D - 1 divisions, each giving a quotient and its
    // remainder (one instruction), where (idx / stride_a) % stored_a took two per axis (the
    // WLS integrator's node loops call this for every node, several times a step).
    IVec<D> j;
    std::int32_t rest = idx;
    for (int a = 0; a + 1 < D; ++a) {
      j[a] = rest % stored_[a];
      rest /= stored_[a];
    }
    j[D - 1] = rest;
    for (int a = 0; a < D; ++a) {
      j[a] += first_[a];
      if (periodic_[a] && j[a] >= n_cells_[a]) j[a] -= n_cells_[a];
      if (periodic_[a] && j[a] < 0) j[a] += n_cells_[a];
    }
    return j;
  }

  /// Whether this rank counts stored node `idx` in global sums: the node's cell (the one it is
  /// the lower corner of; the last cell for the upper face and the ghost nodes beyond a face)
  /// is owned. Every node of the domain is owned by exactly one rank.
  [[nodiscard]] bool owns(std::int32_t idx) const {
    const IVec<D> j = multi_index(idx);
    for (int a = 0; a < D; ++a) {
      const int c = std::clamp(j[a], 0, n_cells_[a] - 1);
      if (c < own_lo_[a] || c >= own_hi_[a]) return false;
    }
    return true;
  }

  [[nodiscard]] Vec<D> node_position(std::int32_t idx) const {
    return origin_ + multi_index(idx).template cast<double>().cwiseProduct(h_);
  }

  /// Largest |xi| (cell units from the origin) a particle may have: the input allows at most
  /// 1e9 cells per axis, and stencil cell and node indices computed from such xi stay far from
  /// int overflow. Positions beyond it (or NaN) have left the grid whatever the axis.
  static constexpr double max_cell_units = 1.5e9;
  /// True when every |xi[a]| < max_cell_units, checked in floating point before any cell index
  /// is formed (a restart position of 3e9 or 1e30 would otherwise wrap to a valid-looking cell).
  [[nodiscard]] static bool indexable(const Vec<D>& xi) {
    for (int a = 0; a < D; ++a)
      if (!(std::abs(xi[a]) < max_cell_units)) return false;
    return true;
  }

  /// Position in cell units relative to the origin: xi = (x - origin) / h.
  [[nodiscard]] Vec<D> to_cell_units(const Vec<D>& x) const { return (x - origin_).cwiseQuotient(h_); }

  /// Cell containing x (may be outside [0, n_cells) for particles in ghost cells).
  [[nodiscard]] IVec<D> cell_of(const Vec<D>& x) const {
    Vec<D> xi = to_cell_units(x);
    IVec<D> c;
    for (int a = 0; a < D; ++a) c[a] = static_cast<int>(std::floor(xi[a]));
    return c;
  }

 private:
  Vec<D> origin_ = Vec<D>::Zero();
  IVec<D> n_cells_ = IVec<D>::Ones();
  Vec<D> h_ = Vec<D>::Ones();
  int ghost_ = 0;
  std::array<bool, D> periodic_{};
  void set_strides() {
    n_total_ = 1;
    for (int a = 0; a < D; ++a) {
      stride_[a] = n_total_;
      n_total_ *= stored_[a];
    }
  }

  std::array<int, D> stored_{};
  std::array<int, D> first_{};
  IVec<D> own_lo_ = IVec<D>::Zero();
  IVec<D> own_hi_ = IVec<D>::Ones();
  std::array<std::int32_t, D> stride_{};
  std::int32_t n_total_ = 0;
};

/// Node values of one velocity field (one per material once contact is on; one otherwise).
template <int D>
struct NodeField {
  std::vector<double> mass;          ///< lumped mass m_i
  std::vector<Vec<D>> momentum;      ///< p_i = sum_p S_pi M_p V_p
  std::vector<Vec<D>> force;         ///< f_i: internal + body + traction
  std::vector<Vec<D>> velocity;      ///< v_i = m^-1 p (after velocity conditions)
  std::vector<Vec<D>> velocity_new;  ///< v_i^+ = m^-1 p^+ (after velocity conditions)
  /// Force exerted by velocity conditions on the node (empty in a simulation without conditions).
  std::vector<Vec<D>> reaction;
  std::vector<Vec<D>> velocity_full; ///< m~_k^-1 q from the full-mass expansion (FMPM/XPIC)
  std::vector<Vec<D>> velocity_work; ///< scratch: projections, re-extrapolated velocities

  /// n entries of every field; velocity_full and velocity_work only when `scratch` (a step with
  /// neither a full-mass expansion nor a second stress-update velocity leaves them empty).
  void resize(std::int32_t n, bool scratch = true) {
    mass.assign(n, 0.0);
    momentum.assign(n, Vec<D>::Zero());
    force.assign(n, Vec<D>::Zero());
    velocity.assign(n, Vec<D>::Zero());
    velocity_new.assign(n, Vec<D>::Zero());
    reaction.assign(n, Vec<D>::Zero());
    velocity_full.assign(scratch ? n : 0, Vec<D>::Zero());
    velocity_work.assign(scratch ? n : 0, Vec<D>::Zero());
  }
};

}  // namespace cairn
