// Bodies from CSV point files ([[body]] shape `points`, docs/geometry.md): one particle per row
// with its position, volume (mass = density x volume), optional velocity, temperature and initial
// stress; bad files are input errors naming the file, the line and the fault.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "../support/scratch_test.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/io/hdf5_util.hpp"
#include "cairn/input/input.hpp"
#include "cairn/materials/initial_stress.hpp"
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

// ---- initial stresses ---------------------------------------------------------------------

/// A block of n^D particles of spacing 0.05 from 0.2 (the lattice of 2 particles per 0.1 cell),
/// each with the stress `columns` (the CSV fields after x, y(, z), volume).
std::string stressed_block(int dim, int n, const std::string& header, const std::string& columns) {
  std::string csv = (dim == 3 ? "x,y,z,volume," : "x,y,volume,") + header + "\n";
  const double h = 0.05, v = dim == 3 ? h * h * h : h * h;
  for (int k = 0; k < (dim == 3 ? n : 1); ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        csv += fmt::format("{},{},", 0.2 + (i + 0.5) * h, 0.2 + (j + 0.5) * h);
        if (dim == 3) csv += fmt::format("{},", 0.2 + (k + 0.5) * h);
        csv += fmt::format("{},{}\n", v, columns);
      }
  return csv;
}

/// The particle's Cauchy stress tau / det F.
Mat3 cauchy(const Particles<3>& p, std::size_t i) {
  return p.kirchhoff_stress[i].full() / p.deformation_gradient[i].determinant();
}

TEST_F(PointFiles, StressColumnsStartEachParticleAtThatStressAndTheMaterialKeepsIt) {
  // sigma0 (Pa, tension positive) in Voigt order xx, yy, zz, yz, xz, xy; E = 1 MPa.
  const std::array<double, 6> s0{-1.0e4, -2.0e4, -3.0e4, 1.0e3, 2.0e3, 3.0e3};
  const std::string columns = fmt::format("{}", fmt::join(s0, ","));
  const Config cfg = load(3, stressed_block(3, 12, "sxx,syy,szz,syz,sxz,sxy", columns));
  Simulation<3> sim(cfg);
  const auto& p = sim.particles();
  ASSERT_EQ(p.n(), 12u * 12u * 12u);
  SymMat3 target;
  target.voigt() = s0;
  const Mat3 sigma0 = target.full();
  for (std::size_t i = 0; i < p.n(); ++i) {
    ASSERT_LT((cauchy(p, i) - sigma0).norm(), 1e-9 * sigma0.norm()) << i;
    // The stress is the material's own for the particle's F (a stretch: symmetric, no turn).
    ASSERT_LT((p.deformation_gradient[i] - p.deformation_gradient[i].transpose()).norm(), 1e-15);
    EXPECT_DOUBLE_EQ(p.mass[i], 2000.0 * 0.05 * 0.05 * 0.05);  // density x the file's volume
  }
  // Compression: the particles start smaller than their stress-free volume.
  EXPECT_LT(p.deformation_gradient[0].determinant(), 1.0);
  // One step: the block's inside is in equilibrium, so its particles keep the stress (a stress
  // set without its stretch would be undone by the first stress update).
  sim.step(sim.next_dt());
  std::size_t inside = 0;
  for (std::size_t i = 0; i < sim.particles().n(); ++i) {
    const Vec<3> X = sim.particles().reference_position[i];
    if (((X.array() - 0.5).abs() > 0.06).any()) continue;
    ++inside;
    EXPECT_LT((cauchy(sim.particles(), i) - sigma0).norm(), 1e-6 * sigma0.norm()) << i;
  }
  EXPECT_EQ(inside, 8u);
}

TEST_F(PointFiles, TwoDimensionalStressesAreInPlaneWithThePlaneStrainStressOutOfPlane) {
  // Plane strain: F_zz = 1 and sigma_zz follows from the material: nu (sxx + syy) for small strains.
  const Config cfg = load(2, stressed_block(2, 4, "sxy,sxx,syy", "500.0,-1000.0,-3000.0"));
  Simulation<2> sim(cfg);
  const auto& p = sim.particles();
  ASSERT_EQ(p.n(), 16u);
  for (std::size_t i = 0; i < p.n(); ++i) {
    const Mat3 s = p.kirchhoff_stress[i].full() / p.deformation_gradient[i].determinant();
    EXPECT_NEAR(s(0, 0), -1000.0, 1e-9);
    EXPECT_NEAR(s(1, 1), -3000.0, 1e-9);
    EXPECT_NEAR(s(0, 1), 500.0, 1e-9);
    EXPECT_EQ(p.deformation_gradient[i](2, 2), 1.0);
    EXPECT_NEAR(s(2, 2), 0.3 * (-4000.0), 0.01 * 1200.0);
  }
  // The same from HDF5: a stress dataset of n x 3 (xx, yy, xy).
  const double position[4] = {0.3, 0.3, 0.6, 0.6}, volume[2] = {0.01, 0.01};
  const double stress[6] = {-1000.0, -3000.0, 500.0, 0.0, 0.0, 0.0};
  {
    const h5::Handle file = h5::create_file(path("points.h5"));
    h5::write_doubles(file.get(), "position", position, 2, 2);
    h5::write_doubles(file.get(), "volume", volume, 2);
    h5::write_doubles(file.get(), "stress", stress, 2, 3);
  }
  std::string text = input(2, "", "points.h5");
  write("case.toml", text);
  Simulation<2> h5sim(load_config(path("case.toml")));
  const auto& q = h5sim.particles();
  ASSERT_EQ(q.n(), 2u);
  const Mat3 s = q.kirchhoff_stress[0].full() / q.deformation_gradient[0].determinant();
  EXPECT_NEAR(s(0, 0), -1000.0, 1e-9);
  EXPECT_NEAR(s(1, 1), -3000.0, 1e-9);
  EXPECT_NEAR(s(0, 1), 500.0, 1e-9);
  const Mat3 zero = q.kirchhoff_stress[1].full();
  EXPECT_EQ(zero.norm(), 0.0);  // the second row: no stress, no stretch
  EXPECT_TRUE(q.deformation_gradient[1].isIdentity(0.0));
}

