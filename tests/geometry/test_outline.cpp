// 2D bodies from outline files with holes ([[body]] shape `outline`, docs/geometry.md): the
// lattice points inside the first loop and outside the others; bad files name line and fault.
// A closed surface mesh cut at z = slice_z gives the loops too.
#include <gtest/gtest.h>

#include "../support/mesh_writer.hpp"
#include "../support/scratch_test.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

const std::string input = R"toml([simulation]
dimension = 2
end_time = 1.0e-4

[grid]
origin = [0.0, 0.0]
extent = [1.0, 1.0]
cell_size = 0.05

[[material]]
name = "m"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[[body]]
name = "plate"
material = "m"
shape = { outline = { file = "plate.csv", scale = 0.1, translate = [0.1, 0.1] } }
)toml";

class OutlineBodies : public test::ScratchTest {
 protected:
  Config load(const std::string& csv) const {
    write("plate.csv", csv);
    write("case.toml", input);
    return load_config(path("case.toml"));
  }
  std::string error_of(const std::string& csv) const {
    return input_error([&] { load(csv); });
  }
};

TEST_F(OutlineBodies, HolesAreLeftEmptyAndTheRestFilledOnTheLattice) {
  // In file units (x 0.1, + 0.1): the square [0, 6]^2 with holes [1, 3] x [1, 2] and [4, 5] x [2, 5],
  // all edges on lattice-cell boundaries (spacing 0.025): 576 - 32 - 48 = 496 particles.
  const Config cfg = load(
      "# a plate with two holes\nx, y\n0, 0\n6, 0\n6, 6\n0, 6\n0, 0\n\n1, 1\n1, 2\n3, 2\n3, 1\n\n\n4, 2\n5, 2\n5, 5\n4, 5\n");
  ASSERT_EQ(cfg.bodies[0].shape.loops.size(), 3u);
  Simulation<2> sim(cfg);
  const auto& p = sim.particles();
  EXPECT_EQ(p.n(), 576u - 32u - 48u);
  double area = 0.0;
  for (std::size_t i = 0; i < p.n(); ++i) {
    const Vec<2> u = (p.position[i] - Vec<2>(0.1, 0.1)) / 0.1;
    EXPECT_TRUE(u.minCoeff() > 0.0 && u.maxCoeff() < 6.0) << u.transpose();
    EXPECT_FALSE(u[0] > 1.0 && u[0] < 3.0 && u[1] > 1.0 && u[1] < 2.0) << u.transpose();
    EXPECT_FALSE(u[0] > 4.0 && u[0] < 5.0 && u[1] > 2.0 && u[1] < 5.0) << u.transpose();
    area += p.volume0[i];
  }
  EXPECT_NEAR(area, (36.0 - 2.0 - 3.0) * 0.01 * cfg.simulation.thickness, 1e-12);
}

TEST_F(OutlineBodies, BadFilesAreInputErrorsNamingTheLine) {
  auto expect = [&](const std::string& csv, const std::string& fault) {
    const std::string e = error_of(csv);
    EXPECT_NE(e.find(fault), std::string::npos) << e;
    EXPECT_NE(e.find("body[0].shape.outline.file"), std::string::npos) << e;
  };
  expect("0, 0\n6, 0\n6, x\n", "line 3: 'x' is not a finite number");
  expect("0, 0\n6, 0, 1\n", "line 2: '6, 0, 1' is not two fields x, y");
  expect("0, 0\n6, 0\n6, 6\n\n1, 1\n2, 1\n", "hole 1 has 2 vertices, fewer than 3");
  expect("0, 0\n6, 0\n0, 4\n5, 6\n", "cross or touch");
  expect("0, 0\n6, 0\n6, 6\n0, 6\n\n5, 5\n7, 5\n7, 7\n", "cross or touch");
  expect("0, 0\n6, 0\n6, 6\n0, 6\n\n7, 7\n8, 7\n8, 8\n", "line 6: hole 1 lies outside the outside loop");
  expect("0, 0\n1, 1\n2, 2\n", "encloses no area");
  expect("# nothing\n", "no loop");
}

TEST_F(OutlineBodies, ASurfaceMeshCutAtSliceZGivesTheLoopsOfItsSection) {
  // Voxels (unit cubes, two layers): the plate [0, 6]^2 with the through holes [1, 3] x [1, 2] and
  // [4, 5] x [2, 5], and apart from it the island [7, 9] x [0, 2]; cut in the middle of the lower layer.
  auto voxels = test::voxel_box({0, 0, 0}, {6, 6, 2});
  for (const auto& v : test::voxel_box({1, 1, 0}, {3, 2, 2})) voxels.erase(v);
  for (const auto& v : test::voxel_box({4, 2, 0}, {5, 5, 2})) voxels.erase(v);
  for (const auto& v : test::voxel_box({7, 0, 0}, {9, 2, 2})) voxels.insert(v);
  test::write_obj(path("part.obj"), test::voxel_surface(voxels, 1.0, {0.0, 0.0, 0.0}));
  std::string text = input;
  text.replace(text.find("file = \"plate.csv\", scale = 0.1, translate = [0.1, 0.1]"), 55,
               "file = \"part.obj\", scale = 0.1, translate = [0.05, 0.05], slice_z = 0.05");
  write("case.toml", text);
  const Config cfg = load_config(path("case.toml"));
  ASSERT_EQ(cfg.bodies[0].shape.loops.size(), 4u);  // the plate's outside first (the largest)
  EXPECT_EQ(cfg.bodies[0].shape.slice_z, 0.05);
  Simulation<2> sim(cfg);
  const auto& p = sim.particles();
  EXPECT_EQ(p.n(), 576u - 32u - 48u + 64u);  // the lattice (spacing 0.025) of the CSV plate, and the island
  double area = 0.0;
  for (std::size_t i = 0; i < p.n(); ++i) {
    const Vec<2> u = (p.position[i] - Vec<2>(0.05, 0.05)) / 0.1;
    EXPECT_FALSE(u[0] > 1.0 && u[0] < 3.0 && u[1] > 1.0 && u[1] < 2.0) << u.transpose();
    EXPECT_FALSE(u[0] > 6.0 && u[0] < 7.0) << u.transpose();
    EXPECT_FALSE(u[0] > 7.0 && u[1] > 2.0) << u.transpose();
    area += p.volume0[i];
  }
  EXPECT_NEAR(area, (36.0 - 2.0 - 3.0 + 4.0) * 0.01 * cfg.simulation.thickness, 1e-12);
  EXPECT_NE(cfg.resolved_toml.find("slice_z = 0.05"), std::string::npos) << cfg.resolved_toml;

  // A plane that misses the surface: an input error naming the file and the surface's z range.
  text.replace(text.find("slice_z = 0.05"), 14, "slice_z = 0.5");
  write("case.toml", text);
  const std::string e = input_error([&] { load_config(path("case.toml")); });
  EXPECT_NE(e.find("body[0].shape.outline.file"), std::string::npos) << e;
  EXPECT_NE(e.find("cut at z = 0.5: the plane does not cut the surface (its z runs from 0 to 0.2"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace cairn
