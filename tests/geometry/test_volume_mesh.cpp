// Bodies from the elements of Gmsh meshes ([[body]] shape `volume_mesh`, docs/geometry.md): one
// particle per element (its centroid) or per point of the symmetric Gauss rule, with the element's
// area/volume (times the weight), so the body's mass is density x mesh volume exactly; a .geo
// outline with a hole is meshed when read (a 2D body with holes from a file).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

#include "../support/scratch_test.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

std::string input(int dim, const std::string& shape) {
  const bool three = dim == 3;
  return "[simulation]\ndimension = " + std::to_string(dim) + "\nend_time = 1.0e-4\n" +
         (three ? "" : "thickness = 0.5\n") + "\n[grid]\norigin = [0.0, 0.0" + (three ? ", 0.0" : "") +
         "]\nextent = [1.0, 1.0" + (three ? ", 1.0" : "") +
         "]\ncell_size = 0.1\n\n[[material]]\nname = \"m\"\nmodel = \"linear_elastic\"\ndensity = 2000.0\n"
         "youngs_modulus = 1.0e6\npoissons_ratio = 0.3\n\n[[body]]\nname = \"part\"\nmaterial = \"m\"\n"
         "shape = { volume_mesh = { " +
         shape + " } }\n";
}

/// Gmsh 2.2 text: nodes (x, y, z) and elements (Gmsh type, node numbers from 1).
std::string msh(const std::vector<std::array<double, 3>>& nodes,
                const std::vector<std::pair<int, std::vector<int>>>& elements) {
  std::ostringstream s;
  s.precision(17);
  s << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << nodes.size() << "\n";
  for (std::size_t i = 0; i < nodes.size(); ++i)
    s << i + 1 << " " << nodes[i][0] << " " << nodes[i][1] << " " << nodes[i][2] << "\n";
  s << "$EndNodes\n$Elements\n" << elements.size() << "\n";
  for (std::size_t e = 0; e < elements.size(); ++e) {
    s << e + 1 << " " << elements[e].first << " 2 1 1";
    for (int n : elements[e].second) s << " " << n;
    s << "\n";
  }
  s << "$EndElements\n";
  return s.str();
}

/// The cube [0.2, 0.6]^3 in six tetrahedra about its diagonal (Kuhn's subdivision).
std::string kuhn_cube() {
  std::vector<std::array<double, 3>> nodes;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) nodes.push_back({0.2 + 0.4 * i, 0.2 + 0.4 * j, 0.2 + 0.4 * k});
  auto node = [](int i, int j, int k) { return 1 + i + 2 * j + 4 * k; };
  std::vector<std::pair<int, std::vector<int>>> tets;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms) {
    std::array<int, 3> c{0, 0, 0};
    std::vector<int> t{node(0, 0, 0)};
    for (int s = 0; s < 3; ++s) {
      c[static_cast<std::size_t>(p[s])] = 1;
      t.push_back(node(c[0], c[1], c[2]));
    }
    tets.push_back({4, t});
  }
  return msh(nodes, tets);
}

class VolumeMeshBodies : public test::ScratchTest {
 protected:
  Config load(int dim, const std::string& shape) const {
    write("case.toml", input(dim, shape));
    return load_config(path("case.toml"));
  }
  std::string error_of(int dim, const std::string& shape) const {
    return input_error([&] { load(dim, shape); });
  }
};

TEST_F(VolumeMeshBodies, TetrahedraGiveOneParticlePerElementOrPerGaussPoint) {
  write("cube.msh", kuhn_cube());
  for (int q : {1, 4}) {
    SCOPED_TRACE(q);
    const Config cfg = load(3, "file = \"cube.msh\", quadrature = " + std::to_string(q));
    Simulation<3> sim(cfg);
    const auto& p = sim.particles();
    ASSERT_EQ(p.n(), 6u * static_cast<std::size_t>(q));
    double volume = 0.0, mass = 0.0;
    Vec<3> moment = Vec<3>::Zero();
    for (std::size_t i = 0; i < p.n(); ++i) {
      EXPECT_NEAR(p.volume0[i], 0.064 / 6.0 / q, 1e-15);
      EXPECT_DOUBLE_EQ(p.mass[i], 2000.0 * p.volume0[i]);
      EXPECT_GT(p.position[i].minCoeff(), 0.2);
      EXPECT_LT(p.position[i].maxCoeff(), 0.6);
      volume += p.volume0[i];
      mass += p.mass[i];
      moment += p.volume0[i] * p.position[i];
    }
    EXPECT_NEAR(volume, 0.064, 1e-15);
    EXPECT_NEAR(mass, 2000.0 * 0.064, 1e-12);
    // The rules integrate linear fields exactly: the centre of volume is the cube's centre.
    EXPECT_NEAR((moment / volume - Vec<3>(0.4, 0.4, 0.4)).norm(), 0.0, 1e-14);
  }
}

