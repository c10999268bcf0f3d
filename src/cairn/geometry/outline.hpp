// 2D outlines with holes from a file ([[body]] shape `outline`, docs/geometry.md): closed loops
// of vertices, the first the outside, the others holes; a point is in the body when a ray from
// it crosses the loops' edges an odd number of times (the even-odd rule), as for `polygon`.
//
// The file (CSV): one vertex "x, y" per line, loops separated by blank lines, lines starting with
// '#' and an optional header "x, y" skipped; a loop's last vertex may repeat its first. Or a
// closed surface mesh cut by a plane z = const (read_outline).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace cairn::geometry {

using Loop = std::vector<std::vector<double>>;  ///< vertices [x, y] in order

/// Read the loops of `path`, scaled by `scale` and shifted by `translate` ([x, y]). Throws
/// std::invalid_argument naming the file, the line and the fault: a field that is not a finite
/// number, a line without two fields, a loop of fewer than 3 vertices or of zero area, two edges
/// that cross or touch (loops must be simple and apart), a hole outside the first loop, no loop.
std::vector<Loop> read_outline_csv(const std::string& path, double scale, const std::vector<double>& translate);

/// The loops of `path`: a CSV outline (read_outline_csv), or, for a surface mesh (.stl, .obj,
/// .ply, .off, read and checked as for `mesh` shapes, its coordinates times `scale`), the cut of
/// the plane z = slice_z through it (CGAL's Polygon_mesh_slicer), shifted by `translate`: every
/// closed polyline of the cut a loop, the largest first, islands and holes by the even-odd rule.
/// Throws std::invalid_argument naming the file and the fault (the mesh's own faults, a plane
/// that misses the surface or runs along a face, loops that touch).
std::vector<Loop> read_outline(const std::string& path, double scale, const std::vector<double>& translate,
                               double slice_z);

/// Whether (x, y) is inside the one closed loop `loop` by the even-odd (crossing) rule.
bool inside_loop(const Loop& loop, double x, double y);

/// Whether (x, y) is inside `loops` by the even-odd rule over all their edges.
bool inside_loops(const std::vector<Loop>& loops, double x, double y);

/// Area enclosed by the even-odd rule: the loops inside an even number of others minus the others.
double loops_area(const std::vector<Loop>& loops);

}  // namespace cairn::geometry
