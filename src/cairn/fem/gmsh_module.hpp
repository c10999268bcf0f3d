// The interface of the Gmsh mesher module. Gmsh and the libraries it brings (OpenCASCADE, FLTK,
// ... 91 in all) are linked into libcairn_gmsh.so alone, which the program loads the first time
// an FEM run reads or generates a Gmsh mesh (fem/gmsh_mesh.cpp): linked into cairn itself, they
// made every command start 0.16 s later, twice over with the OpenMP restart of app/main.cpp
// (docs/performance.md, "Start-up").
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cairn/fem/mesh.hpp"

namespace cairn::fem {

/// Bumped whenever GmshModule or the types it passes change: a module of another version (a
/// stale build) is refused.
inline constexpr int gmsh_module_version = 2;

/// The elements of a .msh file for particles (geometry/volume_mesh.hpp): the nodes (x, y, z),
/// the 3-node triangles and 4-node tetrahedra (node indices into `nodes`) with their Gmsh tags,
/// and the first other element type of dimension 2 or 3 met ("" when none).
struct ElementMesh {
  std::vector<std::array<double, 3>> nodes;
  std::vector<std::array<std::int32_t, 3>> triangles;
  std::vector<std::size_t> triangle_tags;
  std::vector<std::array<std::int32_t, 4>> tetrahedra;
  std::vector<std::size_t> tetrahedron_tags;
  std::string other;
};

/// The elements of the .msh (or .geo, meshed) file `path`, read through the module. Throws
/// std::invalid_argument naming the fault when Gmsh cannot read it.
ElementMesh read_gmsh_elements(const std::string& path);

/// What the module provides. Both functions throw InputError (or std::runtime_error) as the
/// in-program code would; the meshes come back as Gmsh gave them (unchecked, unoriented).
struct GmshModule {
  int version;
  TriangleMesh (*read_file)(const std::string& path);  ///< a .msh file's 3-node triangles
  TriangleMesh (*generate)(const FemConfig& fem);       ///< fem.shape minus the hole, meshed
  ElementMesh (*read_elements)(const std::string& path);  ///< triangles and tetrahedra of a file
};

}  // namespace cairn::fem

/// The module's one exported symbol.
extern "C" const cairn::fem::GmshModule* cairn_gmsh_module();