TEST_F(VolumeMeshBodies, TrianglesTakeTheThicknessAndThreePointRule) {
  write("square.msh", msh({{0.2, 0.2, 0.0}, {0.8, 0.2, 0.0}, {0.8, 0.5, 0.0}, {0.2, 0.5, 0.0}},
                          {{1, {1, 2}}, {2, {1, 2, 3}}, {2, {1, 3, 4}}}));
  const Config cfg = load(2, "file = \"square.msh\", quadrature = 3, translate = [0.1, 0.2, 0.0]");
  Simulation<2> sim(cfg);
  const auto& p = sim.particles();
  ASSERT_EQ(p.n(), 6u);
  double area = 0.0;
  for (std::size_t i = 0; i < p.n(); ++i) {
    area += p.volume0[i];
    EXPECT_NEAR(p.volume0[i], 0.18 / 6.0 * 0.5, 1e-15);
    EXPECT_GT(p.position[i][0], 0.3);
    EXPECT_LT(p.position[i][0], 0.9);
    EXPECT_GT(p.position[i][1], 0.4);
    EXPECT_LT(p.position[i][1], 0.7);
  }
  EXPECT_NEAR(area, 0.18 * 0.5, 1e-15);
}

TEST_F(VolumeMeshBodies, GeoOutlineWithAHoleIsMeshedWhenRead) {
  write("plate.geo",
        "SetFactory(\"OpenCASCADE\");\n"
        "Rectangle(1) = {0.1, 0.1, 0, 0.8, 0.8};\n"
        "Disk(2) = {0.5, 0.5, 0, 0.2};\n"
        "BooleanDifference{ Surface{1}; Delete; }{ Surface{2}; Delete; }\n"
        "Mesh.MeshSizeMax = 0.05;\n");
  const Config cfg = load(2, "file = \"plate.geo\"");
  Simulation<2> sim(cfg);
  const auto& p = sim.particles();
  ASSERT_GT(p.n(), 100u);
  double area = 0.0;
  for (std::size_t i = 0; i < p.n(); ++i) {
    area += p.volume0[i] / 0.5;
    const double r = (p.position[i] - Vec<2>(0.5, 0.5)).norm();
    EXPECT_GT(r, 0.2 * std::cos(std::numbers::pi / 8.0)) << "a particle in the hole";
    EXPECT_GT(p.position[i].minCoeff(), 0.1);
    EXPECT_LT(p.position[i].maxCoeff(), 0.9);
  }
  // The plate minus the hole, the hole's boundary a polygon of chords h <= 0.05 inside the circle:
  // each chord cuts off a segment of about h^3 / (12 r), 2 pi r / h of them: 2 pi h^2 / 12 in all.
  const double exact = 0.64 - std::numbers::pi * 0.04;
  EXPECT_GE(area, exact);
  EXPECT_LE(area - exact, 2.0 * std::numbers::pi * 0.05 * 0.05 / 12.0);
}

TEST_F(VolumeMeshBodies, BadMeshesAreInputErrorsNamingTheFault) {
  write("cube.msh", kuhn_cube());
  auto expect = [&](int dim, const std::string& shape, const std::string& fault) {
    const std::string e = error_of(dim, shape);
    EXPECT_NE(e.find(fault), std::string::npos) << e;
    EXPECT_NE(e.find("body[0].shape.volume_mesh"), std::string::npos) << e;
  };
  expect(3, "file = \"cube.msh\", quadrature = 3", "quadrature = 3: 3D takes 1 or 4 points per element");
  expect(2, "file = \"cube.msh\"", "no 3-node triangles in it (0 triangles, 6 tetrahedra)");
  write("flat.msh", msh({{0.2, 0.2, 0.2}, {0.4, 0.2, 0.2}, {0.6, 0.2, 0.2}, {0.2, 0.4, 0.2}}, {{4, {1, 2, 3, 4}}}));
  expect(3, "file = \"flat.msh\"", "degenerate element 1 (Gmsh tag): zero volume");
  write("quads.msh", msh({{0.2, 0.2, 0.0}, {0.8, 0.2, 0.0}, {0.8, 0.5, 0.0}, {0.2, 0.5, 0.0}}, {{3, {1, 2, 3, 4}}}));
  expect(2, "file = \"quads.msh\"", "type 3 (Quadrilateral 4)");
  expect(2, "file = \"missing.msh\"", "no such file");
  write("bad.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0\n");
  expect(2, "file = \"bad.msh\"", "volume mesh");
  expect(2, "file = \"cube.msh\", rotate = [10.0, 0.0, 0.0]", "[0, 0, angle] in 2D");
}

}  // namespace
}  // namespace cairn
