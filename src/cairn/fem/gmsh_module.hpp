// The interface of the Gmsh mesher module. Gmsh and the libraries it brings (OpenCASCADE, FLTK,
// ... 91 in all) are linked into libcairn_gmsh.so alone, which the program loads the first time
// an FEM run reads or generates a Gmsh mesh (fem/gmsh_mesh.cpp): linked into cairn itself, they
// made every command start 0.16 s later, twice over with the OpenMP restart of app/main.cpp
// (docs/performance.md, "Start-up").
#pragma once

#include <string>

#include "cairn/fem/mesh.hpp"

namespace cairn::fem {

/// Bumped whenever GmshModule or the types it passes change: a module of another version (a
/// stale build) is refused.
inline constexpr int gmsh_module_version = 1;

/// What the module provides. Both functions throw InputError (or std::runtime_error) as the
/// in-program code would; the meshes come back as Gmsh gave them (unchecked, unoriented).
struct GmshModule {
  int version;
  TriangleMesh (*read_file)(const std::string& path);  ///< a .msh file's 3-node triangles
  TriangleMesh (*generate)(const FemConfig& fem);       ///< fem.shape minus the hole, meshed
};

}  // namespace cairn::fem

/// The module's one exported symbol.
extern "C" const cairn::fem::GmshModule* cairn_gmsh_module();
