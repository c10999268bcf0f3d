// Surface meshes as body shapes: reading and checking through CGAL 5.5, the line-by-line inside
// test (surface_mesh.hpp). This is the only translation unit that includes CGAL.
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/util/child_process.hpp"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Polygon_mesh_slicer.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <fmt/format.h>
#include <malloc.h>

#include <algorithm>
#include <boost/function_output_iterator.hpp>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

namespace cairn::geometry {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using Side = CGAL::Side_of_triangle_mesh<Mesh, Kernel>;
using Tree = Side::AABB_tree;
using Polygon = std::vector<std::size_t>;
namespace PMP = CGAL::Polygon_mesh_processing;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::invalid_argument(fmt::format("surface mesh '{}': {}", path, what));
}

std::string point_text(const Point& p) { return fmt::format("({:.6g}, {:.6g}, {:.6g})", p.x(), p.y(), p.z()); }

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

/// A binary STL is an 80-byte header, a 32-bit triangle count n and n records of 50 bytes; an
/// ASCII one starts with "solid" and holds text only. (Some binary headers also start with
/// "solid": a NUL or other control byte in the first kilobyte tells them apart.) Refuses a
/// binary file whose size is not 84 + 50 n before CGAL reads it.
void check_stl_size(const std::string& path, std::uintmax_t size) {
  std::ifstream in(path, std::ios::binary);
  std::string head(static_cast<std::size_t>(std::min<std::uintmax_t>(size, 1024)), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  std::size_t first = head.find_first_not_of(" \t\r\n");
  const bool text = std::none_of(head.begin(), head.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u < 9 || (u > 13 && u < 32);
  });
  if (first != std::string::npos && head.compare(first, 5, "solid") == 0 && text) return;  // ASCII
  if (size < 84) fail(path, fmt::format("a binary STL of {} bytes, shorter than its 84-byte header (truncated)", size));
  std::uint32_t n = 0;
  for (int i = 0; i < 4; ++i) n |= static_cast<std::uint32_t>(static_cast<unsigned char>(head[80 + i])) << (8 * i);
  const std::uintmax_t expected = 84 + 50 * static_cast<std::uintmax_t>(n);
  if (expected != size)
    fail(path, fmt::format("a binary STL whose header counts {} triangles (84 + 50 x {} = {} bytes) but the "
                           "file has {} bytes ({})",
                           n, n, expected, size, size < expected ? "truncated" : "extra bytes or a wrong count"));
}

/// The header of a PLY file, before CGAL reads it: CGAL 5.5's PLY reader adds a `property` to
/// the last `element` declared, and one declared before any element is a write through an empty
/// vector (a crash). Refuses a header without `end_header`, a line of another keyword, a
/// property before the first element.
void check_ply_header(const std::string& path, std::uintmax_t size) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  bool element = false;
  double declared = 0.0;  // elements of every kind: each takes at least one byte
  for (int number = 1; std::getline(in, line) && number <= 100000; ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (number == 1) {
      if (keyword != "ply") fail(path, "a PLY file that does not start with 'ply'");
      continue;
    }
    if (keyword == "end_header") {
      if (declared > static_cast<double>(size))
        fail(path, fmt::format("a PLY header declaring {:.6g} elements in a file of {} bytes (a wrong count)", declared,
                               size));
      return;
    }
    if (keyword == "element") {
      element = true;
      std::string name;
      double count = -1.0;
      words >> name >> count;
      if (!(count >= 0.0)) fail(path, fmt::format("PLY header line {}: an element without a count", number));
      declared += count;
    }
    else if (keyword == "property" && !element)
      fail(path, fmt::format("PLY header line {}: a property before any element", number));
    else if (keyword != "property" && keyword != "format" && keyword != "comment" && keyword != "obj_info")
      fail(path, fmt::format("PLY header line {}: '{}' is no PLY header keyword", number, keyword));
  }
  fail(path, "a PLY header without 'end_header'");
}

