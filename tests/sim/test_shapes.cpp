// Body shapes whose meaning depends on the dimension.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

const std::string hollow_ball = R"toml([simulation]
dimension = 3
end_time = 1.0e-3

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
name = "shell"
material = "m"
shape = { annulus = { center = [0.5, 0.5, 0.5], inner_radius = 0.2, outer_radius = 0.4 } }
particles_per_cell = 2
)toml";

TEST(Shapes, AnAnnulusIn3DIsTheHollowBallBetweenItsTwoSpheres) {
  // Read from an input (the loader accepts it in 3D) and filled with the lattice and with the
  // radial arrangement: every particle lies between the spheres, and the volumes add up to the
  // shell's (the lattice's to its staircase error, the radial arrangement's exactly).
  const double exact = 4.0 / 3.0 * std::numbers::pi * (0.4 * 0.4 * 0.4 - 0.2 * 0.2 * 0.2);
  for (const char* arrangement : {"cartesian", "radial"}) {
    const Config cfg = load_config_string(hollow_ball, "hollow_ball.toml",
                                          {std::string("body[0].arrangement=\"") + arrangement + "\""});
    const Simulation<3> sim(cfg);
    const auto& P = sim.particles();
    ASSERT_GT(P.n(), 1000u) << arrangement;
    double volume = 0.0;
    for (std::size_t p = 0; p < P.n(); ++p) {
      const double r = (P.position[p] - Vec<3>::Constant(0.5)).norm();
      EXPECT_GE(r, 0.2) << arrangement;
      EXPECT_LE(r, 0.4) << arrangement;
      volume += P.volume0[p];
    }
    EXPECT_NEAR(volume, exact, (arrangement == std::string("radial") ? 1e-12 : 0.02) * exact) << arrangement;
  }
}

}  // namespace
}  // namespace cairn
