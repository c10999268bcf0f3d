// Particles from the elements of a Gmsh mesh ([[body]] shape `volume_mesh`, docs/geometry.md):
// the 3-node triangles of a 2D model or the 4-node tetrahedra of a 3D one, one particle per
// element at its centroid with the element's area/volume, or `quadrature` particles per element
// at the points of a symmetric Gauss rule, each with its weight's share of the element, as
// CB-Geo MPM generates material points from a mesh. The particles' volumes sum to the mesh's
// exactly (mass = density x volume). The file is read by the Gmsh API (fem/gmsh_module.hpp); a
// .geo file without a mesh is meshed first.
#pragma once

#include <memory>
#include <string>

#include "cairn/geometry/point_set.hpp"
#include "cairn/geometry/surface_mesh.hpp"

namespace cairn::geometry {

/// The particles of the mesh in `path` for a model of `dimension` (2: triangles, 3: tetrahedra)
/// with `quadrature` points per element (2D: 1 or 3; 3D: 1 or 4), placed by `placement`
/// (no rotation in 2D). Throws std::invalid_argument naming the file and the fault: Gmsh cannot
/// read it, no element of the dimension, another element type (quadrilaterals, second order), a
/// degenerate (zero-volume) element by its Gmsh tag, a 2D mesh off the plane z = 0.
std::shared_ptr<const PointSet> read_volume_mesh(const std::string& path, int dimension, int quadrature,
                                                 const MeshPlacement& placement);

}  // namespace cairn::geometry
