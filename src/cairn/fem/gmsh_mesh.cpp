// Gmsh meshes through the mesher module (fem/gmsh_module.hpp), loaded at first use.
#include <dlfcn.h>
#include <fmt/format.h>

#include <cstring>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "cairn/fem/gmsh_module.hpp"
#include "cairn/fem/mesh.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/util/child_process.hpp"

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

/// Bytes written by the reading child and read back by the parent.
class Bytes {
 public:
  template <class T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const char*>(&v);
    data_.append(p, sizeof v);
  }
  template <class T>
  void put_vector(const std::vector<T>& v) {
    put(v.size());
    data_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void put_string(const std::string& s) {
    put(s.size());
    data_ += s;
  }
  template <class T>
  T get() {
    T v{};
    take(&v, sizeof v);
    return v;
  }
  template <class T>
  std::vector<T> get_vector() {
    std::vector<T> v(get<std::size_t>());
    take(v.data(), v.size() * sizeof(T));
    return v;
  }
  std::string get_string() {
    std::string s(get<std::size_t>(), '\0');
    take(s.data(), s.size());
    return s;
  }
  std::string& data() { return data_; }

 private:
  void take(void* out, std::size_t n) {
    if (at_ + n > data_.size()) throw std::runtime_error("the Gmsh reading process sent a short answer");
    if (n > 0) std::memcpy(out, data_.data() + at_, n);  // (an empty vector's data() may be null)
    at_ += n;
  }
  std::string data_;
  std::size_t at_ = 0;
};

/// Runs `read` (a reading of a file by Gmsh) in a child process and returns what it sent back.
/// Gmsh 4.8 reads a .msh file whose element names a node that $Nodes does not define (in the 2.2
/// and 4.1 formats) without an error and then dereferences a null node in
/// gmsh::model::mesh::getElements: a segmentation fault. In a child such a crash, or a reading
/// that does not end, is an input error (`fail`) instead of the end of the run, and the parent's
/// Gmsh state is never touched by a reading. Errors the reading throws come back with their kind
/// (InputError, std::invalid_argument, other).
Bytes in_child(const std::string& path, const std::function<void(Bytes&)>& read,
               const std::function<void(const std::string&)>& fail) {
  (void)gmsh();  // loaded here, once, not in every child
  constexpr int timeout_seconds = 300;
  // The child may take 1 GiB and 200 bytes per byte of the file beyond what it starts with: a
  // count in a damaged file (a node count of 2^31 in a file of 400 bytes) makes Gmsh's
  // allocation fail there instead of taking the machine's memory.
  std::error_code ec;
  const double file_bytes = static_cast<double>(std::filesystem::file_size(path, ec));
  const double budget = (1u << 30) + 200.0 * (ec ? 0.0 : file_bytes);
  const ChildResult r = run_in_child(
      [&](std::string& out) {
        limit_address_space(budget);
        Bytes answer;
        try {
          answer.put<char>('0');
          read(answer);
        } catch (const InputError& e) {
          answer.data().clear();
          answer.put<char>('I');
          answer.put_string(e.file());
          answer.put<int>(e.line());
          answer.put_string(e.key());
          answer.put_string(e.expected());
          answer.put_string(e.found());
        } catch (const std::invalid_argument& e) {
          answer.data().clear();
          answer.put<char>('A');
          answer.put_string(e.what());
        } catch (const std::exception& e) {
          answer.data().clear();
          answer.put<char>('R');
          answer.put_string(e.what());
        }
        out = std::move(answer.data());
        return 0;
      },
      timeout_seconds);
  if (r.timed_out) fail(fmt::format("Gmsh did not finish reading it in {} s", timeout_seconds));
  if (r.signal != 0)
    fail(fmt::format("Gmsh crashed reading it (signal {}{}): a malformed mesh, e.g. an element whose node is not "
                     "defined in $Nodes",
                     r.signal, child_said(r)));
  if (r.exit_code != 0 || r.output.empty()) fail("the process reading it with Gmsh ended without an answer");
  Bytes in;
  in.data() = r.output;
  const char kind = in.get<char>();
  const std::string memory = fmt::format("Gmsh could not allocate what a count in the file asks for (negative, or more "
                                         "than the {:.3g} GiB a mesh file of {:.0f} bytes may take): a count that does "
                                         "not match the file's content",
                                         budget / (1u << 30), file_bytes);
  if (kind == 'I') {
    std::string file = in.get_string();
    const int line = in.get<int>();
    std::string key = in.get_string(), expected = in.get_string(), found = in.get_string();
    if (found.find("bad_alloc") != std::string::npos) found = memory;
    throw InputError(std::move(file), line, std::move(key), std::move(expected), std::move(found));
  }
  if (kind == 'A' || kind == 'R') {
    const std::string what = in.get_string();
    if (what.find("bad_alloc") != std::string::npos) fail(memory);
    if (kind == 'A') throw std::invalid_argument(what);
    throw std::runtime_error(what);
  }
  return in;
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
  Bytes answer = in_child(
      path,
      [&](Bytes& out) {
        const TriangleMesh read = gmsh().read_file(path);
        out.put_vector(read.nodes);
        out.put_vector(read.triangles);
        out.put_vector(read.element_tags);
        out.put_string(read.source);
      },
      [&](const std::string& what) { throw InputError(path, 0, "fem.mesh_file", "a Gmsh .msh file Gmsh can read", what); });
  TriangleMesh m;
  m.nodes = answer.get_vector<Vec<2>>();
  m.triangles = answer.get_vector<std::array<std::int32_t, 3>>();
  m.element_tags = answer.get_vector<std::size_t>();
  m.source = answer.get_string();
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
  Bytes answer = in_child(
      path,
      [&](Bytes& out) {
        const ElementMesh read = gmsh().read_elements(path);
        out.put_vector(read.nodes);
        out.put_vector(read.triangles);
        out.put_vector(read.triangle_tags);
        out.put_vector(read.tetrahedra);
        out.put_vector(read.tetrahedron_tags);
        out.put_string(read.other);
      },
      [](const std::string& what) { throw std::invalid_argument(what); });
  ElementMesh m;
  m.nodes = answer.get_vector<std::array<double, 3>>();
  m.triangles = answer.get_vector<std::array<std::int32_t, 3>>();
  m.triangle_tags = answer.get_vector<std::size_t>();
  m.tetrahedra = answer.get_vector<std::array<std::int32_t, 4>>();
  m.tetrahedron_tags = answer.get_vector<std::size_t>();
  m.other = answer.get_string();
  return m;
}

TriangleMesh generate_gmsh(const FemConfig& fem) {
  TriangleMesh m = gmsh().generate(fem);
  // Gmsh orients the triangles by the surface normal; OpenCASCADE planar faces face +z, but
  // turn any clockwise element round rather than rely on it.
  orient(m);
  return m;
}

}  // namespace cairn::fem