TEST_F(PointFiles, StressesAMaterialCannotTakeAreRefusedNamingTheFile) {
  // Columns: all or none; a wrong HDF5 shape.
  EXPECT_NE(error_of(3, "x,y,z,volume,sxx,syy\n").find("2 of the 6 stress columns sxx, syy, szz, syz, sxz, sxy"),
            std::string::npos);
  EXPECT_NE(error_of(2, "x,y,volume,szz\n").find("unknown column 'szz'"), std::string::npos);
  {
    const double position[4] = {0.3, 0.3, 0.6, 0.6}, volume[2] = {0.01, 0.01}, stress[4] = {1, 2, 3, 4};
    const h5::Handle file = h5::create_file(path("bad.h5"));
    h5::write_doubles(file.get(), "position", position, 2, 2);
    h5::write_doubles(file.get(), "volume", volume, 2);
    h5::write_doubles(file.get(), "stress", stress, 2, 2);
  }
  write("case.toml", input(2, "", "bad.h5"));
  const std::string h = input_error([&] { load_config(path("case.toml")); });
  EXPECT_NE(h.find("dataset 'stress' of shape [2, 2], not 2 x 3 (xx, yy, xy)"), std::string::npos) << h;

  // A path-dependent model keeps its stress in its state: refused at the body's file.
  // One stressed particle of a material given as its model's lines: the set-up's error.
  auto set_up_error = [&](const std::string& material, const std::string& stress) {
    std::string text = input(3, "", "points.csv");
    text.replace(text.find("thickness = 0.5\n"), 16, "");
    const std::string elastic =
        "model = \"linear_elastic\"\ndensity = 2000.0\nyoungs_modulus = 1.0e6\npoissons_ratio = 0.3\n";
    text.replace(text.find(elastic), elastic.size(), material);
    write("points.csv", "x,y,z,volume,sxx,syy,szz,syz,sxz,sxy\n0.5,0.5,0.5,1e-3," + stress + "\n");
    write("case.toml", text);
    const Config cfg = load_config(path("case.toml"));
    return input_error([&] { Simulation<3> sim(cfg); });
  };
  const std::string e = set_up_error(
      "model = \"mie_gruneisen\"\ndensity = 8870.0\nbulk_modulus = 188e9\nshear_modulus = 76e9\ngamma0 = 2.0\n"
      "s1 = 1.44\nyield_stress = 1e9\n",
      "-1e6,-1e6,-1e6,0,0,0");
  EXPECT_NE(e.find("body[0].shape.points.file"), std::string::npos) << e;
  EXPECT_NE(e.find("(model mie_gruneisen), which keeps its stress in state variables"), std::string::npos) << e;

  // A stress beyond what the material can carry: a tension of 1e9 E, which no stretch of a
  // neo-Hookean solid reaches (its Kirchhoff stress grows slower than J).
  const std::string f = set_up_error(
      "model = \"neo_hookean\"\ndensity = 2000.0\nyoungs_modulus = 1.0e6\npoissons_ratio = 0.3\n",
      "1e15,1e15,1e15,0,0,0");
  EXPECT_NE(f.find("particle 1 of"), std::string::npos) << f;
  EXPECT_NE(f.find("no such stretch found"), std::string::npos) << f;
}

TEST(InitialStretch, NeoHookeanAndCorotationalStretchesCarryTheStress) {
  for (const char* model : {"neo_hookean", "linear_elastic"}) {
    MaterialConfig c;
    c.name = "m";
    c.model = model;
    c.numbers = {{"density", 1000.0}, {"youngs_modulus", 1.0e6}, {"poissons_ratio", 0.25}};
    const auto m = make_material(c);
    ASSERT_TRUE(takes_initial_stress(*m));
    Mat3 sigma0;
    sigma0 << -2.0e5, 3.0e4, 0.0, 3.0e4, 1.0e5, -2.0e4, 0.0, -2.0e4, -5.0e4;  // strains of ~ 20 %
    const auto V = initial_stretch(*m, sigma0, false, false);
    ASSERT_TRUE(V) << model;
    EXPECT_LT((m->kirchhoff(*V) / V->determinant() - sigma0).norm(), 1e-9 * sigma0.norm()) << model;
    // Plane stress: tau_zz = 0, the in-plane part matched.
    Mat3 planar = sigma0;
    planar(0, 2) = planar(2, 0) = planar(1, 2) = planar(2, 1) = 0.0;
    const auto W = initial_stretch(*m, planar, true, true);
    ASSERT_TRUE(W) << model;
    const Mat3 s = m->kirchhoff(*W) / W->determinant();
    EXPECT_NEAR(s(2, 2), 0.0, 1e-9 * sigma0.norm()) << model;
    EXPECT_NEAR(s(0, 1), 3.0e4, 1e-9 * sigma0.norm()) << model;
    EXPECT_NEAR(s(1, 1), 1.0e5, 1e-9 * sigma0.norm()) << model;
  }
}

}  // namespace
}  // namespace cairn
