// Bodies from a grey-level picture (seed 004 Sec. 4.2): each [[body]] takes the lattice points
// whose pixel has a level in its range; row 0 of the picture is its top (highest y).
#include <gtest/gtest.h>

#include <fstream>

#include "../support/config_builder.hpp"
#include "../support/png_writer.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

// 4 x 3 pixels, rows from the top. Levels 10 and 30 appear once, 100 six times, 255 is empty.
const std::vector<unsigned> picture{10,  100, 100, 255,  //
                                    100, 255, 30,  255,  //
                                    255, 100, 100, 100};

const std::string input = R"toml([simulation]
dimension = 2
end_time = 1.0e-3

[grid]
origin = [0.0, 0.0]
extent = [1.0, 1.0]
cell_size = 0.1

[[material]]
name = "a"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[[material]]
name = "b"
model = "linear_elastic"
density = 2000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[[body]]
name = "corner"
material = "a"
shape = { image = { file = "pic.png", pixel_size = 0.1, origin = [0.2, 0.3], levels = [5, 15] } }

[[body]]
name = "mid"
material = "b"
shape = { image = { file = "pic.png", pixel_size = 0.1, origin = [0.2, 0.3], levels = [90, 110] } }

[[body]]
name = "dot"
material = "a"
shape = { image = { file = "pic.png", pixel_size = 0.1, origin = [0.2, 0.3], levels = [20, 40] } }
)toml";

TEST(ImageBodies, ParticlesFillThePixelsOfTheirLevelsWithRowZeroAtTheTop) {
  const auto dir = test::temp_dir("image_bodies");
  test::write_grey_png((dir / "pic.png").string(), 4, 3, picture);
  std::ofstream(dir / "case.toml") << input;
  const Config cfg = load_config((dir / "case.toml").string());
  Simulation<2> sim(cfg);
  const auto& p = sim.particles();

  // 2 x 2 particles per cell of 0.1 and pixels of 0.1: 4 particles per pixel, none on a pixel edge.
  const double per_pixel = 4.0;
  std::vector<int> count(3, 0);
  std::vector<double> volume(3, 0.0);
  for (std::size_t i = 0; i < p.n(); ++i) {
    ASSERT_GE(p.body[i], 0);
    ASSERT_LT(p.body[i], 3);
    ++count[p.body[i]];
    volume[p.body[i]] += p.volume0[i];
  }
  EXPECT_EQ(count[0], 1 * per_pixel);
  EXPECT_EQ(count[1], 6 * per_pixel);
  EXPECT_EQ(count[2], 1 * per_pixel);
  EXPECT_EQ(p.n(), 8u * 4u);
  EXPECT_NEAR(volume[1], 6 * 0.1 * 0.1 * cfg.simulation.thickness, 1e-12);

  for (std::size_t i = 0; i < p.n(); ++i) {
    const auto& x = p.position[i];
    if (p.body[i] == 0) {
      // Top-left pixel (col 0, row 0): the top row of the picture lies at the highest y.
      EXPECT_GT(x[0], 0.2);
      EXPECT_LT(x[0], 0.3);
      EXPECT_GT(x[1], 0.5);
      EXPECT_LT(x[1], 0.6);
      EXPECT_EQ(p.material[i], 0);
    } else if (p.body[i] == 2) {
      // col 2, row 1: x in [0.4, 0.5], y in [0.4, 0.5].
      EXPECT_GT(x[0], 0.4);
      EXPECT_LT(x[0], 0.5);
      EXPECT_GT(x[1], 0.4);
      EXPECT_LT(x[1], 0.5);
    } else {
      EXPECT_EQ(p.material[i], 1);
      EXPECT_GT(x[0], 0.2);
      EXPECT_LT(x[0], 0.6);
      EXPECT_GT(x[1], 0.3);
      EXPECT_LT(x[1], 0.6);
    }
  }
}

TEST(ImageBodies, PositionsOnPixelEdgesTakeThePixelOnTheirPlusSide) {
  // One particle per cell of 0.7 and pixels of 0.35: particles fall on pixel edges (x = 1 and
  // 3 pixels, y = 1 pixel). In floating point 1.05 / 0.35 is just below 3, yet every particle
  // must take the pixel on the + side of its edge.
  const auto dir = test::temp_dir("image_bodies_edges");
  test::write_grey_png((dir / "pic.png").string(), 4, 2, {0, 100, 0, 100,  //
                                                          0, 100, 0, 100});
  Config cfg = test::box_config(2, "bspline2");
  cfg.grid.extent = {2.1, 2.1};
  cfg.grid.cell_size = {0.7, 0.7};
  cfg.source_file = (dir / "case.toml").string();
  cfg.bodies[0].particles_per_cell = {1, 1};
  auto& s = cfg.bodies[0].shape;
  s.kind = "image";
  s.file = "pic.png";
  s.pixel_size = 0.35;
  s.origin = {0.0, 0.0};
  s.level_min = 90;
  s.level_max = 110;
  Simulation<2> sim(cfg);
  EXPECT_EQ(sim.particles().n(), 2u);  // x = 0.35, 1.05 at y = 0.35 (row 0, the top)
}

TEST(ImageBodies, AConfigBuiltInCodeReadsThePictureItself) {
  const auto dir = test::temp_dir("image_bodies_code");
  test::write_grey_png((dir / "pic.png").string(), 4, 3, picture);
  Config cfg = test::box_config(2, "bspline2");
  cfg.source_file = (dir / "case.toml").string();  // the picture is found next to it
  auto& s = cfg.bodies[0].shape;
  s.kind = "image";
  s.file = "pic.png";
  s.pixel_size = 0.05;  // one particle per pixel
  s.origin = {0.0, 0.0};
  s.level_min = 90;
  s.level_max = 110;
  Simulation<2> sim(cfg);
  EXPECT_EQ(sim.particles().n(), 6u);

  s.file = "absent.png";
  try {
    Simulation<2> broken(cfg);
    ADD_FAILURE() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("absent.png"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cairn
