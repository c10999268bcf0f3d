// Subdivision of grid cells by the implicit surface (seed 001 Sec. 3.4): the part of a cell
// where the signed distance d > 0 (inside the body) is split into its connected regions, each
// integrated by one point at its centroid with its volume as weight (Sec. 3.4.2).
//
// Corner k of a cell [lo, lo + h] sits at lo + (bit a of k) h_a along axis a (x fastest, the
// grid's node order). An edge whose ends lie on both sides is cut where the linear interpolant of
// d vanishes (seed 001 Eq. 18).
//
// 2D: marching squares (Fig. 2). The inside part of the cell boundary, walked counter-clockwise
// with its cut points, bounds a triangle, quadrilateral, pentagon or the full square; the two
// ambiguous (saddle) cases are decided by the cell-centre value, the mean of the corners: inside
// joins the two corners into one hexagon, outside gives two triangles (two regions).
//
// 3D: the cube is split into the six tetrahedra of its Kuhn (Freudenthal) decomposition around
// the diagonal from corner 0 to corner 7; in each tetrahedron d is interpolated linearly and its
// positive part is a tetrahedron, a prism or the tetrahedron minus a corner tetrahedron, whose
// volume and centroid are exact. Pieces of tetrahedra that share a face with an inside vertex
// are one region. Because the interpolant is exactly linear in each tetrahedron, a cell cut by a
// plane (d affine) gets the exact volume and centroid of its inside part; the decomposition is
// the same in every cell, so neighbouring cells agree on their common faces (docs/wls.md).
#pragma once

#include <array>

#include "cairn/math/types.hpp"

namespace cairn::wls {

template <int D>
struct CellRegion {
  double volume = 0.0;              ///< measure of the region (area in 2D)
  Vec<D> centroid = Vec<D>::Zero();
};

/// Most regions one cell can hold: 2 in 2D (saddle), 6 in 3D (one per tetrahedron).
template <int D>
constexpr int max_regions = D == 2 ? 2 : 6;

/// Inside regions (d > 0) of the cell [lo, lo + h] with corner values d; returns their number
/// and writes them to `out`. D = 2 or 3.
template <int D>
int cut_cell(const std::array<double, (1 << D)>& d, const Vec<D>& lo, const Vec<D>& h,
             std::array<CellRegion<D>, max_regions<D>>& out);

}  // namespace cairn::wls
