// Every shape family reports a colouring reach that makes the particle-to-grid scatter race-free:
// a sheared, spinning block on a grid wide enough for several colour blocks per axis gives
// bit-identical particles for 1, 2 and 4 threads. CPDI domains deform (and grow their stencils)
// during the run; symmetry faces exercise the ghost mirrors, fixed faces the open-knot face values.
#include <gtest/gtest.h>
#include <omp.h>

#include "../support/config_builder.hpp"
#include "cairn/sim/names.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

TEST(ShapeFamiliesInParallel, EveryFamilyIsBitIdenticalForAnyThreadCount) {
  for (const auto& name : shape_family_names()) {
    Config cfg = test::box_config(2, name, "neo_hookean");
    cfg.grid.cell_size.assign(2, 1.0 / 40);  // 40 x 40 cells: several colour blocks per axis
    cfg.bodies[0].shape.min = {0.0, 0.0};  // touches the x_min and y_min faces
    cfg.bodies[0].shape.max = {0.9, 0.9};
    cfg.bodies[0].velocity = {"3*(Y-0.5)", "-2*(X-0.5)"};
    cfg.boundary.face[0] = FaceCondition::symmetry;
    cfg.boundary.face[2] = FaceCondition::fixed;
    std::vector<Particles<2>> results;
    for (int threads : {1, 2, 4}) {
      cfg.simulation.threads = threads;
      Simulation<2> sim(cfg);
      try {
        for (int s = 0; s < 6; ++s) sim.step(sim.next_dt());
      } catch (const std::exception& e) {
        FAIL() << name << " with " << threads << " threads: " << e.what();
      }
      results.push_back(sim.particles());
    }
    for (std::size_t r = 1; r < results.size(); ++r)
      for (std::size_t p = 0; p < results[0].n(); ++p) {
        ASSERT_EQ(results[r].position[p], results[0].position[p]) << name;
        ASSERT_EQ(results[r].velocity[p], results[0].velocity[p]) << name;
        ASSERT_EQ(results[r].kirchhoff_stress[p], results[0].kirchhoff_stress[p]) << name;
      }
  }
  omp_set_num_threads(omp_get_num_procs());
}

}  // namespace
}  // namespace cairn
