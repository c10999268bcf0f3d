// Time functions and tractions (seed 000 Sec. 2.4, first equation; Sec. 3.3): tri/ramp/table
// factors; face selection by side and box; the grid forces of a traction sum to T A for every
// shape family (partition of unity of the family's face average); the face area follows the
// deformation for the families that track their domain; a traction that selects nothing is an
// error; body forces may use the reference and the current position together.
#include <gtest/gtest.h>

#include <cmath>

#include "cairn/bc/time_function.hpp"
#include "cairn/bc/traction.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

TEST(TimeFunction, TriangleRampTableAndTheirProduct) {
  TimeFunction tri("tri(t, 2)", {}, {}, "test");
  EXPECT_EQ(tri(-0.1), 0.0);
  EXPECT_DOUBLE_EQ(tri(0.5), 0.5);
  EXPECT_DOUBLE_EQ(tri(1.0), 1.0);  // peak 1 at t = w / 2 (seed 000 Sec. 3.3)
  EXPECT_DOUBLE_EQ(tri(1.5), 0.5);
  EXPECT_EQ(tri(2.0), 0.0);
  EXPECT_EQ(tri(3.0), 0.0);
  TimeFunction ramp("A*ramp(t, 4)", {}, {{"A", 3.0}}, "test");
  EXPECT_EQ(ramp(-1.0), 0.0);
  EXPECT_DOUBLE_EQ(ramp(1.0), 0.75);
  EXPECT_DOUBLE_EQ(ramp(9.0), 3.0);
  TimeFunction table("2", {{0.0, 0.0}, {1.0, 10.0}, {3.0, 0.0}}, {}, "test");
  EXPECT_DOUBLE_EQ(table(-1.0), 0.0);   // constant before the first point
  EXPECT_DOUBLE_EQ(table(0.5), 10.0);   // 2 * 5
  EXPECT_DOUBLE_EQ(table(2.0), 10.0);   // 2 * 5
  EXPECT_DOUBLE_EQ(table(7.0), 0.0);    // constant after the last point
  EXPECT_TRUE(TimeFunction("1.5", {}, {}, "c").is_constant());
  EXPECT_FALSE(TimeFunction("t", {}, {}, "c").is_constant());
}

TEST(TimeFunction, RejectsPositionsBadSyntaxAndUnorderedTables) {
  EXPECT_THROW(TimeFunction("x + t", {}, {}, "load"), std::invalid_argument);
  EXPECT_THROW(TimeFunction("X", {}, {}, "load"), std::invalid_argument);
  EXPECT_THROW(TimeFunction("tri(t", {}, {}, "load"), std::invalid_argument);
  EXPECT_THROW(TimeFunction("1", {{1.0, 0.0}, {1.0, 2.0}}, {}, "load"), std::invalid_argument);
}

/// A bar [0, 0.04] x [0, 0.01] (by [0, 0.006] along z in 3D) on 2 mm cells, 2 x 2 particles per cell, with one
/// [[traction]] table appended by the caller.
std::string bar_input(const std::string& shape, const std::string& traction, int dimension = 2) {
  std::string grid, body, mode;
  if (dimension == 1) {
    grid = "origin = [-0.01]\nextent = [0.06]\ncell_size = 0.002\n";
    body = "shape = { box = { min = [0.0], max = [0.04] } }\n";
  } else if (dimension == 2) {
    grid = "origin = [-0.01, -0.01]\nextent = [0.06, 0.03]\ncell_size = 0.002\n";
    body = "shape = { box = { min = [0.0, 0.0], max = [0.04, 0.01] } }\n";
  } else {
    grid = "origin = [-0.01, -0.01, -0.01]\nextent = [0.06, 0.03, 0.03]\ncell_size = 0.002\n";
    body = "shape = { box = { min = [0.0, 0.0, 0.0], max = [0.04, 0.01, 0.006] } }\n";
  }
  return "[simulation]\ndimension = " + std::to_string(dimension) +
         "\nend_time = 1e-3\nthickness = 0.5\n[grid]\n" + grid + "[method]\nshape = \"" + shape +
         "\"\n[[material]]\nname = \"m\"\nmodel = \"linear_elastic\"\ndensity = 1000.0\n"
         "youngs_modulus = 1e7\npoissons_ratio = 0.0\n[[body]]\nname = \"bar\"\nmaterial = \"m\"\n" +
         body + "particles_per_cell = 2\n" + traction;
}

template <int D>
Vec<D> traction_force_sum(Simulation<D>& sim) {
  sim.build_stencils();
  sim.particles_to_grid(true, true);  // no stress, no body force: f is the traction alone
  Vec<D> sum = Vec<D>::Zero();
  for (const auto& f : sim.nodes().force) sum += f;
  return sum;
}

TEST(Tractions, GridForcesSumToTractionTimesAreaForEveryFamily) {
  const std::string load =
      "[[traction]]\nbody = \"bar\"\nside = \"x_min\"\ntraction = [-3.0, 2.0]\nscale = \"0.5\"\n";
  for (const std::string shape : {"linear", "ugimp", "gimp", "cpgimp", "cpdi", "bspline2", "b2gimp",
                                   "b2cpdi", "bspline3", "bspline2_open", "bspline3_open"}) {
    Simulation<2> sim(load_config_string(bar_input(shape, load), "bar.toml"));
    ASSERT_EQ(sim.tractions().n_faces(0), 10u) << shape;  // 5 cells x 2 particles along y
    const Vec<2> sum = traction_force_sum(sim);
    const double area = 0.01 * 0.5;  // face length x thickness
    EXPECT_NEAR(sum[0], -1.5 * area, 1e-14) << shape;
    EXPECT_NEAR(sum[1], 1.0 * area, 1e-14) << shape;
    EXPECT_NEAR((sim.tractions().total_force(0) - sum).norm(), 0.0, 1e-14) << shape;
  }
}

