// Transfers conserve mass and momentum to round-off; a rigid translation stays rigid; a free
// elastic body conserves linear momentum over many steps; results do not depend on the thread
// count (the guarantee documented in transfer/transfer.hpp).
#include <gtest/gtest.h>
#include <omp.h>

#include "../support/config_builder.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

template <int D>
void check_p2g_conservation(const std::string& shape) {
  Config cfg = test::box_config(D, shape);
  cfg.bodies[0].velocity.assign(D, "0");
  cfg.bodies[0].velocity[0] = "1 + X";
  Simulation<D> sim(cfg);
  sim.build_stencils();
  sim.particles_to_grid();
  double m = 0.0;
  Vec<D> p = Vec<D>::Zero(), f = Vec<D>::Zero();
  for (std::int32_t i = 0; i < sim.grid().n_nodes(); ++i) {
    m += sim.nodes().mass[i];
    p += sim.nodes().momentum[i];
    f += sim.nodes().force[i];
  }
  const Totals t = sim.totals();
  EXPECT_NEAR(m, t.mass, 1e-13 * t.mass) << shape;
  EXPECT_LT((to3<D>(p) - t.momentum).norm(), 1e-13 * t.momentum.norm()) << shape;
  EXPECT_LT(f.norm(), 1e-9) << shape;  // unstressed body
}

TEST(Conservation, ParticleToGridConservesMassAndMomentum) {
  for (std::string shape : {"linear", "ugimp", "bspline2", "bspline3"}) {
    check_p2g_conservation<1>(shape);
    check_p2g_conservation<2>(shape);
    check_p2g_conservation<3>(shape);
  }
}

template <int D>
void check_rigid_translation(const std::string& shape) {
  Config cfg = test::box_config(D, shape);
  cfg.bodies[0].velocity.assign(D, "0.3");
  Simulation<D> sim(cfg);
  const auto x0 = sim.particles().position;
  double t = 0.0;
  for (int s = 0; s < 40; ++s) {
    const double dt = sim.next_dt();
    sim.step(dt);
    t += dt;
  }
  for (std::size_t p = 0; p < x0.size(); ++p) {
    // Round-off only: the stress of an undeformed body is zero up to exp(L dt) of an L that is
    // itself round-off, so allow a few 1e-12 after 40 steps.
    EXPECT_LT((sim.particles().velocity[p] - Vec<D>::Constant(0.3)).norm(), 1e-11) << shape;
    EXPECT_LT((sim.particles().position[p] - x0[p] - Vec<D>::Constant(0.3 * t)).norm(), 1e-11) << shape;
    EXPECT_LT((sim.particles().deformation_gradient[p] - Mat3::Identity()).norm(), 1e-12) << shape;
  }
}

TEST(Conservation, RigidTranslationStaysRigid) {
  for (std::string shape : {"linear", "ugimp", "bspline2", "bspline3"}) {
    check_rigid_translation<1>(shape);
    check_rigid_translation<2>(shape);
    check_rigid_translation<3>(shape);
  }
}

TEST(Conservation, FreeBodyConservesLinearMomentum) {
  for (std::string shape : {"linear", "ugimp", "bspline2"}) {
    Config cfg = test::box_config(2, shape, "neo_hookean");
    // Spin, shear and drift, gentle enough that linear MPM's cell-crossing instability does not
    // set in within the 300 steps.
    cfg.bodies[0].velocity = {"0.2*(Y-0.5)", "-0.1*(X-0.5) + 0.01"};
    Simulation<2> sim(cfg);
    const Vec3 p0 = sim.totals().momentum;
    for (int s = 0; s < 300; ++s) sim.step(sim.next_dt());
    const Vec3 p1 = sim.totals().momentum;
    EXPECT_LT((p1 - p0).norm(), 1e-12 * sim.totals().mass) << shape;
  }
}

TEST(Conservation, ResultsAreBitIdenticalForAnyThreadCount) {
  Config cfg = test::box_config(2, "bspline2", "neo_hookean");
  cfg.bodies[0].velocity = {"3*(Y-0.5)", "-(X-0.5)"};
  std::vector<Particles<2>> results;
  for (int threads : {1, 2, 3}) {
    cfg.simulation.threads = threads;
    Simulation<2> sim(cfg);
    for (int s = 0; s < 50; ++s) sim.step(sim.next_dt());
    results.push_back(sim.particles());
  }
  omp_set_num_threads(omp_get_num_procs());
  for (std::size_t r = 1; r < results.size(); ++r) {
    for (std::size_t p = 0; p < results[0].n(); ++p) {
      ASSERT_EQ(results[r].position[p], results[0].position[p]);
      ASSERT_EQ(results[r].velocity[p], results[0].velocity[p]);
      ASSERT_EQ(results[r].kirchhoff_stress[p], results[0].kirchhoff_stress[p]);
    }
  }
}

}  // namespace
}  // namespace cairn
