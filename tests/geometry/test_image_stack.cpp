// Bodies from a stack of PNG slices ([[body]] shape `image_stack`, 3D; seed 004 Sec. 4.2 from
// one picture to a CT-like stack, docs/geometry.md): the slices are ordered by the number in
// their names, each body takes the voxels of its grey-level range; a bad stack (missing slice,
// slices of different sizes, empty folder, a name without a number) is an input error at
// `folder` naming the file.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "../support/png_writer.hpp"
#include "../support/scratch_test.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/geometry/image.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

/// One slice: width x height levels, row 0 the top, from level(col, row).
template <class Level>
void write_slice(const fs::path& path, int width, int height, Level&& level) {
  std::vector<unsigned> v;
  for (int row = 0; row < height; ++row)
    for (int col = 0; col < width; ++col) v.push_back(level(col, row));
  test::write_grey_png(path.string(), width, height, v);
}

std::string stack_input(const std::string& bodies) {
  return "[simulation]\ndimension = 3\nend_time = 1.0e-4\n\n[grid]\norigin = [0.0, 0.0, 0.0]\n"
         "extent = [1.0, 1.0, 1.0]\ncell_size = 0.1\n\n"
         "[[material]]\nname = \"bone\"\nmodel = \"linear_elastic\"\ndensity = 2000.0\nyoungs_modulus = 1.0e6\n"
         "poissons_ratio = 0.3\n\n"
         "[[material]]\nname = \"marrow\"\nmodel = \"linear_elastic\"\ndensity = 1000.0\nyoungs_modulus = 1.0e5\n"
         "poissons_ratio = 0.3\n\n" +
         bodies;
}

std::string body(const std::string& name, const std::string& material, const std::string& shape_keys,
                 int ppc = 2) {
  return "[[body]]\nname = \"" + name + "\"\nmaterial = \"" + material + "\"\nparticles_per_cell = " +
         std::to_string(ppc) + "\n" +
         "shape = { image_stack = { " + shape_keys + " } }\n\n";
}

class ImageStackBodies : public test::ScratchTest {
 protected:
  /// A box of bone (level 200: columns and rows 1..6, slices 1..4 of 8 x 8 x 6) around a
  /// cavity of marrow (level 100: columns and rows 3..4, slices 2..3), and one marker voxel
  /// (level 30) at column 0, row 0 (the top), slice 5. The slices are ct_8.png .. ct_13.png, so
  /// that sorting the names as text would put ct_10 first.
  void write_box_with_cavity(const std::string& folder) const {
    fs::create_directories(dir_ / folder);
    for (int k = 0; k < 6; ++k)
      write_slice(dir_ / folder / ("ct_" + std::to_string(8 + k) + ".png"), 8, 8, [&](int c, int r) {
        if (k == 5 && c == 0 && r == 0) return 30;
        const bool box = c >= 1 && c <= 6 && r >= 1 && r <= 6 && k >= 1 && k <= 4;
        const bool cavity = c >= 3 && c <= 4 && r >= 3 && r <= 4 && k >= 2 && k <= 3;
        return cavity ? 100 : box ? 200 : 0;
      });
    std::ofstream(dir_ / folder / "notes.txt") << "not a slice\n";
  }
  static constexpr const char* placement = "pixel_size = 0.05, slice_spacing = 0.1, origin = [0.2, 0.1, 0.3]";
  std::string box_input() const {
    const std::string f = std::string("folder = \"ct\", ") + placement;
    return stack_input(body("shell", "bone", f + ", levels = [150, 255]") +
                       body("core", "marrow", f + ", levels = [90, 110]") +
                       body("marker", "bone", f + ", levels = [20, 40]"));
  }
};

struct Tally {
  std::size_t n = 0;
  double volume = 0.0, mass = 0.0;
  Vec<3> centroid = Vec<3>::Zero();
};

std::vector<Tally> per_body(const Particles<3>& p, std::size_t n_bodies) {
  std::vector<Tally> t(n_bodies);
  for (std::size_t i = 0; i < p.n(); ++i) {
    Tally& b = t[static_cast<std::size_t>(p.body[i])];
    ++b.n;
    b.volume += p.volume0[i];
    b.mass += p.mass[i];
    b.centroid += p.volume0[i] * p.position[i];
  }
  for (Tally& b : t)
    if (b.volume > 0.0) b.centroid /= b.volume;
  return t;
}