/// The counts of an OFF file, before CGAL reads it: CGAL 5.5 sizes its arrays by the header's
/// counts, so "8 1200000001 0" in a 400-byte file asks for 28 GB. A vertex takes at least 6
/// bytes ("0 0 0 "), a face at least 8 ("3 0 1 2 ") in the text form, more in the binary one.
void check_off_counts(const std::string& path, std::uintmax_t size) {
  std::ifstream in(path, std::ios::binary);
  std::string word;
  std::vector<double> counts;
  bool header = false;
  while (counts.size() < 2 && in >> word) {
    if (word[0] == '#') {
      std::getline(in, word);
      continue;
    }
    if (!header) {  // OFF, COFF, NOFF, STOFF, 4OFF, nOFF ... then perhaps BINARY
      header = true;
      if (word.find("OFF") != std::string::npos) {
        if (in.peek() == ' ' && in >> word) {
          if (word == "BINARY") return;  // (binary counts: CGAL's reader, unchecked here)
          counts.push_back(std::atof(word.c_str()));
        }
        continue;
      }
    }
    counts.push_back(std::atof(word.c_str()));
  }
  if (counts.size() < 2) return;  // (CGAL reports what is missing)
  const double bytes = 6.0 * counts[0] + 8.0 * counts[1];
  if (!(counts[0] >= 0.0 && counts[1] >= 0.0) || bytes > static_cast<double>(size))
    fail(path, fmt::format("an OFF header counting {:.6g} vertices and {:.6g} faces, more than its {} bytes can hold (a "
                           "wrong count)",
                           counts[0], counts[1], size));
  // The faces' own vertex counts, which CGAL also sizes a polygon by: the vertex lines, then one
  // line per face starting with its count (a face of k vertices takes at least 2 k bytes).
  std::string line;
  std::getline(in, line);  // the rest of the counts line
  long long vertices = static_cast<long long>(counts[0]), faces = static_cast<long long>(counts[1]);
  for (long long number = 0; std::getline(in, line) && faces > 0;) {
    std::istringstream words(line);
    std::string first;
    if (!(words >> first) || first[0] == '#') continue;
    if (vertices > 0) {
      --vertices;
      continue;
    }
    --faces;
    ++number;
    const double k = std::atof(first.c_str());
    if (!(k >= 0.0) || 2.0 * k > static_cast<double>(size))
      fail(path, fmt::format("face {} of the OFF file lists {:.6g} vertices, more than its {} bytes can hold", number, k,
                             size));
  }
}

/// Faults of the polygon soup (file order, file coordinates): repeated vertices and zero areas,
/// open and over-shared edges. Returns the number of edges whose two faces run the same way
/// (inconsistent orientation, repaired by the caller).
std::size_t check_soup(const std::string& path, const std::vector<Point>& points,
                       const std::vector<Polygon>& polygons) {
  for (const Point& p : points)
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      fail(path, fmt::format("a vertex with a non-finite coordinate {}", point_text(p)));
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const Polygon& q = polygons[f];
    if (q.size() < 3) fail(path, fmt::format("face #{} (counting from 0) has {} vertices, fewer than 3", f, q.size()));
    for (std::size_t i = 0; i < q.size(); ++i)
      for (std::size_t j = i + 1; j < q.size(); ++j)
        if (q[i] == q[j])
          fail(path, fmt::format("degenerate face #{} (counting from 0): vertex {} appears twice", f,
                                 point_text(points[q[i]])));
    if (q.size() == 3 && CGAL::collinear(points[q[0]], points[q[1]], points[q[2]]))
      fail(path, fmt::format("degenerate face #{} (counting from 0): zero area, its vertices {}, {}, {} lie on "
                             "one line",
                             f, point_text(points[q[0]]), point_text(points[q[1]]), point_text(points[q[2]])));
  }
  struct Use {
    int count = 0;
    int direction = 0;  // sum of +1 (traversed from the lower index) and -1
  };
  std::unordered_map<std::uint64_t, Use> edges;
  edges.reserve(2 * polygons.size());
  for (const Polygon& q : polygons)
    for (std::size_t i = 0; i < q.size(); ++i) {
      const std::uint64_t u = q[i], v = q[(i + 1) % q.size()];
      Use& e = edges[std::min(u, v) << 32 | std::max(u, v)];
      ++e.count;
      e.direction += u < v ? 1 : -1;
    }
  std::size_t open = 0, shared = 0, inconsistent = 0;
  std::vector<std::string> open_where, shared_where;
  auto where = [&](std::uint64_t key) {
    return fmt::format("{}-{}", point_text(points[key >> 32]), point_text(points[key & 0xffffffffu]));
  };
  for (const auto& [key, e] : edges) {
    if (e.count == 1 && ++open <= 3) open_where.push_back(where(key));
    if (e.count > 2 && ++shared <= 3) shared_where.push_back(where(key) + fmt::format(" ({} faces)", e.count));
    if (e.count == 2 && e.direction != 0) ++inconsistent;
  }
  if (open > 0)
    fail(path, fmt::format("not closed (not watertight): {} open edge{} (used by one face only), e.g. {} "
                           "(file coordinates); close the holes in the modeller or export a solid",
                           open, open == 1 ? "" : "s", fmt::join(open_where, ", ")));
  if (shared > 0)
    fail(path, fmt::format("not a manifold surface: {} edge{} shared by more than two faces, e.g. {} "
                           "(file coordinates)",
                           shared, shared == 1 ? "" : "s", fmt::join(shared_where, ", ")));
  return inconsistent;
}

