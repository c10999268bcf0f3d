// Closed triangle surfaces from CAD and mesh files (STL ASCII/binary, OBJ, PLY, OFF) as the
// shapes of 3D bodies ([[body]] shape `mesh`, docs/geometry.md).
//
// read_surface_mesh() reads the file with CGAL's IO readers (no parser of our own), checks it and
// refuses, with a message naming the file and the fault, a surface that cannot bound a volume:
// an empty or unreadable (truncated) file, a binary STL whose triangle count disagrees with its
// size, a degenerate face (repeated vertex or zero area), open edges (a border: not watertight),
// edges shared by more than two faces, self-intersections, a zero enclosed volume. An
// inconsistent or inward orientation is repaired (CGAL Polygon_mesh_processing) and reported as
// a warning. Faces with more than three vertices (OBJ quads) are triangulated.
//
// The inside test classifies lattice points line by line: one query of the AABB tree per line
// parallel to x gives the x at which the line crosses the surface (each crossing decided by exact
// 2D orientation predicates in the y-z plane), and a point is inside when an odd number of
// crossings lie below its x (the even-odd rule, which also handles cavities and several shells).
// A line that meets an edge or vertex of the surface exactly is not trusted: its points are
// classified one by one by CGAL::Side_of_triangle_mesh (ray shooting with random directions).
//
// CGAL is included only by surface_mesh.cpp; this header is free of it.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace cairn::geometry {

/// Placement of a mesh file's coordinates in the model: x = R (scale x_file) + translate, R the
/// rotation by Euler angles (degrees) about x, then y, then z (fixed axes: R = Rz Ry Rx).
struct MeshPlacement {
  double scale = 1.0;  ///< includes the file's unit in the model's length unit
  std::array<double, 3> rotate_degrees{0.0, 0.0, 0.0};
  std::array<double, 3> translate{0.0, 0.0, 0.0};
};

/// x = R (scale x_file) + translate.
std::array<double, 3> place(const MeshPlacement& placement, const std::array<double, 3>& x_file);

/// Length of one `unit` ("m", "dm", "cm", "mm", "um", "in", "ft") in metres; throws
/// std::invalid_argument for another name.
double unit_in_metres(const std::string& unit);
/// The unit names unit_in_metres() knows.
const std::vector<std::string>& unit_names();

/// Memo of the last line's crossings, one per caller (the test is const and thread-safe with
/// one LineCache per thread).
struct LineCache {
  bool valid = false;
  double y = 0.0, z = 0.0;
  bool exact = true;              ///< false: the line touched an edge or vertex (per-point test)
  std::vector<double> crossings;  ///< sorted x of the crossings
};

class SurfaceMesh {
 public:
  ~SurfaceMesh();
  SurfaceMesh(const SurfaceMesh&) = delete;
  SurfaceMesh& operator=(const SurfaceMesh&) = delete;

  /// Is (x, y, z) inside the closed surface? Points on the surface count as either side.
  [[nodiscard]] bool inside(double x, double y, double z, LineCache& cache) const;

  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] double volume() const { return volume_; }  ///< enclosed volume (model units)
  [[nodiscard]] const std::array<double, 3>& lo() const { return lo_; }  ///< bounding box
  [[nodiscard]] const std::array<double, 3>& hi() const { return hi_; }
  [[nodiscard]] std::size_t n_triangles() const { return n_triangles_; }
  [[nodiscard]] std::size_t n_vertices() const { return n_vertices_; }
  [[nodiscard]] std::size_t n_shells() const { return n_shells_; }  ///< connected components
  /// Heap bytes the AABB tree took when it was built (measured by mallinfo2).
  [[nodiscard]] std::size_t tree_bytes() const { return tree_bytes_; }
  /// Repairs made while reading (an orientation turned outward), one sentence each.
  [[nodiscard]] const std::vector<std::string>& warnings() const { return warnings_; }
  /// The cut of the plane z = `z` through the surface (CGAL::Polygon_mesh_slicer): its polylines
  /// as [x, y] vertices, each closed one without its repeated last vertex; `open` counts the
  /// polylines that do not close (the plane runs along a face or an edge).
  struct Cut {
    std::vector<std::vector<std::array<double, 2>>> loops;
    std::size_t open = 0;
  };
  [[nodiscard]] Cut slice(double z) const;

  friend std::shared_ptr<const SurfaceMesh> read_surface_mesh(const std::string& path,
                                                               const MeshPlacement& placement);

 private:
  SurfaceMesh();
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string file_;
  double volume_ = 0.0;
  std::array<double, 3> lo_{}, hi_{};
  std::size_t n_triangles_ = 0, n_vertices_ = 0, n_shells_ = 0, tree_bytes_ = 0;
  std::vector<std::string> warnings_;
};

/// The run summary's line for a body filled from `mesh`: its particles' volume (n_particles of
/// particle_volume each) beside the mesh's own volume, their relative difference, the mesh's size.
std::string volume_note(const std::string& body, const SurfaceMesh& mesh, long long n_particles,
                        double particle_volume);

/// Read, check, place and index the surface in `path`. Throws std::invalid_argument whose text
/// names the file and the fault (see the top of this file).
std::shared_ptr<const SurfaceMesh> read_surface_mesh(const std::string& path, const MeshPlacement& placement);

}  // namespace cairn::geometry