TEST_F(ImageStackBodies, ABoxWithACavityHasTheVolumeMassAndPositionOfItsVoxels) {
  write_box_with_cavity("ct");
  write("case.toml", box_input());
  const Config cfg = load_config(path("case.toml"));
  ASSERT_EQ(cfg.bodies.size(), 3u);
  const auto& s = cfg.bodies[0].shape;
  EXPECT_EQ(s.kind, "image_stack");
  EXPECT_EQ(s.pattern, "*.png");
  ASSERT_TRUE(s.image);
  EXPECT_EQ(s.image->depth, 6);
  EXPECT_EQ(fs::path(s.image->files.front()).filename().string(), "ct_8.png");  // by number, not as text
  EXPECT_EQ(fs::path(s.image->files.back()).filename().string(), "ct_13.png");
  EXPECT_EQ(cfg.bodies[1].shape.image.get(), s.image.get());  // read once

  Simulation<3> sim(cfg);
  const auto t = per_body(sim.particles(), 3);
  // A voxel is 0.05 x 0.05 x 0.1; the lattice (spacing 0.05) puts 1 x 1 x 2 points in each.
  const double voxel = 0.05 * 0.05 * 0.1;
  const double shell_voxels = 6 * 6 * 4 - 2 * 2 * 2, core_voxels = 2 * 2 * 2;
  EXPECT_EQ(t[0].n, static_cast<std::size_t>(2 * shell_voxels));
  EXPECT_NEAR(t[0].volume, shell_voxels * voxel, 1e-12);
  EXPECT_NEAR(t[0].mass, 2000.0 * shell_voxels * voxel, 1e-9);
  EXPECT_EQ(t[1].n, static_cast<std::size_t>(2 * core_voxels));
  EXPECT_NEAR(t[1].volume, core_voxels * voxel, 1e-12);
  EXPECT_NEAR(t[1].mass, 1000.0 * core_voxels * voxel, 1e-9);
  // Shell and core are centred on the box: x 0.2 + 0.05 (1..6 + 1/2), y from the top row
  // 0.1 + 0.05 (8 - (1..6) - 1/2), z 0.3 + 0.1 (1..4 + 1/2).
  for (int b = 0; b < 2; ++b) {
    EXPECT_NEAR(t[b].centroid[0], 0.4, 1e-12) << b;
    EXPECT_NEAR(t[b].centroid[1], 0.3, 1e-12) << b;
    EXPECT_NEAR(t[b].centroid[2], 0.6, 1e-12) << b;
  }
  // The marker: column 0, the top row (highest y), the last slice (highest z).
  EXPECT_EQ(t[2].n, 2u);
  EXPECT_NEAR(t[2].centroid[0], 0.225, 1e-12);
  EXPECT_NEAR(t[2].centroid[1], 0.475, 1e-12);
  EXPECT_NEAR(t[2].centroid[2], 0.85, 1e-12);

  // The resolved input names the folder and pattern and reads back to the same shape.
  EXPECT_NE(cfg.resolved_toml.find("image_stack = { folder = "), std::string::npos) << cfg.resolved_toml;
  const Config r = load_config_string(cfg.resolved_toml, "elsewhere/resolved.toml");
  EXPECT_EQ(r.resolved_toml, cfg.resolved_toml);
  EXPECT_EQ(r.bodies[0].shape.file, s.file);
  EXPECT_EQ(r.bodies[0].shape.slice_spacing, 0.1);
  EXPECT_EQ(r.bodies[0].shape.origin, (std::vector<double>{0.2, 0.1, 0.3}));
}

TEST_F(ImageStackBodies, ASphereScanHoldsTheSphereWithinTheVoxelResolution) {
  // 24 slices of 24 x 24 voxels of edge 0.025: a sphere of radius 0.25 about (0.5, 0.5, 0.5),
  // scanned as a CT scanner would (a voxel is in when its centre is), slices named scan0000..
  const int n = 24;
  const double h = 0.025, radius = 0.25, o = 0.2;
  fs::create_directories(dir_ / "scan");
  long long in = 0;
  for (int k = 0; k < n; ++k)
    write_slice(dir_ / "scan" / fmt::format("scan{:04d}.png", k), n, n, [&](int c, int r) {
      const double x = o + (c + 0.5) * h, y = o + (n - 1 - r + 0.5) * h, z = o + (k + 0.5) * h;
      const bool inside = std::hypot(x - 0.5, y - 0.5, z - 0.5) <= radius;
      in += inside;
      return inside ? 255 : 0;
    });
  write("case.toml", stack_input(body("ball", "bone",
                                      "folder = \"scan\", pattern = \"scan*.png\", pixel_size = 0.025, "
                                      "slice_spacing = 0.025, origin = [0.2, 0.2, 0.2], levels = [128, 255]",
                                      4)));
  Simulation<3> sim(load_config(path("case.toml")));
  const auto t = per_body(sim.particles(), 1);
  // ppc 4 on cells of 0.1: one lattice point at the centre of each voxel.
  EXPECT_EQ(t[0].n, static_cast<std::size_t>(in));
  EXPECT_NEAR(t[0].volume, static_cast<double>(in) * h * h * h, 1e-12);
  EXPECT_NEAR(t[0].mass, 2000.0 * t[0].volume, 1e-9);
  // The scan of a sphere of 10 voxels' radius holds 4224 voxels, 0.84 % more than the sphere.
  const double exact = 4.0 / 3.0 * M_PI * radius * radius * radius;
  EXPECT_NEAR(t[0].volume, exact, 0.02 * exact);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(t[0].centroid[a], 0.5, 1e-12) << a;
}