/// R = Rz Ry Rx for Euler angles in degrees about the fixed x, y, z axes.
std::array<std::array<double, 3>, 3> rotation(const std::array<double, 3>& degrees) {
  const double k = std::numbers::pi / 180.0;
  const double cx = std::cos(k * degrees[0]), sx = std::sin(k * degrees[0]);
  const double cy = std::cos(k * degrees[1]), sy = std::sin(k * degrees[1]);
  const double cz = std::cos(k * degrees[2]), sz = std::sin(k * degrees[2]);
  return {{{cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
           {sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx},
           {-sy, cy * sx, cy * cx}}};
}

}  // namespace

struct SurfaceMesh::Impl {
  Mesh mesh;
  Tree tree;
  std::unique_ptr<Side> side;
};

SurfaceMesh::SurfaceMesh() : impl_(std::make_unique<Impl>()) {}
SurfaceMesh::~SurfaceMesh() = default;

std::array<double, 3> place(const MeshPlacement& placement, const std::array<double, 3>& x_file) {
  const auto R = rotation(placement.rotate_degrees);
  std::array<double, 3> x{};
  for (std::size_t a = 0; a < 3; ++a)
    x[a] = placement.scale * (R[a][0] * x_file[0] + R[a][1] * x_file[1] + R[a][2] * x_file[2]) + placement.translate[a];
  return x;
}

double unit_in_metres(const std::string& unit) {
  static const std::vector<std::pair<std::string, double>> units{
      {"m", 1.0}, {"dm", 0.1}, {"cm", 0.01}, {"mm", 1e-3}, {"um", 1e-6}, {"in", 0.0254}, {"ft", 0.3048}};
  for (const auto& [name, metres] : units)
    if (name == unit) return metres;
  throw std::invalid_argument(fmt::format("unknown length unit '{}'", unit));
}

const std::vector<std::string>& unit_names() {
  static const std::vector<std::string> names{"m", "dm", "cm", "mm", "um", "in", "ft"};
  return names;
}

