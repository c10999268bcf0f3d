// Bodies from surface meshes ([[body]] shape `mesh`, docs/geometry.md): each format fills the
// body that the surface encloses, on the particle lattice, with the volume and mass it should
// have; bad files are input errors that name the fault.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "../support/mesh_writer.hpp"
#include "../support/scratch_test.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

constexpr double density = 1000.0;
constexpr double spacing = 0.025;  // cell 0.05, 2 particles per cell per axis

std::string input(const std::string& shape, const std::string& extra = "") {
  return R"toml([simulation]
dimension = 3
end_time = 1.0e-4

[grid]
origin = [0.0, 0.0, 0.0]
extent = [1.0, 1.0, 1.0]
cell_size = 0.05

[[material]]
name = "m"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[[body]]
name = "part"
material = "m"
particles_per_cell = 2
shape = { mesh = { )toml" +
         shape + " } }\n" + extra;
}

class SurfaceMeshBodies : public test::ScratchTest {
 protected:
  Config load(const std::string& shape, const std::string& extra = "") const {
    write("case.toml", input(shape, extra));
    return load_config(path("case.toml"));
  }
  /// The InputError text of loading `shape` and setting the simulation up, or "".
  std::string error_of(const std::string& shape) const {
    return input_error([&] {
      const Config c = load(shape);
      Simulation<3> sim(c);
    });
  }
};

/// Every particle of body 0, with its checks: mass = density x volume, volume = spacing^3.
std::vector<Vec<3>> particles_of(const Simulation<3>& sim) {
  std::vector<Vec<3>> out;
  const auto& p = sim.particles();
  for (std::size_t i = 0; i < p.n(); ++i) {
    EXPECT_DOUBLE_EQ(p.volume0[i], spacing * spacing * spacing);
    EXPECT_DOUBLE_EQ(p.mass[i], density * p.volume0[i]);
    out.push_back(p.position[i]);
  }
  return out;
}

/// Writers of every format, by file name.
const std::vector<std::pair<std::string, std::function<void(const std::string&, const test::TriangleSurface&)>>>&
formats() {
  static const std::vector<std::pair<std::string, std::function<void(const std::string&, const test::TriangleSurface&)>>>
      f{{"ascii.stl", test::write_ascii_stl},
        {"binary.stl", [](const std::string& p, const test::TriangleSurface& s) { test::write_binary_stl(p, s); }},
        {"mesh.obj", test::write_obj},
        {"mesh.off", test::write_off},
        {"ascii.ply", [](const std::string& p, const test::TriangleSurface& s) { test::write_ply(p, s, false); }},
        {"binary.ply", [](const std::string& p, const test::TriangleSurface& s) { test::write_ply(p, s, true); }}};
  return f;
}

/// The lattice points (spacing 0.025 from 0.0125) that `in` holds, in a box of voxel voxels.
std::size_t lattice_count(const std::function<bool(const Vec<3>&)>& in) {
  std::size_t n = 0;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j)
      for (int k = 0; k < 40; ++k) n += in(Vec<3>((i + 0.5) * spacing, (j + 0.5) * spacing, (k + 0.5) * spacing));
  return n;
}

TEST_F(SurfaceMeshBodies, CubeInEveryFormatFillsExactlyItsLatticePoints) {
  // [0.25, 0.75]^3: faces on lattice-cell boundaries, so exactly 20^3 particles; the lattice lines
  // with y = z run along the faces' diagonals (the per-point fallback of the inside test).
  const auto cube = test::voxel_surface(test::voxel_box({0, 0, 0}, {1, 1, 1}), 0.5, {0.25, 0.25, 0.25});
  for (const auto& [name, write] : formats()) {
    SCOPED_TRACE(name);
    write(path(name), cube);
    const Config cfg = load("file = \"" + name + "\"");
    ASSERT_TRUE(cfg.bodies[0].shape.mesh);
    EXPECT_NEAR(cfg.bodies[0].shape.mesh->volume(), 0.125, 1e-12);
    EXPECT_EQ(cfg.bodies[0].shape.mesh->n_triangles(), 12u);
    Simulation<3> sim(cfg);
    const auto x = particles_of(sim);
    EXPECT_EQ(x.size(), 8000u);
    for (const auto& p : x) {
      EXPECT_GT(p.minCoeff(), 0.25);
      EXPECT_LT(p.maxCoeff(), 0.75);
    }
  }
}

