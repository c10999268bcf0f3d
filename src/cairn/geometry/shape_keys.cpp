// Keys of the shape kinds read from files (shape_keys.hpp; docs/geometry.md).
#include "cairn/geometry/shape_keys.hpp"

#include <limits>

#include "cairn/geometry/surface_mesh.hpp"

namespace cairn::geometry {

const std::vector<ShapeKindDecl>& shape_kinds() {
  static const std::vector<ShapeKindDecl> kinds{
      {"mesh", {false, false, true},
       "Inside of a closed triangle surface from a file: STL (ASCII or binary), OBJ, PLY or OFF "
       "(docs/geometry.md)."},
      {"volume_mesh", {false, true, true},
       "Elements of a Gmsh mesh (.msh, or .geo meshed on reading): 3-node triangles (2D) or 4-node "
       "tetrahedra (3D), one particle per element or per quadrature point (docs/geometry.md)."},
      {"outline", {false, true, false},
       "Inside of closed loops read from a CSV file, the first the outside and the others holes, or "
       "of the cut of a closed surface mesh at z = slice_z (docs/geometry.md)."},
      {"points", {false, true, true},
       "Particles given one by one in a CSV or HDF5 file: position, volume, optional velocity, "
       "temperature and initial stress (docs/geometry.md)."},
      {"image_stack", {false, false, true},
       "Voxels of a stack of grey-level PNG slices (a CT scan) whose level lies in a range, one body per "
       "material shade, as `image` in 2D (docs/geometry.md)."},
  };
  return kinds;
}

std::vector<KeyDecl> shape_keys() {
  auto key = [](const std::string& name, KeyType type, const std::string& value, const std::string& doc) {
    KeyDecl d;
    d.section = "body.shape.mesh";
    d.name = name;
    d.type = type;
    d.default_value = value;
    d.required = value.empty();
    d.doc = doc;
    return d;
  };
  std::vector<KeyDecl> k;
  k.push_back(key("file", KeyType::string, "",
                  "Closed triangle surface (.stl ASCII or binary, .obj, .ply, .off), relative to the "
                  "directory of the input file; faces with more vertices are triangulated."));
  k.push_back(key("units", KeyType::string, "\"model\"",
                  "Length unit of the file's coordinates, converted to the model's length unit "
                  "(simulation.units): model (no conversion) or m, dm, cm, mm, um, in, ft."));
  k.back().choices = [] {
    std::vector<std::string> names{"model"};
    for (const auto& u : unit_names()) names.push_back(u);
    return names;
  };
  k.push_back(key("scale", KeyType::real, "1.0", "Factor on the file's coordinates (after units)."));
  k.back().min = std::numeric_limits<double>::denorm_min();
  k.push_back(key("rotate", KeyType::real_array, "[0.0, 0.0, 0.0]",
                  "Euler angles in degrees about the fixed x, then y, then z axis (R = Rz Ry Rx), "
                  "turning the scaled surface about the origin."));
  k.push_back(key("translate", KeyType::real_array, "[0.0, 0.0, 0.0]",
                  "Shift [x, y, z] applied last: x = R (scale x_file) + translate."));
  // volume_mesh: the file, the rule, and the mesh's placement keys.
  const std::size_t n_mesh = k.size();
  k.push_back(key("file", KeyType::string, "",
                  "Gmsh mesh (.msh) or geometry (.geo, meshed when read), relative to the directory of the "
                  "input file: its 3-node triangles (2D, in z = 0) or 4-node tetrahedra (3D)."));
  k.push_back(key("quadrature", KeyType::integer, "1",
                  "Particles per element: 1 (the centroid) or the points of the symmetric Gauss rule, 3 on a "
                  "triangle, 4 on a tetrahedron; each with its share of the element's area/volume."));
  k.back().min = 1;
  k.back().max = 4;
  for (std::size_t i = 1; i < n_mesh; ++i) k.push_back(k[i]);  // units, scale, rotate, translate
  for (std::size_t i = n_mesh; i < k.size(); ++i) k[i].section = "body.shape.volume_mesh";
  // outline: the file and its placement.
  const std::size_t n_outline = k.size();
  k.push_back(key("file", KeyType::string, "",
                  "CSV file of vertices \"x, y\", one per line, loops separated by blank lines: the first "
                  "loop the outside, the others holes; or a closed surface mesh (.stl, .obj, .ply, .off) cut by "
                  "the plane z = slice_z. Relative to the input file's directory."));
  k.push_back(key("scale", KeyType::real, "1.0", "Factor on the file's coordinates."));
  k.back().min = std::numeric_limits<double>::denorm_min();
  k.push_back(key("translate", KeyType::real_array, "[0.0, 0.0]", "Shift [x, y] applied after scale."));
  k.push_back(key("slice_z", KeyType::real, "0.0",
                  "A surface mesh file: the height z (of the scaled coordinates) of the plane whose cut through "
                  "the surface is the outline; its closed curves are the loops (even-odd rule)."));
  for (std::size_t i = n_outline; i < k.size(); ++i) k[i].section = "body.shape.outline";
  KeyDecl points = key("file", KeyType::string, "",
                        "CSV file with a header row x, y (, z), volume (an area in 2D), optional vx, vy (, vz), "
                        "temperature and initial stress (sxx, syy, szz, syz, sxz, sxy in 3D; sxx, syy, sxy in 2D), one "
                        "particle per row; or HDF5 (.h5, .hdf5) with datasets position (n x D), volume (n), optional "
                        "velocity, temperature, stress (n x 6 / n x 3). Relative to the input file's directory.");
  points.section = "body.shape.points";
  k.push_back(points);
  // image_stack: the slices, their placement and the grey levels of the body.
  const std::size_t n_stack = k.size();
  k.push_back(key("folder", KeyType::string, "",
                  "Folder of the slices (PNG files, any kind as for `image`), relative to the directory of the "
                  "input file; slice 0, at the lowest z, is the file with the lowest number in its name, the "
                  "numbers consecutive."));
  k.push_back(key("pattern", KeyType::string, "\"*.png\"",
                  "Glob (fnmatch: *, ?, [...]) that the slices' file names match, e.g. \"ct_*.png\"; other files "
                  "in the folder are not read."));
  k.push_back(key("pixel_size", KeyType::real, "", "Edge of one (square) pixel of a slice in length units."));
  k.back().min = std::numeric_limits<double>::denorm_min();
  k.push_back(key("slice_spacing", KeyType::real, "",
                  "Distance between slices along z in length units: slice k covers z in [z0 + k slice_spacing, "
                  "z0 + (k + 1) slice_spacing)."));
  k.back().min = std::numeric_limits<double>::denorm_min();
  k.push_back(key("origin", KeyType::real_array, "[0.0, 0.0, 0.0]",
                  "Position [x0, y0, z0] of the lower-left corner of slice 0: each slice covers width * "
                  "pixel_size by height * pixel_size from there, its first (top) row at the highest y."));
  k.push_back(key("levels", KeyType::integer_array, "",
                  "Grey levels [lo, hi] (0 = black, 255 = white), lo <= hi: a particle position belongs to the "
                  "body when the voxel under it has a level in lo..hi."));
  k.back().min = 0;
  k.back().max = 255;
  for (std::size_t i = n_stack; i < k.size(); ++i) k[i].section = "body.shape.image_stack";
  return k;
}

}  // namespace cairn::geometry