std::shared_ptr<const SurfaceMesh> read_surface_mesh(const std::string& path, const MeshPlacement& placement) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) fail(path, "no such file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  if (size == 0) fail(path, "the file is empty");
  const std::string ext = lower_extension(path);
  if (ext != ".stl" && ext != ".obj" && ext != ".ply" && ext != ".off")
    fail(path, fmt::format("extension '{}' is none of .stl, .obj, .ply, .off", ext));
  if (ext == ".stl") check_stl_size(path, size);
  if (ext == ".ply") check_ply_header(path, size);
  if (ext == ".off") check_off_counts(path, size);

  // CGAL's readers run in a child process, which sends back the points and faces: CGAL 5.5's
  // PLY reader dereferences a null property on some damaged headers (found by
  // cairn_fuzz_geometry), and the child may take 1 GiB and 200 bytes per byte of the file, so
  // that a count sizing its arrays fails there; a crash or a failure there is an input error.
  std::vector<Point> points;
  std::vector<Polygon> polygons;
  bool read = false;
  const ChildResult soup = run_in_child(
      [&](std::string& out) {
        limit_address_space((1u << 30) + 200.0 * static_cast<double>(size));
        std::string error;
        bool ok = false;
        try {
          ok = CGAL::IO::read_polygon_soup(path, points, polygons, CGAL::parameters::verbose(false));
        } catch (const std::exception& e) {
          error = e.what();
        }
        auto put = [&](const void* p, std::size_t n) { put_bytes(out, p, n); };
        const std::uint64_t flags[3] = {ok ? 1u : 0u, points.size(), polygons.size()};
        put(flags, sizeof flags);
        for (const Point& p : points) {
          const double x[3] = {p.x(), p.y(), p.z()};
          put(x, sizeof x);
        }
        for (const Polygon& q : polygons) {
          const std::uint64_t n = q.size();
          put(&n, sizeof n);
          put(q.data(), q.size() * sizeof(std::size_t));
        }
        out += error;
        return 0;
      },
      300);
  if (soup.signal != 0 || soup.timed_out || soup.exit_code != 0 || soup.output.size() < 24)
    fail(path, fmt::format("CGAL's {} reader failed on it ({}): a damaged file", ext.substr(1), child_ending(soup, 300)));
  {
    AnswerReader answer(soup.output);
    auto take = [&](void* p, std::size_t n) {
      if (!answer.take(p, n)) fail(path, "CGAL's reader process sent a short answer");
    };
    std::uint64_t flags[3];
    take(flags, sizeof flags);
    read = flags[0] == 1;
    points.reserve(flags[1]);
    for (std::uint64_t i = 0; i < flags[1]; ++i) {
      double x[3];
      take(x, sizeof x);
      points.emplace_back(x[0], x[1], x[2]);
    }
    polygons.reserve(flags[2]);
    for (std::uint64_t i = 0; i < flags[2]; ++i) {
      std::uint64_t n = 0;
      take(&n, sizeof n);
      if (n > soup.output.size()) fail(path, "CGAL's reader process sent a bad answer");
      Polygon q(n);
      take(q.data(), n * sizeof(std::size_t));
      polygons.push_back(std::move(q));
    }
    const std::string error = answer.rest();
    if (!error.empty()) fail(path, fmt::format("CGAL's {} reader failed: {}", ext.substr(1), error));
  }
  if (!read)
    fail(path, fmt::format("CGAL's {} reader could not read it (malformed or truncated: {} vertices and {} faces "
                           "read before the fault)",
                           ext.substr(1), points.size(), polygons.size()));
  if (polygons.empty()) fail(path, fmt::format("no faces ({} vertices)", points.size()));
  for (const Polygon& q : polygons)
    for (std::size_t v : q)
      if (v >= points.size())
        fail(path, fmt::format("a face refers to vertex {} of {}", v, points.size()));

  auto result = std::shared_ptr<SurfaceMesh>(new SurfaceMesh());
  SurfaceMesh& out = *result;
  out.file_ = path;
  // Points equal in every coordinate are one vertex (STL stores each triangle's own copies).
  const std::size_t merged = PMP::merge_duplicate_points_in_polygon_soup(points, polygons);
  (void)merged;
  const std::size_t inconsistent = check_soup(path, points, polygons);
  std::size_t turned = 0;
  if (inconsistent > 0) {
    const std::vector<Polygon> before = polygons;
    if (!PMP::orient_polygon_soup(points, polygons))
      fail(path, fmt::format("{} edges join faces of opposite orientation and the faces cannot be oriented "
                             "consistently (a non-orientable or non-manifold surface)",
                             inconsistent));
    for (std::size_t f = 0; f < polygons.size(); ++f) turned += polygons[f] != before[f];
  }

  for (Point& p : points) {
    const auto x = place(placement, {p.x(), p.y(), p.z()});
    p = Point(x[0], x[1], x[2]);
  }

  Mesh& mesh = out.impl_->mesh;
  if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) PMP::orient_polygon_soup(points, polygons);
  PMP::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  if (!CGAL::is_triangle_mesh(mesh)) {
    if (!PMP::triangulate_faces(mesh)) fail(path, "a face with more than three vertices could not be triangulated");
    for (auto f : faces(mesh))
      if (PMP::is_degenerate_triangle_face(f, mesh))
        fail(path, fmt::format("a face triangulates into a degenerate (zero-area) triangle, #{} of the triangulated "
                               "surface",
                               static_cast<std::size_t>(f.idx())));
  }
  if (!CGAL::is_closed(mesh)) fail(path, "not closed after triangulation");

  // Self-intersections: the count and the first pair.
  std::size_t n_pairs = 0;
  std::pair<std::size_t, std::size_t> first{0, 0};
  if (PMP::does_self_intersect(mesh)) {
    PMP::self_intersections(mesh, boost::make_function_output_iterator([&](const auto& pair) {
                              if (n_pairs++ == 0) first = {pair.first.idx(), pair.second.idx()};
                            }));
    fail(path, fmt::format("the surface intersects itself: {} pair{} of faces cross, the first faces #{} and #{} "
                           "(counting from 0){}",
                           n_pairs, n_pairs == 1 ? "" : "s", first.first, first.second,
                           CGAL::is_triangle_mesh(mesh) && polygons.size() == mesh.number_of_faces()
                               ? ""
                               : " of the triangulated surface"));
  }

  // Orientation: each shell bounds the volume on its inner side, a cavity's shell faces inward.
  std::vector<std::array<std::uint32_t, 3>> before;
  before.reserve(mesh.number_of_faces());
  auto corners = [&](Mesh::Face_index f) {
    std::array<std::uint32_t, 3> c{};
    int i = 0;
    for (auto v : vertices_around_face(mesh.halfedge(f), mesh)) c[i++] = static_cast<std::uint32_t>(v.idx());
    std::rotate(c.begin(), std::min_element(c.begin(), c.end()), c.end());
    return c;
  };
  for (auto f : faces(mesh)) before.push_back(corners(f));
  // CGAL 5.5's orient_to_bound_a_volume reads freed memory on some nearly degenerate surfaces
  // (an OBJ cube with two corners 1e-16 apart, found by cairn_fuzz_geometry): it runs on a child
  // process's copy of the mesh, which sends back which faces it turned, and a crash there is an
  // input error; the turns are made here.
  const ChildResult oriented = run_in_child(
      [&](std::string& answer) {
        PMP::orient_to_bound_a_volume(mesh);
        for (auto f : faces(mesh)) answer.push_back(corners(f) != before[f.idx()] ? '1' : '0');
        return 0;
      },
      300);
  if (oriented.signal != 0 || oriented.timed_out || oriented.exit_code != 0 ||
      oriented.output.size() != mesh.number_of_faces())
    fail(path, "CGAL failed to orient the surface to bound a volume (a nearly degenerate surface: corners or faces "
               "almost on each other?" + child_said(oriented) + ")");
  std::vector<Mesh::Face_index> to_turn;
  for (auto f : faces(mesh))
    if (oriented.output[f.idx()] == '1') to_turn.push_back(f);
  PMP::reverse_face_orientations(to_turn, mesh);
  const std::size_t flipped = to_turn.size();
  if (turned > 0)
    out.warnings_.push_back(fmt::format("surface mesh '{}': {} edges joined faces of opposite orientation; {} faces "
                                        "turned to agree with their neighbours",
                                        path, inconsistent, turned));
  if (flipped > 0)
    out.warnings_.push_back(fmt::format("surface mesh '{}': {} of {} faces turned so that every shell faces out of "
                                        "the body{}",
                                        path, flipped, mesh.number_of_faces(),
                                        flipped == mesh.number_of_faces() ? " (the file's normals pointed inward)" : ""));

  out.volume_ = PMP::volume(mesh);
  if (!(out.volume_ > 0.0)) fail(path, fmt::format("the surface encloses no volume ({:.6g})", out.volume_));
  auto shell = mesh.add_property_map<Mesh::Face_index, std::size_t>("f:shell", 0).first;
  out.n_shells_ = PMP::connected_components(mesh, shell);
  mesh.remove_property_map(shell);
  out.n_triangles_ = mesh.number_of_faces();
  out.n_vertices_ = mesh.number_of_vertices();
  const CGAL::Bbox_3 box = PMP::bbox(mesh);
  out.lo_ = {box.xmin(), box.ymin(), box.zmin()};
  out.hi_ = {box.xmax(), box.ymax(), box.zmax()};

  const std::size_t heap = mallinfo2().uordblks;
  Tree& tree = out.impl_->tree;
  tree.insert(faces(mesh).first, faces(mesh).second, mesh);
  tree.build();
  const std::size_t grown = mallinfo2().uordblks;
  out.tree_bytes_ = grown > heap ? grown - heap : 0;
  out.impl_->side = std::make_unique<Side>(tree);
  return result;
}

