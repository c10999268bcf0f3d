// The per-step transfer cache: for each particle its stencil (node index, S_pi, grad S_pi),
// filled once per step by the shape family and reused by every transfer of that step, plus the
// cell-block colouring that makes particle-to-grid scatters race-free without atomics.
//
// Two layouts, chosen by the family's builder (transfer/transfer.hpp reads both):
//  - list: up to `stride` entries (node, S, G) per particle, `count[p]` of them used. Any family
//    (CPDI, B2CPDI, wide GIMP stencils).
//  - tensor: tensor-product families (seed 003 Eq. 18) keep only the per-axis factors, `width`
//    node offsets, 1D weights phi and derivatives dphi/dx per axis, and the transfers form
//    S_pi = prod_a phi_a and G_pi,b = prod_a (a == b ? dphi_a : phi_a) on the fly. A 3D quadratic
//    B-spline stencil is then 180 bytes instead of 27 * 36 = 972, and the products cost less than
//    reading the expanded entries back from memory (docs/performance.md). Entries outside a
//    particle's support have S = 0 and G = 0; transfers visit them (they add zeros), so every
//    node offset is a stored node and the colouring reach covers the full width.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "cairn/math/types.hpp"

namespace cairn {

enum class StencilLayout : std::uint8_t { list, tensor };

template <int D>
struct TransferCache {
  StencilLayout layout = StencilLayout::list;
  std::size_t n = 0;                 ///< particles
  /// Particles [0, n_owned) are updated by gathers; a distributed run's ghost copies of other
  /// ranks' particles follow them and are only scattered (docs/parallel.md). n_owned = n unless
  /// the simulation says otherwise after the build.
  std::size_t n_owned = 0;
  /// A distributed run: every particle in increasing id (the serial order), for the colouring's
  /// sort and contact's point clouds. Empty: storage order is id order, or sorted_storage.
  std::vector<std::int32_t> id_order;
  /// A serial run keeps its particles in cell-block order (Simulation::keep_particles_sorted):
  /// storage order is not id order, and the colouring sorts each block's particles by id itself
  /// (no id_order: it would cost 4 bytes per particle for good).
  bool sorted_storage = false;

  // ---- list layout ----
  int stride = 0;                    ///< stencil slots per particle (the family's maximum)
  std::vector<std::int32_t> node;    ///< n*stride node indices (storage numbering)
  std::vector<double> weight;        ///< S_pi
  std::vector<Vec<D>> gradient;      ///< G_pi = grad S_pi (physical units)
  std::vector<std::uint16_t> count;  ///< number of used slots per particle

  // ---- tensor layout ----
  int width = 0;                       ///< nodes per axis (2, 3 or 4)
  std::vector<std::int32_t> axis_node; ///< n*D*width: per axis the storage offsets of the nodes
  /// n*D*2*width: per axis the weights phi(k), then the derivatives dphi(k)/dx (physical units)
  std::vector<double> axis_value;

  /// Stencil reach in cells beyond the cell holding the particle (floor of its position in cell
  /// units, grid.cell_of), per axis: nodes from cell - reach_lo to cell + 1 + reach_hi. Reported
  /// by the family so that colouring blocks are wide enough.
  IVec<D> reach_lo = IVec<D>::Zero();
  IVec<D> reach_hi = IVec<D>::Zero();

  // Colouring: particles sorted by block; blocks of one colour share no node.
  std::vector<std::int32_t> order;          ///< particle indices grouped by block
  std::vector<std::int32_t> block_begin;    ///< n_blocks + 1 offsets into order
  std::vector<std::vector<std::int32_t>> colour_blocks;  ///< blocks of each colour, by index
  /// Per colour and block (as colour_blocks): where the block's middle lies among the colour's
  /// particles taken block by block in the order of the blocks' middle particles, doubled
  /// (an integer); the last entry is twice the colour's particle count. A scatter gives thread t
  /// of T the blocks of the t-th T-quantile (transfer/transfer.hpp, scatter).
  std::vector<std::vector<std::int64_t>> colour_rank;
  std::vector<std::int32_t> block_of;       ///< scratch: block of each particle
  std::vector<std::int32_t> cursor;         ///< scratch: per-thread block counts of the sort
  std::vector<std::int32_t> by_middle;      ///< scratch: a colour's blocks ranked by middle particle
  std::vector<std::int32_t> id_runs;        ///< scratch: bounds of a block's runs of increasing id
  /// order/block_begin/colour_blocks are the sort of block_of for these block and colour counts
  /// (colour_blocks skips the sort while no particle changes block).
  bool colouring_valid = false;
  IVec<D> colouring_blocks = IVec<D>::Zero(), colouring_colours = IVec<D>::Zero();

  /// List layout for n particles with `slots` stencil entries each (no-op when already sized).
  void reserve(std::size_t n_particles, int slots) {
    if (layout == StencilLayout::list && stride == slots && n == n_particles) {
      n_owned = n;
      return;
    }
    release_tensor();
    layout = StencilLayout::list;
    n = n_particles;
    stride = slots;
    node.assign(n * slots, -1);
    weight.assign(n * slots, 0.0);
    gradient.assign(n * slots, Vec<D>::Zero());
    count.assign(n, 0);
    resize_common();
  }

  /// Tensor layout for n particles with `nodes_per_axis` nodes per axis.
  void reserve_tensor(std::size_t n_particles, int nodes_per_axis) {
    if (layout == StencilLayout::tensor && width == nodes_per_axis && n == n_particles) {
      n_owned = n;
      return;
    }
    release_list();
    layout = StencilLayout::tensor;
    n = n_particles;
    width = nodes_per_axis;
    axis_node.assign(n * D * width, 0);
    axis_value.assign(n * D * 2 * width, 0.0);
    resize_common();
  }

 private:
  void resize_common() {
    n_owned = n;
    colouring_valid = false;
    block_of.assign(n, 0);
    order.assign(n, 0);
  }
  void release_list() {
    stride = 0;
    std::vector<std::int32_t>().swap(node);
    std::vector<double>().swap(weight);
    std::vector<Vec<D>>().swap(gradient);
    std::vector<std::uint16_t>().swap(count);
  }
  void release_tensor() {
    width = 0;
    std::vector<std::int32_t>().swap(axis_node);
    std::vector<double>().swap(axis_value);
  }
};

}  // namespace cairn
