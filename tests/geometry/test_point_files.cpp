// Bodies from CSV point files ([[body]] shape `points`, docs/geometry.md): one particle per row
// with its position, volume (mass = density x volume), optional velocity and temperature; bad
// files are input errors naming the file, the line and the fault.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "../support/scratch_test.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/io/hdf5_util.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

std::string input(int dim, const std::string& velocity = "", const std::string& file = "points.csv") {
  const std::string v3 = dim == 3 ? ", 0.0" : "";
  return "[simulation]\ndimension = " + std::to_string(dim) +
         "\nend_time = 1.0e-4\nthickness = 0.5\n\n[grid]\norigin = [0.0, 0.0" + v3 + "]\nextent = [1.0, 1.0" +
         (dim == 3 ? ", 1.0" : "") +
         "]\ncell_size = 0.1\n\n[[material]]\nname = \"m\"\nmodel = \"linear_elastic\"\ndensity = 2000.0\n"
         "youngs_modulus = 1.0e6\npoissons_ratio = 0.3\n\n[[body]]\nname = \"cloud\"\nmaterial = \"m\"\n"
         "shape = { points = { file = \"" + file + "\" } }\n" +
         velocity;
}

class PointFiles : public test::ScratchTest {
 protected:
  Config load(int dim, const std::string& csv, const std::string& velocity = "") const {
    write("points.csv", csv);
    std::string text = input(dim, velocity);
    if (dim == 3) text.replace(text.find("thickness = 0.5\n"), 16, "");
    write("case.toml", text);
    return load_config(path("case.toml"));
  }
  std::string error_of(int dim, const std::string& csv) const {
    return input_error([&] { load(dim, csv); });
  }
};

TEST_F(PointFiles, EachRowIsOneParticleWithItsVolumeVelocityAndTemperature) {
  const Config cfg = load(3,
                          "# a DEM packing\n"
                          "x, y, z, volume, vx, vy, vz, temperature\n"
                          "0.25, 0.5, 0.5, 1.0e-3, 1.0, 0.0, -2.0, 300.0\n"
                          "\n"
                          "0.75, 0.5, 0.5, 8.0e-3, 0.0, 3.0, 0.0, 350.0\n");
  Simulation<3> sim(cfg);
  const auto& p = sim.particles();
  ASSERT_EQ(p.n(), 2u);
  EXPECT_EQ(p.position[0], Vec<3>(0.25, 0.5, 0.5));
  EXPECT_EQ(p.position[1], Vec<3>(0.75, 0.5, 0.5));
  EXPECT_DOUBLE_EQ(p.volume0[0], 1.0e-3);
  EXPECT_DOUBLE_EQ(p.volume0[1], 8.0e-3);
  EXPECT_DOUBLE_EQ(p.mass[0], 2000.0 * 1.0e-3);
  EXPECT_DOUBLE_EQ(p.mass[1], 2000.0 * 8.0e-3);
  EXPECT_EQ(p.velocity[0], Vec<3>(1.0, 0.0, -2.0));
  EXPECT_EQ(p.velocity[1], Vec<3>(0.0, 3.0, 0.0));
  EXPECT_NEAR(p.size0[1][0], 0.2, 1e-12);  // a cube of the particle's volume
  if (p.has_temperature) {
    EXPECT_EQ(p.temperature[0], 300.0);
    EXPECT_EQ(p.temperature[1], 350.0);
  }
}

TEST_F(PointFiles, TwoDimensionalAreasTakeTheThicknessAndTheBodyVelocityApplies) {
  const Config cfg = load(2, "x,y,volume\n0.3,0.3,0.01\n0.6,0.4,0.02\n0.5,0.8,0.03\n", "velocity = [\"X\", 1.0]\n");
  Simulation<2> sim(cfg);
  const auto& p = sim.particles();
  ASSERT_EQ(p.n(), 3u);
  double volume = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < p.n(); ++i) {
    volume += p.volume0[i];
    mass += p.mass[i];
    EXPECT_DOUBLE_EQ(p.velocity[i][0], p.position[i][0]);
    EXPECT_DOUBLE_EQ(p.velocity[i][1], 1.0);
  }
  EXPECT_NEAR(volume, 0.06 * 0.5, 1e-15);
  EXPECT_NEAR(mass, 2000.0 * 0.06 * 0.5, 1e-12);
}

TEST_F(PointFiles, Hdf5DatasetsGiveTheSameParticles) {
  const double position[6] = {0.25, 0.5, 0.5, 0.75, 0.5, 0.5}, volume[2] = {1.0e-3, 8.0e-3};
  const double velocity[6] = {1.0, 0.0, -2.0, 0.0, 3.0, 0.0};
  {
    const h5::Handle file = h5::create_file(path("points.h5"));
    h5::write_doubles(file.get(), "position", position, 2, 3);
    h5::write_doubles(file.get(), "volume", volume, 2);
    h5::write_doubles(file.get(), "velocity", velocity, 2, 3);
  }
  std::string text = input(3, "", "points.h5");
  text.replace(text.find("thickness = 0.5\n"), 16, "");
  write("case.toml", text);
  const Config cfg = load_config(path("case.toml"));
  Simulation<3> sim(cfg);
  const auto& p = sim.particles();
  ASSERT_EQ(p.n(), 2u);
  EXPECT_EQ(p.position[1], Vec<3>(0.75, 0.5, 0.5));
  EXPECT_DOUBLE_EQ(p.mass[1], 2000.0 * 8.0e-3);
  EXPECT_EQ(p.velocity[0], Vec<3>(1.0, 0.0, -2.0));

  {
    const h5::Handle file = h5::create_file(path("bad.h5"));
    h5::write_doubles(file.get(), "position", position, 3, 2);
    h5::write_doubles(file.get(), "volume", volume, 2);
  }
  text.replace(text.find("points.h5"), 9, "bad.h5");
  write("case.toml", text);
  const std::string e = input_error([&] { load_config(path("case.toml")); });
  EXPECT_NE(e.find("dataset 'position' of shape [3, 2], not n x 3"), std::string::npos) << e;
}

TEST_F(PointFiles, BadFilesAreInputErrorsNamingTheLine) {
  auto expect = [&](int dim, const std::string& csv, const std::string& fault) {
    const std::string e = error_of(dim, csv);
    EXPECT_NE(e.find(fault), std::string::npos) << e;
    EXPECT_NE(e.find("body[0].shape.points.file"), std::string::npos) << e;
  };
  expect(3, "x,y,z,volum\n", "line 1: unknown column 'volum'");
  expect(3, "x,y,volume\n", "line 1: the header has no column 'z'");
  expect(2, "x,y,volume,vx\n", "1 of the 2 velocity columns");
  expect(2, "x,y,volume\n0.1,0.2,0.01\n0.1,0.2\n", "line 3: 2 fields, the header has 3");
  expect(2, "x,y,volume\n0.1,0.2,0.01\n0.1,abc,0.01\n", "line 3: column 'y': 'abc' is not a finite number");
  expect(2, "x,y,volume\n0.1,0.2,-1\n", "line 2: volume -1 is not above zero");
  expect(2, "x,y,volume\n", "a header but no particle rows");
  expect(2, "", "no header row");
}

}  // namespace
}  // namespace cairn