SurfaceMesh::Cut SurfaceMesh::slice(double z) const {
  CGAL::Polygon_mesh_slicer<Mesh, Kernel> slicer(impl_->mesh);  // (its own AABB tree, of the edges)
  std::vector<std::vector<Point>> polylines;
  slicer(Kernel::Plane_3(0.0, 0.0, 1.0, -z), std::back_inserter(polylines));
  Cut cut;
  for (const auto& line : polylines) {
    if (line.size() < 2 || line.front() != line.back()) {
      ++cut.open;
      continue;
    }
    std::vector<std::array<double, 2>> loop;
    for (std::size_t i = 0; i + 1 < line.size(); ++i) loop.push_back({line[i].x(), line[i].y()});
    cut.loops.push_back(std::move(loop));
  }
  return cut;
}

std::string volume_note(const std::string& body, const SurfaceMesh& mesh, long long n_particles,
                        double particle_volume) {
  const double v = static_cast<double>(n_particles) * particle_volume;
  return fmt::format("body '{}': {} particles of volume {:.6g}, mesh volume {:.6g} ({:+.3f} %; {}: {} triangles, "
                     "{} shell{}, AABB tree {:.3g} MiB)",
                     body, n_particles, v, mesh.volume(), 100.0 * (v / mesh.volume() - 1.0),
                     std::filesystem::path(mesh.file()).filename().string(), mesh.n_triangles(), mesh.n_shells(),
                     mesh.n_shells() == 1 ? "" : "s", static_cast<double>(mesh.tree_bytes()) / (1024.0 * 1024.0));
}

