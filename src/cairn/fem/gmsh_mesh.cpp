// Gmsh meshes through the mesher module (fem/gmsh_module.hpp), loaded at first use.
#include <dlfcn.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cairn/fem/gmsh_module.hpp"
#include "cairn/fem/mesh.hpp"
#include "cairn/config/errors.hpp"

namespace cairn::fem {
namespace {

/// Loads libcairn_gmsh.so from beside the running program (build/release/cairn), else from where
/// the build put it (programs elsewhere: the tests, copies of the binary), once per process.
const GmshModule& gmsh() {
  static const GmshModule* const loaded = [] {
    std::vector<std::string> candidates;
    std::error_code ec;
    const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) candidates.push_back((self.parent_path() / "libcairn_gmsh.so").string());
    candidates.emplace_back(CAIRN_GMSH_MODULE);
    std::string why;
    for (const std::string& path : candidates) {
      void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (handle == nullptr) {
        why += std::string("\n  ") + ::dlerror();
        continue;
      }
      const auto entry = reinterpret_cast<const GmshModule* (*)()>(::dlsym(handle, "cairn_gmsh_module"));
      const GmshModule* m = entry != nullptr ? entry() : nullptr;
      if (m == nullptr || m->version != gmsh_module_version) {
        why += "\n  " + path + ": not a Cairn Gmsh module of version " + std::to_string(gmsh_module_version);
        ::dlclose(handle);
        continue;
      }
      return m;  // kept loaded for the life of the process
    }
    throw std::runtime_error("the Gmsh mesher module could not be loaded (rebuild Cairn):" + why);
  }();
  return *loaded;
}

/// Turns every clockwise triangle round.
void orient(TriangleMesh& m) {
  for (std::size_t e = 0; e < m.triangles.size(); ++e)
    if (twice_area(m, e) < 0.0) std::swap(m.triangles[e][1], m.triangles[e][2]);
}

}  // namespace

TriangleMesh read_gmsh_file(const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw InputError(path, 0, "fem.mesh_file", "a readable Gmsh .msh file", "no such file");
  TriangleMesh m = gmsh().read_file(path);
  // A surface meshed with its normal along -z has every triangle clockwise: turn them all
  // round. A mesh with some clockwise elements among counter-clockwise ones keeps them, and
  // check_mesh rejects them as inverted.
  bool all_clockwise = !m.triangles.empty();
  for (std::size_t e = 0; e < m.triangles.size() && all_clockwise; ++e) all_clockwise = twice_area(m, e) < 0.0;
  if (all_clockwise) orient(m);
  return m;
}

ElementMesh read_gmsh_elements(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw std::invalid_argument("no such file");
  return gmsh().read_elements(path);
}

TriangleMesh generate_gmsh(const FemConfig& fem) {
  TriangleMesh m = gmsh().generate(fem);
  // Gmsh orients the triangles by the surface normal; OpenCASCADE planar faces face +z, but
  // turn any clockwise element round rather than rely on it.
  orient(m);
  return m;
}

}  // namespace cairn::fem
