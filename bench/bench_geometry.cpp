// Bodies from surface meshes (docs/geometry.md; figure in docs/performance.md, "Geometry"):
// a torus of about 1M triangles (n_u = 1000 segments around z, n_v = 500 around the tube, binary
// STL written once to the temp directory) is
//   * GeometryRead: read, checked (closedness, orientation, self-intersections) and indexed
//     (AABB tree); counters: triangles, tree MiB (heap growth while the tree was built);
//   * GeometryInside: the inside test alone over a lattice of 256^3 points in its bounds;
//     counter points/s and inside points/s;
//   * GeometryFill: a whole 3D set-up (Simulation<3>: grid, particles with their state) whose
//     one body is the torus at 2 particles per cell; counter particles/s.
// Run (one core): OMP_NUM_THREADS=1 build/release/bench/cairn_bench --benchmark_filter=Geometry
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>

#include "../tests/support/mesh_writer.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

const std::string& torus_file() {
  static const std::string path = [] {
    const auto p = std::filesystem::temp_directory_path() / "cairn_bench_torus_1m.stl";
    test::write_binary_stl(p.string(), test::torus({0.0, 0.0, 0.0}, 0.3, 0.12, 1000, 500));
    return p.string();
  }();
  return path;
}

void GeometryRead(benchmark::State& state) {
  std::shared_ptr<const geometry::SurfaceMesh> mesh;
  for (auto _ : state) mesh = geometry::read_surface_mesh(torus_file(), {});
  state.counters["triangles"] = static_cast<double>(mesh->n_triangles());
  state.counters["tree_MiB"] = static_cast<double>(mesh->tree_bytes()) / (1024.0 * 1024.0);
  state.counters["tree_B_per_triangle"] = static_cast<double>(mesh->tree_bytes()) / mesh->n_triangles();
}
BENCHMARK(GeometryRead)->Unit(benchmark::kSecond)->Iterations(1);

void GeometryInside(benchmark::State& state) {
  const auto mesh = geometry::read_surface_mesh(torus_file(), {});
  const int n = 256;
  const auto lo = mesh->lo(), hi = mesh->hi();
  std::size_t in = 0, points = 0;
  for (auto _ : state) {
    geometry::LineCache cache;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double x = lo[0] + (i + 0.5) * (hi[0] - lo[0]) / n, y = lo[1] + (j + 0.5) * (hi[1] - lo[1]) / n,
                       z = lo[2] + (k + 0.5) * (hi[2] - lo[2]) / n;
          in += mesh->inside(x, y, z, cache);
          ++points;
        }
  }
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.counters["inside/s"] = benchmark::Counter(static_cast<double>(in), benchmark::Counter::kIsRate);
}
BENCHMARK(GeometryInside)->Unit(benchmark::kSecond)->Iterations(1);

void GeometryFill(benchmark::State& state) {
  const std::string dir = std::filesystem::temp_directory_path().string();
  // Cell 0.008, 2 particles per cell and axis: about 1.6M particles in the torus (volume 0.085).
  const std::string text = R"(
[simulation]
dimension = 3
end_time = 1.0e-3
[grid]
origin = [-0.44, -0.44, -0.136]
extent = [0.88, 0.88, 0.272]
cell_size = 0.008
[[material]]
name = "m"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3
[[body]]
name = "torus"
material = "m"
shape = { mesh = { file = ")" + torus_file() + R"(" } }
)";
  const Config cfg = load_config_string(text, dir + "/bench_geometry.toml");
  std::size_t n = 0;
  for (auto _ : state) {
    Simulation<3> sim(cfg);
    n += sim.particles().n();
  }
  state.counters["particles"] = static_cast<double>(n) / static_cast<double>(state.iterations());
  state.counters["particles/s"] = benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsRate);
}
BENCHMARK(GeometryFill)->Unit(benchmark::kSecond)->Iterations(1);

}  // namespace
}  // namespace cairn
