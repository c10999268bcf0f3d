// Triangle meshes for the reference explicit FEM (docs/fem.md): read from Gmsh .msh files or
// generated (Gmsh API, or a structured mapped mesh), then checked like any input.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/math/types.hpp"

namespace cairn::fem {

/// Linear (3-node) triangles in the plane, counter-clockwise.
struct TriangleMesh {
  std::vector<Vec<2>> nodes;
  std::vector<std::array<std::int32_t, 3>> triangles;
  /// Element number shown in messages (Gmsh element tag; 1-based index for generated meshes).
  std::vector<std::size_t> element_tags;
  std::string source;  ///< file name or "generated <shape> mesh", for messages

  [[nodiscard]] std::size_t n_nodes() const { return nodes.size(); }
  [[nodiscard]] std::size_t n_elements() const { return triangles.size(); }
};

/// Twice the signed area of triangle e in the reference configuration.
double twice_area(const TriangleMesh& mesh, std::size_t e);

/// Rejects a mesh that cannot be simulated, throwing InputError(source, 0, key, ...): no
/// element, a node index out of range, an inverted (clockwise) or degenerate (area below
/// 1e-12 of its longest edge squared) element, non-finite coordinates. `key` names the input key
/// the mesh came from (fem.mesh_file or fem.shape).
void check_mesh(const TriangleMesh& mesh, const std::string& key);

/// Reads the 3-node triangles of a Gmsh .msh file through the Gmsh API. Line and point
/// elements (boundary entities) are ignored, nodes no triangle uses are dropped; any other
/// 2D or 3D element type, a node off the plane z = 0 or a missing node is an InputError.
TriangleMesh read_gmsh_file(const std::string& path);

/// Meshes fem.shape (minus the hole, if any) with the Gmsh API (OpenCASCADE geometry,
/// Frontal-Delaunay triangles of size fem.size).
TriangleMesh generate_gmsh(const FemConfig& fem);

/// Structured (mapped) meshes: a box of nx x ny squares, each cut into four triangles by its
/// diagonals (a centre node; no preferred direction), or an annulus of nr x nt polar quads,
/// each split into two triangles along alternating diagonals. Sizes follow fem.size.
TriangleMesh generate_structured(const FemConfig& fem);

/// The mesh of an FEM run: read or generated as the config says, then checked.
TriangleMesh make_mesh(const FemConfig& fem);

}  // namespace cairn::fem