TEST_F(ImageStackBodies, BadStacksAreInputErrorsAtFolderNamingTheFile) {
  auto error_for = [&](const std::string& folder, const std::string& pattern = "*.png") {
    write("case.toml", stack_input(body("b", "bone",
                                        "folder = \"" + folder + "\", pattern = \"" + pattern + "\", " + placement +
                                            ", levels = [150, 255]")));
    return input_error([&] { load_config(path("case.toml")); });
  };
  auto slice = [&](const std::string& folder, const std::string& name, int w = 8, int h = 8) {
    fs::create_directories(dir_ / folder);
    write_slice(dir_ / folder / name, w, h, [](int, int) { return 200; });
  };
  auto expect = [&](const std::string& e, const std::string& fault) {
    EXPECT_NE(e.find("body[0].shape.image_stack.folder"), std::string::npos) << e;
    EXPECT_NE(e.find(fault), std::string::npos) << e;
  };
  // A missing slice: 1, 2, 4.
  for (const char* name : {"s001.png", "s002.png", "s004.png"}) slice("gap", name);
  expect(error_for("gap"), "slice 3 is missing: the numbers jump from 's002.png' to 's004.png'");
  // Slices of different sizes.
  slice("sizes", "s1.png");
  slice("sizes", "s2.png", 8, 7);
  expect(error_for("sizes"), "slice 's2.png' is 8 x 7 pixels, the first slice 's1.png' 8 x 8");
  // An empty folder, a pattern matching nothing, no folder at all.
  fs::create_directories(dir_ / "empty");
  expect(error_for("empty"), "no file matches '*.png' (an empty folder?)");
  expect(error_for("sizes", "ct_*.png"), "no file matches 'ct_*.png'");
  expect(error_for("nowhere"), "not a folder");
  // A name without a number, two names with one number, a slice that is no PNG.
  slice("names", "a.png");
  slice("names", "b.png");
  expect(error_for("names"), "has no slice number");
  slice("twice", "s1.png");
  slice("twice", "s01.png");
  expect(error_for("twice"), "have the same slice number 1");
  slice("broken", "s1.png");
  std::ofstream(dir_ / "broken" / "s2.png") << "not a picture\n";
  expect(error_for("broken"), "s2.png': not a PNG file");
}

TEST_F(ImageStackBodies, CommandLineExitsWithTwoNamingTheMissingSlice) {
  write_box_with_cavity("ct");
  fs::remove(dir_ / "ct" / "ct_10.png");
  write("case.toml", box_input());
  const std::string log = path("log.txt");
  const std::string cmd = std::string(CAIRN_BINARY) + " check " + path("case.toml") + " > " + log + " 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 2);
  std::stringstream text;
  text << std::ifstream(log).rdbuf();
  EXPECT_NE(text.str().find("slice 10 is missing: the numbers jump from 'ct_9.png' to 'ct_11.png'"),
            std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("case.toml:"), std::string::npos) << text.str();
}

TEST_F(ImageStackBodies, OnlyThreeDimensional) {
  write_box_with_cavity("ct");
  std::string text = box_input();
  text.replace(text.find("dimension = 3"), 13, "dimension = 2");
  text.replace(text.find("origin = [0.0, 0.0, 0.0]"), 24, "origin = [0.0, 0.0]");
  text.replace(text.find("extent = [1.0, 1.0, 1.0]"), 24, "extent = [1.0, 1.0]");
  write("case.toml", text);
  const std::string e = input_error([&] { load_config(path("case.toml")); });
  EXPECT_NE(e.find("valid in 2D"), std::string::npos) << e;
}

}  // namespace
}  // namespace cairn
