// Mesh checks and the structured generators (the Gmsh parts are in gmsh_mesh.cpp).
#include "cairn/fem/mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "cairn/config/errors.hpp"

namespace cairn::fem {

double twice_area(const TriangleMesh& mesh, std::size_t e) {
  const auto& t = mesh.triangles[e];
  const Vec<2> a = mesh.nodes[t[1]] - mesh.nodes[t[0]];
  const Vec<2> b = mesh.nodes[t[2]] - mesh.nodes[t[0]];
  return a[0] * b[1] - a[1] * b[0];
}

void check_mesh(const TriangleMesh& mesh, const std::string& key) {
  const auto bad = [&](const std::string& expected, const std::string& found) {
    throw InputError(mesh.source, 0, key, expected, found);
  };
  if (mesh.triangles.empty()) bad("a mesh with at least one 3-node triangle", "no triangle");
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
    if (!mesh.nodes[i].allFinite()) bad("finite node coordinates", fmt::format("node {} is not finite", i + 1));
  const auto n = static_cast<std::int64_t>(mesh.nodes.size());
  for (std::size_t e = 0; e < mesh.triangles.size(); ++e) {
    const auto& t = mesh.triangles[e];
    const std::size_t tag = e < mesh.element_tags.size() ? mesh.element_tags[e] : e + 1;
    for (const std::int32_t v : t)
      if (v < 0 || v >= n) bad("elements whose nodes exist", fmt::format("element {} refers to a missing node", tag));
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      bad("three distinct nodes per element", fmt::format("element {} repeats a node", tag));
    double longest = 0.0;
    for (int k = 0; k < 3; ++k)
      longest = std::max(longest, (mesh.nodes[t[(k + 1) % 3]] - mesh.nodes[t[k]]).squaredNorm());
    const double a2 = twice_area(mesh, e);
    if (std::abs(a2) <= 1e-12 * longest)
      bad("elements of non-zero area", fmt::format("element {} is degenerate (area {:.3g})", tag, 0.5 * a2));
    if (a2 < 0.0)
      bad("counter-clockwise elements (positive area)",
          fmt::format("element {} is inverted (area {:.3g}, nodes clockwise)", tag, 0.5 * a2));
  }
}

namespace {

TriangleMesh structured_box(const BodyShapeConfig& s, double size) {
  TriangleMesh m;
  const Vec<2> lo(s.min[0], s.min[1]), hi(s.max[0], s.max[1]);
  const int nx = std::max(1, static_cast<int>(std::lround((hi[0] - lo[0]) / size)));
  const int ny = std::max(1, static_cast<int>(std::lround((hi[1] - lo[1]) / size)));
  const double hx = (hi[0] - lo[0]) / nx, hy = (hi[1] - lo[1]) / ny;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.nodes.emplace_back(lo[0] + i * hx, lo[1] + j * hy);
  const auto corner = [&](int i, int j) { return static_cast<std::int32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const auto c = static_cast<std::int32_t>(m.nodes.size());
      m.nodes.emplace_back(lo[0] + (i + 0.5) * hx, lo[1] + (j + 0.5) * hy);
      const std::int32_t a = corner(i, j), b = corner(i + 1, j), d = corner(i + 1, j + 1), e = corner(i, j + 1);
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({b, d, c});
      m.triangles.push_back({d, e, c});
      m.triangles.push_back({e, a, c});
    }
  return m;
}

TriangleMesh structured_annulus(const BodyShapeConfig& s, double size) {
  TriangleMesh m;
  const double ri = s.inner_radius, ro = s.outer_radius;
  const int nr = std::max(1, static_cast<int>(std::lround((ro - ri) / size)));
  const int nt = std::max(3, static_cast<int>(std::lround(2.0 * std::numbers::pi * 0.5 * (ri + ro) / size)));
  for (int j = 0; j <= nr; ++j) {
    const double r = ri + (ro - ri) * j / nr;
    for (int k = 0; k < nt; ++k) {
      const double th = 2.0 * std::numbers::pi * k / nt;
      m.nodes.emplace_back(s.center[0] + r * std::cos(th), s.center[1] + r * std::sin(th));
    }
  }
  const auto node = [&](int j, int k) { return static_cast<std::int32_t>(j * nt + (k % nt)); };
  for (int j = 0; j < nr; ++j)
    for (int k = 0; k < nt; ++k) {
      const std::int32_t a = node(j, k), b = node(j, k + 1), c = node(j + 1, k + 1), d = node(j + 1, k);
      if ((j + k) % 2 == 0) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      } else {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, c, d});
      }
    }
  for (auto& t : m.triangles) std::swap(t[1], t[2]);  // built clockwise (theta, then outwards)
  return m;
}

}  // namespace

TriangleMesh generate_structured(const FemConfig& fem) {
  TriangleMesh m = fem.shape.kind == "annulus" ? structured_annulus(fem.shape, fem.size)
                                               : structured_box(fem.shape, fem.size);
  m.source = fmt::format("generated structured {} mesh", fem.shape.kind);
  return m;
}

TriangleMesh make_mesh(const FemConfig& fem) {
  TriangleMesh m;
  std::string key = "fem.shape";
  if (!fem.mesh_file.empty()) {
    m = read_gmsh_file(fem.mesh_file);
    key = "fem.mesh_file";
  } else if (fem.mesher == "structured") {
    m = generate_structured(fem);
  } else {
    m = generate_gmsh(fem);
  }
  check_mesh(m, key);
  return m;
}

}  // namespace cairn::fem
