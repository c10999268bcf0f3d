// The [[body]] shape kinds of the geometry room and their keys (sections "body.shape.<kind>"),
// declared beside the readers that use them; input/schema.cpp adds them to the input's declarations.
#pragma once

#include <string>
#include <vector>

#include "cairn/config/keys.hpp"

namespace cairn::geometry {

/// A shape kind of this room: its name, the dimensions it is valid in (valid_in[D - 1]), a doc line.
struct ShapeKindDecl {
  std::string name;
  bool valid_in[3];
  std::string doc;
};

/// The shape kinds read from files: mesh (3D surface meshes), volume_mesh (Gmsh elements),
/// outline (2D loops with holes), points (CSV/HDF5 point files), image_stack (3D PNG slices).
const std::vector<ShapeKindDecl>& shape_kinds();

/// Their parameters, as key declarations of sections "body.shape.<kind>".
std::vector<KeyDecl> shape_keys();

}  // namespace cairn::geometry