TEST(Tractions, OneAndThreeDimensions) {
  {
    Simulation<1> sim(load_config_string(
        bar_input("bspline2", "[[traction]]\nside = \"x_max\"\ntraction = [4.0]\n", 1), "bar.toml"));
    EXPECT_EQ(sim.tractions().n_faces(0), 1u);
    EXPECT_NEAR(traction_force_sum(sim)[0], 4.0 * 0.5, 1e-14);  // times the cross-section
  }
  {
    Simulation<3> sim(load_config_string(
        bar_input("cpdi", "[[traction]]\nside = \"z_max\"\ntraction = [0.0, 0.0, 2.0]\n", 3), "bar.toml"));
    EXPECT_EQ(sim.tractions().n_faces(0), 20u * 5u * 4u);
    EXPECT_NEAR(traction_force_sum(sim)[2], 2.0 * 0.04 * 0.01, 1e-14);
  }
}

TEST(Tractions, SelectionBySideBoxAndEveryExposedFace) {
  auto faces = [](const std::string& load) {
    Simulation<2> sim(load_config_string(bar_input("linear", load), "bar.toml"));
    return sim.tractions().n_faces(0);
  };
  EXPECT_EQ(faces("[[traction]]\nside = \"y_max\"\ntraction = [0.0, 1.0]\n"), 40u);
  // Every exposed face in the box around the right end: 10 x_max faces, and the y faces of the
  // particles whose face centres lie in the box (x = 35.5 ... 39.5 mm: 5 columns, top and bottom).
  EXPECT_EQ(faces("[[traction]]\nbox_min = [0.035, -1.0]\nbox_max = [0.05, 1.0]\ntraction = [1.0, 0.0]\n"),
            10u + 2u * 5u);
  EXPECT_EQ(faces("[[traction]]\nside = \"x_max\"\nbox_min = [0.0, 0.0]\nbox_max = [1.0, 0.005]\n"
                  "traction = [1.0, 0.0]\n"),
            5u);
  EXPECT_THROW(faces("[[traction]]\nside = \"x_max\"\nbox_min = [0.0, 0.0]\nbox_max = [0.01, 0.01]\n"
                     "traction = [1.0, 0.0]\n"),
               InputError);  // selects no face: file, line, key, expected, found
}

TEST(Tractions, FaceAreaFollowsTheDeformationWhereTheFamilyTracksIt) {
  const std::string load = "[[traction]]\nside = \"x_min\"\ntraction = [1.0, 0.0]\n";
  for (const std::string shape : {"cpdi", "b2cpdi", "cpgimp", "gimp", "bspline2"}) {
    Simulation<2> sim(load_config_string(bar_input(shape, load), "bar.toml"));
    for (auto& F : sim.particles().deformation_gradient) F(1, 1) = 1.5;  // stretch along the face
    const bool tracks = shape == "cpdi" || shape == "b2cpdi" || shape == "cpgimp";
    EXPECT_NEAR(traction_force_sum(sim)[0], (tracks ? 1.5 : 1.0) * 0.01 * 0.5, 1e-14) << shape;
  }
  auto domain = [](const std::string& name) {
    MethodConfig method;
    method.shape = name;
    return make_shape_family<2>(ShapeContext{method, 2})->particle_domain();
  };
  EXPECT_EQ(domain("cpdi"), ParticleDomain::convected);
  EXPECT_EQ(domain("b2cpdi"), ParticleDomain::convected);
  EXPECT_EQ(domain("cpgimp"), ParticleDomain::stretched);
  EXPECT_EQ(domain("bspline2"), ParticleDomain::undeformed);
  EXPECT_EQ(domain("gimp"), ParticleDomain::undeformed);
}

TEST(Tractions, FollowTheTimeFunctionAtTheMiddleOfTheStepAndDoWork) {
  const std::string load =
      "[[traction]]\nside = \"x_max\"\ntraction = [10.0, 0.0]\nscale = \"t\"\n"
      "table = [[0.0, 1.0], [1.0, 3.0]]\n";
  Simulation<2> sim(load_config_string(bar_input("bspline2", load), "bar.toml"));
  const double dt = 1e-6;
  sim.step(dt);
  const double t_mid = 0.5 * dt;
  EXPECT_NEAR(sim.tractions().total_force(0)[0], 10.0 * t_mid * (1.0 + 2.0 * t_mid) * 0.005, 1e-18);
  for (int i = 0; i < 20; ++i) sim.step(dt);
  EXPECT_GT(sim.external_work(), 0.0);  // a pull on the free end does positive work
}

TEST(BodyForce, ExpressionOfReferenceAndCurrentPosition) {
  // Manufactured body force b = 10 (x - X): a body shifted by u = 0.001 feels b = 0.01 everywhere,
  // so one FLIP step from rest gives every particle V = 0.01 dt.
  const std::string input = bar_input("bspline2", "") +
                            "[body_force]\nexpression = [\"10*(x - X)\", \"5*(y - Y) + 0*X\"]\n";
  Config c = load_config_string(input, "bar.toml");
  c.bodies[0].displacement = {"0.001", "0.002"};
  Simulation<2> sim(c);
  const double dt = 1e-6;
  sim.step(dt);
  for (std::size_t p = 0; p < sim.particles().n(); ++p) {
    EXPECT_NEAR(sim.particles().velocity[p][0], 0.01 * dt, 1e-20) << p;
    EXPECT_NEAR(sim.particles().velocity[p][1], 0.01 * dt, 1e-20) << p;
  }
}

}  // namespace
}  // namespace cairn
