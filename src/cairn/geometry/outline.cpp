// 2D outlines from CSV files and from cuts through surface meshes (outline.hpp).
#include "cairn/geometry/outline.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/geometry/text.hpp"

namespace cairn::geometry {

namespace {

double twice_signed_area(const Loop& loop) {
  double a = 0.0;
  for (std::size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++)
    a += loop[j][0] * loop[i][1] - loop[i][0] * loop[j][1];
  return a;
}

/// Sign of the cross product (b - a) x (c - a): exact enough for input vertices that are not
/// almost collinear; a zero counts as touching.
int orientation(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c) {
  const double v = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  return (v > 0.0) - (v < 0.0);
}

bool on_segment(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& p) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= p[1] &&
         p[1] <= std::max(a[1], b[1]);
}

/// Do segments ab and cd cross or touch?
bool meet(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c,
          const std::vector<double>& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d), o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) || (o3 == 0 && on_segment(c, d, a)) ||
         (o4 == 0 && on_segment(c, d, b));
}

/// The loops' checks: at least 3 vertices and some area each (a repeated last vertex dropped),
/// no two edges meeting but neighbours of one loop, and with `nested` every hole inside the first
/// loop. `fail(line, what)` throws; first_line[k] is the line of loop k (0: none).
template <class Fail>
void check_loops(std::vector<Loop>& loops, const std::vector<long>& first_line, bool nested, Fail&& fail) {
  for (std::size_t k = 0; k < loops.size(); ++k) {
    Loop& loop = loops[k];
    if (loop.size() > 1 && loop.front() == loop.back()) loop.pop_back();
    const std::string which = k == 0 ? "the outside loop" : fmt::format("hole {}", k);
    if (loop.size() < 3)
      fail(first_line[k], fmt::format("{} has {} vertices, fewer than 3", which, loop.size()));
    if (twice_signed_area(loop) == 0.0) fail(first_line[k], fmt::format("{} encloses no area", which));
  }
  // Simple and apart: no two edges meet but neighbours of one loop at their shared vertex.
  struct Edge {
    std::size_t loop, index;
  };
  std::vector<Edge> edges;
  for (std::size_t k = 0; k < loops.size(); ++k)
    for (std::size_t i = 0; i < loops[k].size(); ++i) edges.push_back({k, i});
  auto end_of = [&](const Edge& e, int s) -> const std::vector<double>& {
    const Loop& l = loops[e.loop];
    return l[(e.index + static_cast<std::size_t>(s)) % l.size()];
  };
  for (std::size_t p = 0; p < edges.size(); ++p)
    for (std::size_t q = p + 1; q < edges.size(); ++q) {
      const Edge &e = edges[p], &f = edges[q];
      if (e.loop == f.loop) {
        const std::size_t n = loops[e.loop].size();
        if (f.index == e.index + 1 || (e.index == 0 && f.index == n - 1)) continue;  // neighbours
      }
      if (meet(end_of(e, 0), end_of(e, 1), end_of(f, 0), end_of(f, 1)))
        fail(first_line[e.loop], fmt::format("edge {} of {} and edge {} of {} cross or touch, near ({}, {})", e.index + 1,
                                             e.loop == 0 ? "the outside loop" : fmt::format("hole {}", e.loop),
                                             f.index + 1, f.loop == 0 ? "the outside loop" : fmt::format("hole {}", f.loop),
                                             end_of(f, 0)[0], end_of(f, 0)[1]));
    }
  if (nested)
    for (std::size_t k = 1; k < loops.size(); ++k)
      if (!inside_loop(loops[0], loops[k][0][0], loops[k][0][1]))
        fail(first_line[k], fmt::format("hole {} lies outside the outside loop", k));
}

}  // namespace

bool inside_loop(const Loop& v, double x, double y) {
  bool in = false;  // even-odd crossing rule: edges crossed by the ray from (x, y) towards +x
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++)
    if ((v[i][1] > y) != (v[j][1] > y) && x < (v[j][0] - v[i][0]) * (y - v[i][1]) / (v[j][1] - v[i][1]) + v[i][0])
      in = !in;
  return in;
}

bool inside_loops(const std::vector<Loop>& loops, double x, double y) {
  bool in = false;
  for (const Loop& v : loops) in = in != inside_loop(v, x, y);
  return in;
}