TEST_F(SurfaceMeshBodies, ObjQuadsAreTriangulated) {
  // Blender's OBJ export writes quads: the cube [0.25, 0.75]^3 as 6 of them, counter-clockwise
  // seen from outside.
  write("quads.obj",
        "v 0.25 0.25 0.25\nv 0.75 0.25 0.25\nv 0.75 0.75 0.25\nv 0.25 0.75 0.25\n"
        "v 0.25 0.25 0.75\nv 0.75 0.25 0.75\nv 0.75 0.75 0.75\nv 0.25 0.75 0.75\n"
        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n");
  const Config cfg = load("file = \"quads.obj\"");
  EXPECT_TRUE(cfg.warnings.empty());
  EXPECT_EQ(cfg.bodies[0].shape.mesh->n_triangles(), 12u);
  EXPECT_NEAR(cfg.bodies[0].shape.mesh->volume(), 0.125, 1e-12);
  EXPECT_EQ(particles_of(Simulation<3>(cfg)).size(), 8000u);
}

/// Sphere and torus: every lattice point the analytic body holds with a margin `band` from its
/// surface is a particle and no point outside it by `band` is; the particle volume is within the
/// documented bound A l / 10 of the mesh's volume (docs/geometry.md, "How close the volume is").
void check_smooth_body(const Simulation<3>& sim, const geometry::SurfaceMesh& mesh, const test::TriangleSurface& s,
                       const std::function<double(const Vec<3>&)>& signed_distance, double band) {
  const auto x = particles_of(sim);
  for (const auto& p : x) EXPECT_LT(signed_distance(p), band) << p.transpose();
  const std::size_t deep = lattice_count([&](const Vec<3>& p) { return signed_distance(p) < -band; });
  const std::size_t held = lattice_count([&](const Vec<3>& p) { return signed_distance(p) > band; });
  std::size_t deep_particles = 0;
  for (const auto& p : x) deep_particles += signed_distance(p) < -band;
  EXPECT_EQ(deep_particles, deep);
  EXPECT_GT(held, 0u);
  const double volume = static_cast<double>(x.size()) * spacing * spacing * spacing;
  // (a binary STL stores float coordinates: 6e-8 relative each)
  EXPECT_NEAR(mesh.volume(), test::enclosed_volume(s), 1e-6 * mesh.volume());
  const double bound = test::surface_area(s) * spacing / 10.0;
  EXPECT_LE(std::abs(volume - mesh.volume()), bound)
      << "particle volume " << volume << ", mesh volume " << mesh.volume();
  std::printf("particle volume %.6g, mesh volume %.6g: %+.3f %% (bound %.3f %%)\n", volume, mesh.volume(),
              100.0 * (volume / mesh.volume() - 1.0), 100.0 * bound / mesh.volume());
}

TEST_F(SurfaceMeshBodies, SphereInEveryFormatHoldsTheBallWithinTheLatticeResolution) {
  const int n_lat = 24, n_lon = 48;
  const double R = 0.3;
  const auto sphere = test::uv_sphere({0.5, 0.5, 0.5}, R, n_lat, n_lon);
  // Every face lies within R (1 - cos(pi / (2 n_lat) + pi / n_lon)) of the sphere (plus float
  // rounding of a binary STL).
  const double band = R * (1.0 - std::cos(std::numbers::pi / (2 * n_lat) + std::numbers::pi / n_lon)) + 1e-6;
  for (const auto& [name, write] : formats()) {
    SCOPED_TRACE(name);
    write(path(name), sphere);
    const Config cfg = load("file = \"" + name + "\"");
    Simulation<3> sim(cfg);
    check_smooth_body(sim, *cfg.bodies[0].shape.mesh, sphere,
                      [&](const Vec<3>& p) { return (p - Vec<3>(0.5, 0.5, 0.5)).norm() - R; }, band);
  }
}

TEST_F(SurfaceMeshBodies, TorusInEveryFormatHoldsTheRingWithinTheLatticeResolution) {
  const int n_u = 48, n_v = 24;
  const double R = 0.3, r = 0.12;
  const auto ring = test::torus({0.5, 0.5, 0.5}, R, r, n_u, n_v);
  const double band = (R + r) * (1.0 - std::cos(std::numbers::pi / n_u)) + r * (1.0 - std::cos(std::numbers::pi / n_v)) +
                      1e-6;
  for (const auto& [name, write] : formats()) {
    SCOPED_TRACE(name);
    write(path(name), ring);
    const Config cfg = load("file = \"" + name + "\"");
    Simulation<3> sim(cfg);
    check_smooth_body(sim, *cfg.bodies[0].shape.mesh, ring,
                      [&](const Vec<3>& p) {
                        const Vec<3> d = p - Vec<3>(0.5, 0.5, 0.5);
                        return std::hypot(std::hypot(d[0], d[1]) - R, d[2]) - r;
                      },
                      band);
  }
}

/// Voxel bodies aligned with the lattice (voxels of 0.1 = 4 spacings from 0.2): exactly 64
/// particles per voxel, each inside a voxel of the set.
void check_voxels(const Simulation<3>& sim, const std::set<std::array<int, 3>>& voxels) {
  const auto x = particles_of(sim);
  EXPECT_EQ(x.size(), 64u * voxels.size());
  for (const auto& p : x) {
    const std::array<int, 3> v{static_cast<int>(std::floor((p[0] - 0.2) / 0.1)),
                               static_cast<int>(std::floor((p[1] - 0.2) / 0.1)),
                               static_cast<int>(std::floor((p[2] - 0.2) / 0.1))};
    EXPECT_TRUE(voxels.count(v)) << p.transpose();
  }
}

TEST_F(SurfaceMeshBodies, NonConvexMultiShellAndCavityBodies) {
  std::set<std::array<int, 3>> l_shape = test::voxel_box({0, 0, 0}, {3, 1, 2});
  for (const auto& v : test::voxel_box({0, 1, 0}, {1, 3, 2})) l_shape.insert(v);
  std::set<std::array<int, 3>> two = test::voxel_box({0, 0, 0}, {2, 2, 2});
  for (const auto& v : test::voxel_box({3, 3, 3}, {5, 4, 5})) two.insert(v);
  std::set<std::array<int, 3>> hollow = test::voxel_box({0, 0, 0}, {3, 3, 3});
  hollow.erase({1, 1, 1});
  const std::vector<std::tuple<std::string, std::set<std::array<int, 3>>, std::size_t>> cases{
      {"l_shape.stl", l_shape, 1}, {"two_shells.obj", two, 2}, {"cavity.off", hollow, 2}};
  for (const auto& [name, voxels, shells] : cases) {
    SCOPED_TRACE(name);
    const auto s = test::voxel_surface(voxels, 0.1, {0.2, 0.2, 0.2});
    if (name.ends_with(".stl")) test::write_ascii_stl(path(name), s);
    else if (name.ends_with(".obj")) test::write_obj(path(name), s);
    else test::write_off(path(name), s);
    const Config cfg = load("file = \"" + name + "\"");
    EXPECT_EQ(cfg.bodies[0].shape.mesh->n_shells(), shells);
    EXPECT_NEAR(cfg.bodies[0].shape.mesh->volume(), 1e-3 * static_cast<double>(voxels.size()), 1e-12);
    Simulation<3> sim(cfg);
    check_voxels(sim, voxels);
  }
}

TEST_F(SurfaceMeshBodies, InwardAndInconsistentOrientationsAreTurnedWithAWarning) {
  std::set<std::array<int, 3>> hollow = test::voxel_box({0, 0, 0}, {3, 3, 3});
  hollow.erase({1, 1, 1});
  auto inward = test::voxel_surface(hollow, 0.1, {0.2, 0.2, 0.2});
  inward.flip();
  test::write_obj(path("inward.obj"), inward);
  Config cfg = load("file = \"inward.obj\"");
  ASSERT_EQ(cfg.warnings.size(), 1u);
  EXPECT_NE(cfg.warnings[0].find("faces turned so that every shell faces out of the body"), std::string::npos)
      << cfg.warnings[0];
  check_voxels(Simulation<3>(cfg), hollow);

  auto mixed = test::voxel_surface(test::voxel_box({0, 0, 0}, {2, 2, 2}), 0.1, {0.2, 0.2, 0.2});
  std::swap(mixed.triangles[3][1], mixed.triangles[3][2]);
  test::write_off(path("mixed.off"), mixed);
  cfg = load("file = \"mixed.off\"");
  ASSERT_GE(cfg.warnings.size(), 1u);
  EXPECT_NE(cfg.warnings[0].find("edges joined faces of opposite orientation"), std::string::npos) << cfg.warnings[0];
  check_voxels(Simulation<3>(cfg), test::voxel_box({0, 0, 0}, {2, 2, 2}));
}

TEST_F(SurfaceMeshBodies, UnitsScaleRotateAndTranslatePlaceTheSurface) {
  // The file holds [0, 200] x [0, 100] x [0, 100] in mm; rotated 90 degrees about z it becomes
  // [-0.1, 0] x [0, 0.2] x [0, 0.1] m, shifted by [0.3, 0.2, 0.4]: [0.2, 0.3] x [0.2, 0.4] x [0.4, 0.5].
  const auto block = test::voxel_surface(test::voxel_box({0, 0, 0}, {2, 1, 1}), 100.0);
  test::write_binary_stl(path("block.stl"), block);
  const Config cfg =
      load("file = \"block.stl\", units = \"mm\", rotate = [0.0, 0.0, 90.0], translate = [0.3, 0.2, 0.4]");
  EXPECT_NEAR(cfg.bodies[0].shape.mesh->volume(), 0.002, 1e-12);
  Simulation<3> sim(cfg);
  const auto x = particles_of(sim);
  EXPECT_EQ(x.size(), 4u * 8u * 4u);
  for (const auto& p : x) {
    EXPECT_GT(p[0], 0.2);
    EXPECT_LT(p[0], 0.3);
    EXPECT_GT(p[1], 0.2);
    EXPECT_LT(p[1], 0.4);
    EXPECT_GT(p[2], 0.4);
    EXPECT_LT(p[2], 0.5);
  }
  // scale: the same file at scale 1e-3 (no units) is the same body before the rotation.
  const Config scaled = load("file = \"block.stl\", scale = 1.0e-3, translate = [0.2, 0.2, 0.4]");
  EXPECT_EQ(particles_of(Simulation<3>(scaled)).size(), x.size());
}

TEST_F(SurfaceMeshBodies, BadFilesAreInputErrorsNamingTheFault) {
  const auto cube = test::voxel_surface(test::voxel_box({0, 0, 0}, {2, 2, 2}), 0.1, {0.2, 0.2, 0.2});
  auto expect_error = [&](const std::string& name, const std::string& fault) {
    SCOPED_TRACE(name);
    const std::string e = error_of("file = \"" + name + "\"");
    EXPECT_NE(e.find(fault), std::string::npos) << e;
    EXPECT_NE(e.find(name), std::string::npos) << e;
    EXPECT_NE(e.find("body[0].shape.mesh.file"), std::string::npos) << e;
  };
  auto open = cube;
  open.triangles.pop_back();
  test::write_ascii_stl(path("open.stl"), open);
  expect_error("open.stl", "3 open edges");

  // Two voxels touching along an edge: that edge has four faces.
  test::write_obj(path("edge.obj"), test::voxel_surface({{0, 0, 0}, {1, 1, 0}}, 0.1, {0.2, 0.2, 0.2}));
  expect_error("edge.obj", "not a manifold surface: 1 edge shared by more than two faces");

  auto crossing = cube;  // a second cube through the first
  crossing.add(test::voxel_surface(test::voxel_box({0, 0, 0}, {2, 2, 2}), 0.1, {0.25, 0.25, 0.25}));
  test::write_off(path("crossing.off"), crossing);
  expect_error("crossing.off", "the surface intersects itself");

  auto flat = cube;  // a zero-area triangle
  flat.vertices.push_back({0.2, 0.2, 0.3});
  flat.triangles.push_back({0, static_cast<int>(flat.vertices.size()) - 1, 0});
  flat.triangles.back()[2] = flat.triangles.back()[1];
  test::write_obj(path("repeated.obj"), flat);
  expect_error("repeated.obj", "degenerate face #48");

  auto line = cube;
  line.vertices.push_back({0.2, 0.2, 0.2});
  line.vertices.push_back({0.3, 0.3, 0.3});
  line.vertices.push_back({0.4, 0.4, 0.4});
  const int n = static_cast<int>(line.vertices.size());
  line.triangles.insert(line.triangles.begin() + 5, {n - 3, n - 2, n - 1});
  test::write_off(path("line.off"), line);
  expect_error("line.off", "degenerate face #5 (counting from 0): zero area");

  std::ofstream(path("empty.stl")).close();
  expect_error("empty.stl", "the file is empty");
  std::ofstream(path("nothing.off")) << "OFF\n0 0 0\n";
  expect_error("nothing.off", "no faces");

  test::write_binary_stl(path("count.stl"), cube, 1000);
  expect_error("count.stl", "header counts 1000 triangles");
  test::write_binary_stl(path("short.stl"), cube);
  fs::resize_file(path("short.stl"), fs::file_size(path("short.stl")) - 30);
  expect_error("short.stl", "(truncated)");

  test::write_ascii_stl(path("cut.stl"), cube);
  fs::resize_file(path("cut.stl"), fs::file_size(path("cut.stl")) / 2);
  expect_error("cut.stl", "could not read it (malformed or truncated");
  test::write_off(path("cut.off"), cube);
  fs::resize_file(path("cut.off"), fs::file_size(path("cut.off")) - 40);
  expect_error("cut.off", "could not read it (malformed or truncated");

  std::ofstream(path("mesh.vtk")) << "# vtk\n";
  expect_error("mesh.vtk", "extension '.vtk' is none of .stl, .obj, .ply, .off");
  expect_error("missing.stl", "no such file");

  // A surface reaching past the grid.
  test::write_obj(path("far.obj"), test::voxel_surface(test::voxel_box({0, 0, 0}, {2, 2, 2}), 0.1, {0.9, 0.2, 0.2}));
  const std::string e = error_of("file = \"far.obj\"");
  EXPECT_NE(e.find("body[0].shape"), std::string::npos) << e;
  EXPECT_NE(e.find("clip"), std::string::npos) << e;
}

TEST_F(SurfaceMeshBodies, CommandLineExitsWithTwoOnABadMeshAndReportsVolumes) {
  auto open = test::voxel_surface(test::voxel_box({0, 0, 0}, {2, 2, 2}), 0.1, {0.2, 0.2, 0.2});
  test::write_ascii_stl(path("good.stl"), open);
  open.triangles.erase(open.triangles.begin() + 7);
  test::write_binary_stl(path("open.stl"), open);
  auto cli = [&](const std::string& file, const std::string& log) {
    std::ofstream(dir_ / "case.toml") << input("file = \"" + file + "\"");
    const std::string cmd = std::string(CAIRN_BINARY) + " check " + (dir_ / "case.toml").string() + " > " +
                            (dir_ / log).string() + " 2>&1";
    return WEXITSTATUS(std::system(cmd.c_str()));
  };
  auto text = [&](const std::string& log) {
    std::ifstream f(dir_ / log);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  EXPECT_EQ(cli("open.stl", "bad.txt"), 2);
  EXPECT_NE(text("bad.txt").find("not closed (not watertight): 3 open edges"), std::string::npos) << text("bad.txt");
  EXPECT_EQ(cli("good.stl", "good.txt"), 0) << text("good.txt");
  EXPECT_NE(text("good.txt").find("body 'part': 512 particles of volume 0.008, mesh volume 0.008 ("),
            std::string::npos)
      << text("good.txt");
  EXPECT_NE(text("good.txt").find("0.000 %; good.stl: 48 triangles, 1 shell, AABB tree"), std::string::npos)
      << text("good.txt");
}

}  // namespace
}  // namespace cairn
