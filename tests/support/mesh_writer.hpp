// Small closed triangle surfaces made in the tests (boxes of voxels, UV spheres, tori) and
// written as STL (ASCII, binary), OBJ, PLY (ASCII, binary) and OFF files, so that the mesh
// readers (CGAL's, geometry/surface_mesh.cpp) are tested on files no other tool made.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace cairn::test {

struct TriangleSurface {
  std::vector<std::array<double, 3>> vertices;
  std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from outside
  /// Append another surface (a second shell).
  void add(const TriangleSurface& other) {
    const int offset = static_cast<int>(vertices.size());
    vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
    for (auto t : other.triangles) triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  /// Every triangle turned (normals into the body).
  void flip() {
    for (auto& t : triangles) std::swap(t[1], t[2]);
  }
};

/// The outer surface of a set of unit voxels (i, j, k) scaled by `h` and shifted by `origin`:
/// each face between a voxel of the set and one outside becomes two triangles, vertices shared
/// by lattice index. No two voxels of the set may touch along an edge only (that surface would
/// not be a manifold). A voxel missing inside a block makes a cavity, apart blocks several shells.
inline TriangleSurface voxel_surface(const std::set<std::array<int, 3>>& voxels, double h,
                                     std::array<double, 3> origin = {0.0, 0.0, 0.0}) {
  TriangleSurface s;
  std::map<std::array<int, 3>, int> index;
  auto vertex = [&](std::array<int, 3> c) {
    auto [it, added] = index.emplace(c, static_cast<int>(s.vertices.size()));
    if (added) s.vertices.push_back({origin[0] + h * c[0], origin[1] + h * c[1], origin[2] + h * c[2]});
    return it->second;
  };
  for (const auto& v : voxels)
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        std::array<int, 3> n = v;
        n[axis] += side ? 1 : -1;
        if (voxels.count(n)) continue;
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        std::array<int, 3> c0 = v;
        c0[axis] += side;
        std::array<int, 3> c1 = c0, c2 = c0, c3 = c0;
        c1[u] += 1;
        c2[u] += 1;
        c2[w] += 1;
        c3[w] += 1;
        // (u, w, axis) is right-handed: c0 c1 c2 c3 runs counter-clockwise seen from +axis.
        const int a = vertex(c0), b = vertex(c1), c = vertex(c2), d = vertex(c3);
        if (side) {
          s.triangles.push_back({a, b, c});
          s.triangles.push_back({a, c, d});
        } else {
          s.triangles.push_back({a, c, b});
          s.triangles.push_back({a, d, c});
        }
      }
  return s;
}

/// Voxels of the box [lo, hi) in voxel indices.
inline std::set<std::array<int, 3>> voxel_box(std::array<int, 3> lo, std::array<int, 3> hi) {
  std::set<std::array<int, 3>> v;
  for (int i = lo[0]; i < hi[0]; ++i)
    for (int j = lo[1]; j < hi[1]; ++j)
      for (int k = lo[2]; k < hi[2]; ++k) v.insert({i, j, k});
  return v;
}