bool SurfaceMesh::inside(double x, double y, double z, LineCache& cache) const {
  if (!(y >= lo_[1] && y <= hi_[1] && z >= lo_[2] && z <= hi_[2] && x >= lo_[0] && x <= hi_[0])) return false;
  if (!cache.valid || cache.y != y || cache.z != z) {
    cache.valid = true;
    cache.y = y;
    cache.z = z;
    cache.exact = true;
    cache.crossings.clear();
    const Mesh& mesh = impl_->mesh;
    std::vector<Mesh::Face_index> hit;
    const Kernel::Segment_3 line(Point(lo_[0] - 1.0, y, z), Point(hi_[0] + 1.0, y, z));
    impl_->tree.all_intersected_primitives(line, std::back_inserter(hit));
    const Kernel::Point_2 p(y, z);
    for (auto f : hit) {
      Point c[3];
      int i = 0;
      for (auto v : vertices_around_face(mesh.halfedge(f), mesh)) c[i++] = mesh.point(v);
      const Kernel::Point_2 a(c[0].y(), c[0].z()), b(c[1].y(), c[1].z()), d(c[2].y(), c[2].z());
      // Exact signs of the sub-triangle areas (y-z projection): all alike = a proper crossing;
      // a zero = the line meets an edge, a vertex or lies in the face's plane.
      const auto s0 = CGAL::orientation(b, d, p), s1 = CGAL::orientation(d, a, p), s2 = CGAL::orientation(a, b, p);
      if (s0 == CGAL::COLLINEAR || s1 == CGAL::COLLINEAR || s2 == CGAL::COLLINEAR) {
        cache.exact = false;
        break;
      }
      if (s0 != s1 || s1 != s2) continue;
      // Barycentric weights: the sub-triangle areas opposite each corner.
      auto area = [](const Kernel::Point_2& u, const Kernel::Point_2& v, const Kernel::Point_2& w) {
        return (v.x() - u.x()) * (w.y() - u.y()) - (v.y() - u.y()) * (w.x() - u.x());
      };
      const double wa = area(b, d, p), wb = area(d, a, p), wc = area(a, b, p);
      cache.crossings.push_back((wa * c[0].x() + wb * c[1].x() + wc * c[2].x()) / (wa + wb + wc));
    }
    std::sort(cache.crossings.begin(), cache.crossings.end());
  }
  if (!cache.exact) return (*impl_->side)(Point(x, y, z)) != CGAL::ON_UNBOUNDED_SIDE;
  const auto below = std::lower_bound(cache.crossings.begin(), cache.crossings.end(), x) - cache.crossings.begin();
  return below % 2 == 1;
}

}  // namespace cairn::geometry
