// Gmsh elements as particles (volume_mesh.hpp).
#include "cairn/geometry/volume_mesh.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "cairn/fem/gmsh_module.hpp"

namespace cairn::geometry {

namespace {

/// A point of a rule in barycentric coordinates, with its weight (the weights sum to 1).
struct RulePoint {
  std::array<double, 4> lambda;
  double weight;
};

/// The standard symmetric rules on simplices (e.g. Zienkiewicz, Taylor & Zhu, The Finite Element
/// Method: Its Basis and Fundamentals, 6th ed., numerical integration on triangles and
/// tetrahedra; the rules CB-Geo MPM places its material points by): 1 point (the centroid,
/// exact for linear fields); 3 points on triangles at (2/3, 1/6, 1/6) and permutations, 4 on
/// tetrahedra at (a, b, b, b) and permutations with a = (5 + 3 sqrt 5) / 20, b = (5 - sqrt 5) / 20,
/// all of equal weight (exact for quadratic fields).
std::vector<RulePoint> rule(int dimension, int n) {
  if (n == 1) {
    const double c = 1.0 / (dimension + 1);
    return {{{c, c, c, dimension == 3 ? c : 0.0}, 1.0}};
  }
  std::vector<RulePoint> out;
  if (dimension == 2) {
    for (int i = 0; i < 3; ++i) {
      std::array<double, 4> l{1.0 / 6.0, 1.0 / 6.0, 1.0 / 6.0, 0.0};
      l[static_cast<std::size_t>(i)] = 2.0 / 3.0;
      out.push_back({l, 1.0 / 3.0});
    }
  } else {
    const double a = (5.0 + 3.0 * std::sqrt(5.0)) / 20.0, b = (5.0 - std::sqrt(5.0)) / 20.0;
    for (int i = 0; i < 4; ++i) {
      std::array<double, 4> l{b, b, b, b};
      l[static_cast<std::size_t>(i)] = a;
      out.push_back({l, 0.25});
    }
  }
  return out;
}

}  // namespace

std::shared_ptr<const PointSet> read_volume_mesh(const std::string& path, int dimension, int quadrature,
                                                 const MeshPlacement& placement) {
  auto fail = [&](const std::string& what) {
    throw std::invalid_argument(fmt::format("volume mesh '{}': {}", path, what));
  };
  const bool rule_ok = quadrature == 1 || (dimension == 2 && quadrature == 3) || (dimension == 3 && quadrature == 4);
  if (!rule_ok)
    fail(fmt::format("quadrature = {}: {}D takes 1 or {} points per element", quadrature, dimension,
                     dimension == 2 ? 3 : 4));
  fem::ElementMesh m;
  try {
    m = fem::read_gmsh_elements(path);
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
  const std::size_t n_elements = dimension == 2 ? m.triangles.size() : m.tetrahedra.size();
  if (n_elements == 0)
    fail(fmt::format("no {} in it ({} triangles, {} tetrahedra{}{})", dimension == 2 ? "3-node triangles" : "4-node tetrahedra",
                     m.triangles.size(), m.tetrahedra.size(), m.other.empty() ? "" : ", ", m.other));
  if (!m.other.empty())
    fail(fmt::format("{}: only 3-node triangles (2D) and 4-node tetrahedra (3D) are read", m.other));
  if (dimension == 2) {
    if (!m.tetrahedra.empty()) fail(fmt::format("{} tetrahedra in a 2D model", m.tetrahedra.size()));
    for (std::size_t i = 0; i < m.nodes.size(); ++i)
      if (m.nodes[i][2] != 0.0) fail(fmt::format("a 2D mesh must lie in z = 0: node {} at z = {}", i + 1, m.nodes[i][2]));
  }
  auto set = std::make_shared<PointSet>();
  set->file = path;
  set->dimension = dimension;
  for (auto& v : set->lo) v = std::numeric_limits<double>::infinity();
  for (auto& v : set->hi) v = -std::numeric_limits<double>::infinity();
  std::vector<std::array<double, 3>> x(m.nodes.size());
  for (std::size_t i = 0; i < m.nodes.size(); ++i) x[i] = place(placement, m.nodes[i]);
  const auto points = rule(dimension, quadrature);
  const std::size_t corners = static_cast<std::size_t>(dimension) + 1;
  for (std::size_t e = 0; e < n_elements; ++e) {
    std::array<std::int32_t, 4> c{};
    for (std::size_t k = 0; k < corners; ++k)
      c[k] = dimension == 2 ? m.triangles[e][k] : m.tetrahedra[e][k];
    // |det| / 2 (triangle) or / 6 (tetrahedron) of the edge vectors from corner 0.
    double size = 0.0;
    const auto& p0 = x[static_cast<std::size_t>(c[0])];
    double u[3][3];
    for (std::size_t k = 1; k < corners; ++k)
      for (std::size_t a = 0; a < 3; ++a) u[k - 1][a] = x[static_cast<std::size_t>(c[k])][a] - p0[a];
    if (dimension == 2) {
      size = 0.5 * std::abs(u[0][0] * u[1][1] - u[0][1] * u[1][0]);
    } else {
      size = std::abs(u[0][0] * (u[1][1] * u[2][2] - u[1][2] * u[2][1]) - u[0][1] * (u[1][0] * u[2][2] - u[1][2] * u[2][0]) +
                      u[0][2] * (u[1][0] * u[2][1] - u[1][1] * u[2][0])) /
             6.0;
    }
    if (!(size > 0.0))
      fail(fmt::format("degenerate element {} (Gmsh tag): zero {}", dimension == 2 ? m.triangle_tags[e] : m.tetrahedron_tags[e],
                       dimension == 2 ? "area" : "volume"));
    for (const RulePoint& q : points) {
      std::array<double, 3> p{0.0, 0.0, 0.0};
      for (std::size_t k = 0; k < corners; ++k)
        for (std::size_t a = 0; a < 3; ++a) p[a] += q.lambda[k] * x[static_cast<std::size_t>(c[k])][a];
      for (std::size_t a = 0; a < 3; ++a) {
        set->lo[a] = std::min(set->lo[a], p[a]);
        set->hi[a] = std::max(set->hi[a], p[a]);
      }
      set->position.push_back(p);
      set->volume.push_back(q.weight * size);
      set->total_volume += q.weight * size;
    }
  }
  return set;
}

}  // namespace cairn::geometry