double loops_area(const std::vector<Loop>& loops) {
  // Even-odd: a loop inside an even number of others adds its area, inside an odd number it cuts a hole.
  double area = 0.0;
  for (std::size_t k = 0; k < loops.size(); ++k) {
    std::size_t depth = 0;
    for (std::size_t j = 0; j < loops.size(); ++j)
      depth += j != k && inside_loop(loops[j], loops[k][0][0], loops[k][0][1]);
    area += (depth % 2 == 0 ? 0.5 : -0.5) * std::abs(twice_signed_area(loops[k]));
  }
  return area;
}

std::vector<Loop> read_outline_csv(const std::string& path, double scale, const std::vector<double>& translate) {
  auto fail = [&](long line, const std::string& what) {
    throw std::invalid_argument(line > 0 ? fmt::format("outline file '{}', line {}: {}", path, line, what)
                                         : fmt::format("outline file '{}': {}", path, what));
  };
  std::ifstream in(path);
  if (!in) fail(0, "cannot open it");
  std::vector<Loop> loops(1);
  std::vector<long> first_line(1, 0);
  std::string line;
  long number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string t = trim(line);
    if (!t.empty() && t[0] == '#') continue;
    if (t.empty()) {
      if (!loops.back().empty()) {
        loops.emplace_back();
        first_line.push_back(0);
      }
      continue;
    }
    const auto comma = t.find(',');
    if (comma == std::string::npos || t.find(',', comma + 1) != std::string::npos)
      fail(number, fmt::format("'{}' is not two fields x, y", t));
    const std::string fx = trim(t.substr(0, comma)), fy = trim(t.substr(comma + 1));
    if (fx == "x" && fy == "y" && loops.size() == 1 && loops[0].empty()) continue;  // the header
    double v[2];
    const std::string* fields[2] = {&fx, &fy};
    for (int a = 0; a < 2; ++a) {
      const auto [end, ec] = std::from_chars(fields[a]->data(), fields[a]->data() + fields[a]->size(), v[a]);
      if (ec != std::errc() || end != fields[a]->data() + fields[a]->size() || !std::isfinite(v[a]))
        fail(number, fmt::format("'{}' is not a finite number", *fields[a]));
    }
    if (first_line.back() == 0) first_line.back() = number;
    loops.back().push_back({scale * v[0] + translate[0], scale * v[1] + translate[1]});
  }
  if (loops.back().empty()) {
    loops.pop_back();
    first_line.pop_back();
  }
  if (loops.empty()) fail(0, "no loop (no vertex lines)");
  check_loops(loops, first_line, true, [&](long line, const std::string& what) { fail(line, what); });
  return loops;
}

std::vector<Loop> read_outline(const std::string& path, double scale, const std::vector<double>& translate,
                               double slice_z) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext != ".stl" && ext != ".obj" && ext != ".ply" && ext != ".off") return read_outline_csv(path, scale, translate);
  MeshPlacement placement;
  placement.scale = scale;
  const auto mesh = read_surface_mesh(path, placement);  // closed, oriented, without self-intersections
  auto fail = [&](long, const std::string& what) {
    throw std::invalid_argument(fmt::format("outline from the surface mesh '{}' cut at z = {}: {}", path, slice_z, what));
  };
  const SurfaceMesh::Cut cut = mesh->slice(slice_z);
  if (cut.open > 0)
    fail(0, fmt::format("{} of the cut's {} polylines do not close (the plane runs along a face or an edge of the "
                        "surface; move slice_z a little)",
                        cut.open, cut.open + cut.loops.size()));
  if (cut.loops.empty())
    fail(0, fmt::format("the plane does not cut the surface (its z runs from {} to {} after scale)", mesh->lo()[2],
                        mesh->hi()[2]));
  std::vector<Loop> loops;
  for (const auto& l : cut.loops) {
    Loop loop;
    for (const auto& v : l) loop.push_back({v[0] + translate[0], v[1] + translate[1]});
    loops.push_back(std::move(loop));
  }
  // The largest loop first (an outside); several islands and holes inside holes by the even-odd rule.
  std::stable_sort(loops.begin(), loops.end(), [](const Loop& a, const Loop& b) {
    return std::abs(twice_signed_area(a)) > std::abs(twice_signed_area(b));
  });
  check_loops(loops, std::vector<long>(loops.size(), 0), false, fail);
  return loops;
}

}  // namespace cairn::geometry
