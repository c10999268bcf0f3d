// The Gmsh mesher module (libcairn_gmsh.so, loaded at first use by fem/gmsh_mesh.cpp): reading
// .msh files and meshing the generated shapes through the Gmsh API. Gmsh keeps one global model,
// so every use is serialised by a mutex and wrapped in initialize/finalize. Only what needs Gmsh
// is here; the checks and the orientation of the triangles stay in the program.
#include <gmsh.h>

#include <fmt/format.h>

#include <cmath>
#include <mutex>
#include <new>
#include <numbers>
#include <stdexcept>
#include <unordered_map>

#include "cairn/fem/gmsh_module.hpp"
#include "cairn/fem/mesh.hpp"
#include "cairn/config/errors.hpp"

namespace cairn::fem {
namespace {

std::mutex& gmsh_mutex() {
  static std::mutex m;
  return m;
}

/// One Gmsh session: initialised quietly, finalised on scope exit.
class GmshSession {
 public:
  GmshSession() : lock_(gmsh_mutex()) {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 0);
  }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
};

/// Text of whatever Gmsh threw (Gmsh 4.8 throws std::string; later versions std::exception).
std::string current_error() {
  try {
    throw;
  } catch (const std::bad_alloc&) {
    // Also std::bad_array_new_length (a negative or overflowing count) and, below, a vector's
    // std::length_error: what a damaged count in a file asks for. One text for all of them,
    // which the reading's parent process recognises (gmsh_mesh.cpp, in_child).
    return "std::bad_alloc";
  } catch (const std::length_error&) {
    return "std::bad_alloc";
  } catch (const std::exception& e) {
    return e.what();
  } catch (const std::string& s) {
    return s;
  } catch (const char* s) {
    return s;
  } catch (...) {
    return "unknown Gmsh error";
  }
}

/// The 3-node triangles of the current Gmsh model. `key` and `source` for messages.
TriangleMesh extract(const std::string& source, const std::string& key) {
  const auto bad = [&](const std::string& expected, const std::string& found) {
    throw InputError(source, 0, key, expected, found);
  };
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, param;
  gmsh::model::mesh::getNodes(node_tags, coords, param, -1, -1, false, false);
  std::unordered_map<std::size_t, std::size_t> index_of_tag;
  for (std::size_t i = 0; i < node_tags.size(); ++i) {
    index_of_tag[node_tags[i]] = i;
    if (std::abs(coords[3 * i + 2]) > 0.0)
      bad("a planar mesh in z = 0", fmt::format("node {} at z = {}", node_tags[i], coords[3 * i + 2]));
  }
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> element_tags, element_nodes;
  gmsh::model::mesh::getElements(types, element_tags, element_nodes, -1, -1);
  TriangleMesh m;
  m.source = source;
  std::unordered_map<std::size_t, std::int32_t> compact;  // Gmsh node tag -> mesh node
  for (std::size_t k = 0; k < types.size(); ++k) {
    std::string name;
    int dim = 0, order = 0, n_nodes = 0, n_primary = 0;
    std::vector<double> local;
    gmsh::model::mesh::getElementProperties(types[k], name, dim, order, n_nodes, local, n_primary);
    if (dim < 2) continue;  // points and lines: boundary entities
    if (types[k] != 2)
      bad("3-node triangles only (Gmsh element type 2)",
          fmt::format("element {} of type {} ({}), one of {} such elements", element_tags[k].front(), types[k], name,
                      element_tags[k].size()));
    for (std::size_t e = 0; e < element_tags[k].size(); ++e) {
      std::array<std::int32_t, 3> t{};
      for (int c = 0; c < 3; ++c) {
        const std::size_t tag = element_nodes[k][3 * e + static_cast<std::size_t>(c)];
        const auto it = index_of_tag.find(tag);
        if (it == index_of_tag.end())
          bad("elements whose nodes exist", fmt::format("element {} refers to missing node {}", element_tags[k][e], tag));
        auto [slot, added] = compact.try_emplace(tag, static_cast<std::int32_t>(m.nodes.size()));
        if (added) m.nodes.emplace_back(coords[3 * it->second], coords[3 * it->second + 1]);
        t[static_cast<std::size_t>(c)] = slot->second;
      }
      m.triangles.push_back(t);
      m.element_tags.push_back(element_tags[k][e]);
    }
  }
  return m;
}

TriangleMesh read_file(const std::string& path) {
  const std::string key = "fem.mesh_file";
  GmshSession session;
  try {
    gmsh::open(path);
  } catch (...) {
    throw InputError(path, 0, key, "a Gmsh .msh file Gmsh can read", current_error());
  }
  return extract(path, key);
}

TriangleMesh generate(const FemConfig& fem) {
  const BodyShapeConfig& s = fem.shape;
  const std::string source = fmt::format("generated {} mesh", s.kind);
  GmshSession session;
  try {
    gmsh::model::add("cairn");
    namespace occ = gmsh::model::occ;
    int surface = -1;
    const auto disk = [](double cx, double cy, double rx, double ry) {
      if (rx >= ry) return occ::addDisk(cx, cy, 0.0, rx, ry);
      // OpenCASCADE wants the major radius along x: make it so, then turn by 90 degrees.
      const int tag = occ::addDisk(cx, cy, 0.0, ry, rx);
      occ::rotate({{2, tag}}, cx, cy, 0.0, 0.0, 0.0, 1.0, 0.5 * std::numbers::pi);
      return tag;
    };
    const auto cut = [](int object, int tool) {
      gmsh::vectorpair out;
      std::vector<gmsh::vectorpair> map;
      occ::cut({{2, object}}, {{2, tool}}, out, map);
      if (out.size() != 1) throw std::runtime_error(fmt::format("the cut left {} surfaces", out.size()));
      return out.front().second;
    };
    if (s.kind == "box") {
      surface = occ::addRectangle(s.min[0], s.min[1], 0.0, s.max[0] - s.min[0], s.max[1] - s.min[1]);
    } else if (s.kind == "circle") {
      surface = disk(s.center[0], s.center[1], s.radius, s.radius);
    } else if (s.kind == "ellipse") {
      surface = disk(s.center[0], s.center[1], s.semi_axes[0], s.semi_axes[1]);
    } else if (s.kind == "annulus") {
      surface = cut(disk(s.center[0], s.center[1], s.outer_radius, s.outer_radius),
                    disk(s.center[0], s.center[1], s.inner_radius, s.inner_radius));
    } else if (s.kind == "polygon") {
      std::vector<int> points, lines;
      for (const auto& v : s.vertices) points.push_back(occ::addPoint(v[0], v[1], 0.0));
      for (std::size_t i = 0; i < points.size(); ++i)
        lines.push_back(occ::addLine(points[i], points[(i + 1) % points.size()]));
      surface = occ::addPlaneSurface({occ::addCurveLoop(lines)});
    } else {
      throw std::runtime_error("no Gmsh generator for shape kind " + s.kind);
    }
    if (fem.hole_radius > 0.0)
      surface = cut(surface, disk(fem.hole_center[0], fem.hole_center[1], fem.hole_radius, fem.hole_radius));
    occ::synchronize();
    gmsh::option::setNumber("Mesh.MeshSizeMax", fem.size);
    gmsh::option::setNumber("Mesh.MeshSizeMin", 0.0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 1);
    gmsh::option::setNumber("Mesh.Algorithm", 6);  // Frontal-Delaunay
    gmsh::model::mesh::generate(2);
  } catch (const InputError&) {
    throw;
  } catch (...) {
    throw InputError(source, 0, "fem.shape", "a shape Gmsh can mesh", current_error());
  }
  return extract(source, "fem.shape");
}

ElementMesh read_elements(const std::string& path) {
  GmshSession session;
  ElementMesh m;
  try {
    gmsh::open(path);
    // A .geo geometry without a mesh: mesh it (3D when it has volumes, else 2D).
    std::vector<std::size_t> tags;
    std::vector<double> coords, param;
    gmsh::model::mesh::getNodes(tags, coords, param, -1, -1, false, false);
    if (tags.empty()) gmsh::model::mesh::generate(gmsh::model::getDimension());
  } catch (...) {
    throw std::invalid_argument("Gmsh could not read or mesh it: " + current_error());
  }
  std::vector<std::size_t> node_tags;
  std::vector<double> coords, param;
  gmsh::model::mesh::getNodes(node_tags, coords, param, -1, -1, false, false);
  std::unordered_map<std::size_t, std::int32_t> index_of_tag;
  for (std::size_t i = 0; i < node_tags.size(); ++i) {
    index_of_tag[node_tags[i]] = static_cast<std::int32_t>(i);
    m.nodes.push_back({coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]});
  }
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> element_tags, element_nodes;
  gmsh::model::mesh::getElements(types, element_tags, element_nodes, -1, -1);
  for (std::size_t k = 0; k < types.size(); ++k) {
    std::string name;
    int dim = 0, order = 0, n_nodes = 0, n_primary = 0;
    std::vector<double> local;
    gmsh::model::mesh::getElementProperties(types[k], name, dim, order, n_nodes, local, n_primary);
    if (dim < 2) continue;
    if (types[k] != 2 && types[k] != 4) {
      if (m.other.empty())
        m.other = fmt::format("{} elements of type {} ({}), e.g. element {}", element_tags[k].size(), types[k], name,
                              element_tags[k].front());
      continue;
    }
    const auto n = static_cast<std::size_t>(n_nodes);
    for (std::size_t e = 0; e < element_tags[k].size(); ++e) {
      std::array<std::int32_t, 4> c{};
      for (std::size_t i = 0; i < n; ++i) {
        const auto it = index_of_tag.find(element_nodes[k][n * e + i]);
        if (it == index_of_tag.end())
          throw std::invalid_argument(fmt::format("element {} refers to missing node {}", element_tags[k][e],
                                                  element_nodes[k][n * e + i]));
        c[i] = it->second;
      }
      if (types[k] == 2) {
        m.triangles.push_back({c[0], c[1], c[2]});
        m.triangle_tags.push_back(element_tags[k][e]);
      } else {
        m.tetrahedra.push_back(c);
        m.tetrahedron_tags.push_back(element_tags[k][e]);
      }
    }
  }
  return m;
}

const GmshModule module{gmsh_module_version, read_file, generate, read_elements};

}  // namespace

}  // namespace cairn::fem

extern "C" [[gnu::visibility("default")]] const cairn::fem::GmshModule* cairn_gmsh_module() {
  return &cairn::fem::module;
}
