// Regular Cartesian background grid with ghost layers and optional periodic wrap per axis.
//
// Node multi-indices j run over [0, n_cells] along each axis for the domain nodes; non-periodic
// axes also store `ghost_layers` extra nodes on each side (j < 0 and j > n_cells) so that wide
// stencils (B-splines, GIMP) near the faces have somewhere to go. A periodic axis stores n_cells
// nodes and wraps j modulo n_cells. The grid owns geometry only; node values live in NodeField.
#pragma once

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
    n_total_ = 1;
    for (int a = 0; a < D; ++a) {
      stored_[a] = periodic_[a] ? n_cells_[a] : n_cells_[a] + 1 + 2 * ghost_;
      offset_[a] = periodic_[a] ? 0 : ghost_;
      stride_[a] = n_total_;
      n_total_ *= stored_[a];
    }
  }

  [[nodiscard]] const Vec<D>& origin() const { return origin_; }
  [[nodiscard]] const Vec<D>& cell_size() const { return h_; }
  [[nodiscard]] double min_cell_size() const { return h_.minCoeff(); }
  [[nodiscard]] const IVec<D>& n_cells() const { return n_cells_; }
  [[nodiscard]] int ghost_layers() const { return ghost_; }
  [[nodiscard]] bool periodic(int axis) const { return periodic_[axis]; }
  [[nodiscard]] std::int32_t n_nodes() const { return n_total_; }
  [[nodiscard]] int stored_nodes(int axis) const { return stored_[axis]; }
  [[nodiscard]] double cell_volume() const { return h_.prod(); }
  /// Upper corner of the domain.
  [[nodiscard]] Vec<D> extent_max() const { return origin_ + (n_cells_.template cast<double>().cwiseProduct(h_)); }

  /// Storage index of the node with multi-index j, wrapping periodic axes; -1 if the node lies
  /// beyond the stored ghost layers (the stencil left the grid).
  [[nodiscard]] std::int32_t node_index(const IVec<D>& j) const {
    std::int32_t idx = 0;
    for (int a = 0; a < D; ++a) {
      int k = j[a];
      if (periodic_[a]) {
        k %= n_cells_[a];
        if (k < 0) k += n_cells_[a];
      } else {
        k += offset_[a];
        if (k < 0 || k >= stored_[a]) return -1;
      }
      idx += k * stride_[a];
    }
    return idx;
  }

  /// Contribution of axis `a`, multi-index component j, to the storage index (wrapping a
  /// periodic axis); -1 when j lies beyond the stored ghost layers. The storage index of a node
  /// is the sum of its axes' contributions.
  [[nodiscard]] std::int32_t axis_index(int a, int j) const {
    if (periodic_[a]) {
      j %= n_cells_[a];
      if (j < 0) j += n_cells_[a];
    } else {
      j += offset_[a];
      if (j < 0 || j >= stored_[a]) return -1;
    }
    return j * stride_[a];
  }

  /// Multi-index (domain numbering, may be negative for ghost nodes) of a stored node.
  [[nodiscard]] IVec<D> multi_index(std::int32_t idx) const {
    IVec<D> j;
    for (int a = 0; a < D; ++a) {
      j[a] = (idx / stride_[a]) % stored_[a] - offset_[a];
    }
    return j;
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
  std::array<int, D> stored_{};
  std::array<int, D> offset_{};
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