/// UV sphere: n_lat bands from pole to pole, n_lon segments around z; vertices on the sphere.
inline TriangleSurface uv_sphere(std::array<double, 3> c, double r, int n_lat, int n_lon) {
  TriangleSurface s;
  const double pi = std::numbers::pi;
  s.vertices.push_back({c[0], c[1], c[2] + r});
  for (int i = 1; i < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      const double t = pi * i / n_lat, p = 2.0 * pi * j / n_lon;
      s.vertices.push_back({c[0] + r * std::sin(t) * std::cos(p), c[1] + r * std::sin(t) * std::sin(p),
                            c[2] + r * std::cos(t)});
    }
  s.vertices.push_back({c[0], c[1], c[2] - r});
  const int south = static_cast<int>(s.vertices.size()) - 1;
  auto at = [&](int i, int j) { return 1 + (i - 1) * n_lon + (j % n_lon); };
  for (int j = 0; j < n_lon; ++j) {
    s.triangles.push_back({0, at(1, j), at(1, j + 1)});
    s.triangles.push_back({south, at(n_lat - 1, j + 1), at(n_lat - 1, j)});
  }
  for (int i = 1; i + 1 < n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return s;
}

/// Torus about the z axis through c: tube radius r around the circle of radius R; n_u segments
/// around z, n_v around the tube; vertices on the torus.
inline TriangleSurface torus(std::array<double, 3> c, double R, double r, int n_u, int n_v) {
  TriangleSurface s;
  const double pi = std::numbers::pi;
  for (int i = 0; i < n_u; ++i)
    for (int j = 0; j < n_v; ++j) {
      const double u = 2.0 * pi * i / n_u, v = 2.0 * pi * j / n_v;
      const double rho = R + r * std::cos(v);
      s.vertices.push_back({c[0] + rho * std::cos(u), c[1] + rho * std::sin(u), c[2] + r * std::sin(v)});
    }
  auto at = [&](int i, int j) { return (i % n_u) * n_v + (j % n_v); };
  for (int i = 0; i < n_u; ++i)
    for (int j = 0; j < n_v; ++j) {
      s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return s;
}

/// Volume enclosed (divergence theorem; positive for outward triangles).
inline double enclosed_volume(const TriangleSurface& s) {
  double v = 0.0;
  for (auto t : s.triangles) {
    const auto &a = s.vertices[t[0]], &b = s.vertices[t[1]], &c = s.vertices[t[2]];
    v += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
  }
  return v;
}

inline double surface_area(const TriangleSurface& s) {
  double area = 0.0;
  for (auto t : s.triangles) {
    const auto &a = s.vertices[t[0]], &b = s.vertices[t[1]], &c = s.vertices[t[2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
    area += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  return area;
}

inline void write_ascii_stl(const std::string& path, const TriangleSurface& s) {
  std::ofstream f(path);
  f.precision(17);
  f << "solid test\n";
  for (auto t : s.triangles) {
    f << " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const auto& p = s.vertices[t[k]];
      f << "   vertex " << p[0] << " " << p[1] << " " << p[2] << "\n";
    }
    f << "  endloop\n endfacet\n";
  }
  f << "endsolid test\n";
}

/// Binary STL: 80-byte header, triangle count, 50 bytes per triangle (floats, little endian).
/// `count` overrides the stored triangle count (a corrupt file) when not negative.
inline void write_binary_stl(const std::string& path, const TriangleSurface& s, long long count = -1) {
  std::ofstream f(path, std::ios::binary);
  char header[80] = {};
  std::strncpy(header, "binary test mesh", sizeof header);
  f.write(header, 80);
  const auto n = static_cast<std::uint32_t>(count >= 0 ? count : static_cast<long long>(s.triangles.size()));
  f.write(reinterpret_cast<const char*>(&n), 4);
  for (auto t : s.triangles) {
    float v[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) v[3 + 3 * k + a] = static_cast<float>(s.vertices[t[k]][a]);
    f.write(reinterpret_cast<const char*>(v), sizeof v);
    const std::uint16_t attribute = 0;
    f.write(reinterpret_cast<const char*>(&attribute), 2);
  }
}

inline void write_obj(const std::string& path, const TriangleSurface& s) {
  std::ofstream f(path);
  f.precision(17);
  f << "# test mesh\n";
  for (const auto& p : s.vertices) f << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
  for (auto t : s.triangles) f << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
}

inline void write_off(const std::string& path, const TriangleSurface& s) {
  std::ofstream f(path);
  f.precision(17);
  f << "OFF\n" << s.vertices.size() << " " << s.triangles.size() << " 0\n";
  for (const auto& p : s.vertices) f << p[0] << " " << p[1] << " " << p[2] << "\n";
  for (auto t : s.triangles) f << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
}

inline void write_ply(const std::string& path, const TriangleSurface& s, bool binary = false) {
  std::ofstream f(path, std::ios::binary);
  f << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\nelement vertex " << s.vertices.size()
    << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << s.triangles.size()
    << "\nproperty list uchar int vertex_indices\nend_header\n";
  f.precision(17);
  for (const auto& p : s.vertices) {
    if (binary) f.write(reinterpret_cast<const char*>(p.data()), 3 * sizeof(double));
    else f << p[0] << " " << p[1] << " " << p[2] << "\n";
  }
  for (auto t : s.triangles) {
    if (binary) {
      const unsigned char three = 3;
      f.write(reinterpret_cast<const char*>(&three), 1);
      f.write(reinterpret_cast<const char*>(t.data()), 3 * sizeof(int));
    } else {
      f << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
    }
  }
}

}  // namespace cairn::test
