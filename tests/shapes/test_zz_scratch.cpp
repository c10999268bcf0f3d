#include <gtest/gtest.h>
#include "../support/config_builder.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/io/input.hpp"
namespace cairn {
TEST(Scratch, Linear) {
  Config cfg = test::box_config(2, "linear", "neo_hookean");
  cfg.grid.cell_size.assign(2, 1.0 / 40);
  cfg.bodies[0].shape.min = {0.0, 0.0};
  cfg.bodies[0].shape.max = {0.9, 0.9};
  cfg.bodies[0].velocity = {"3*(Y-0.5)", "-2*(X-0.5)"};
  cfg.boundary.face[0] = FaceCondition::symmetry;
  cfg.boundary.face[2] = FaceCondition::fixed;
  cfg.simulation.threads = 1;
  std::cout << config_to_toml(cfg) << std::endl;
  Simulation<2> sim(cfg);
  for (int s = 0; s < 6; ++s) {
    double dt = sim.next_dt();
    std::cout << "step " << s << " dt " << dt << " n " << sim.particles().n() << std::endl;
    sim.step(dt);
  }
}
}
