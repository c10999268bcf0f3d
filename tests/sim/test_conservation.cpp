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
::testing::AssertionResult p2g_conserves(const std::string& shape) {
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
  const double dm = std::abs(m - t.mass) / t.mass;
  const double dp = (to3<D>(p) - t.momentum).norm() / t.momentum.norm();
  if (dm <= 1e-13 && dp <= 1e-13 && f.norm() <= 1e-9)  // f: an unstressed body
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << shape << " D=" << D << ": mass error " << dm
                                       << ", momentum error " << dp << ", |sum f| " << f.norm();
}

TEST(Conservation, ParticleToGridConservesMassAndMomentum) {
  for (std::string shape : {"linear", "ugimp", "bspline2", "bspline3"}) {
    EXPECT_TRUE(p2g_conserves<1>(shape));
    EXPECT_TRUE(p2g_conserves<2>(shape));
    EXPECT_TRUE(p2g_conserves<3>(shape));
  }
}

template <int D>
::testing::AssertionResult stays_rigid(const std::string& shape) {
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
  // Round-off only: the stress of an undeformed body is zero up to exp(L dt) of an L that is
  // itself round-off, so allow a few 1e-12 after 40 steps.
  double dv = 0.0, dx = 0.0, dF = 0.0;
  for (std::size_t p = 0; p < x0.size(); ++p) {
    dv = std::max(dv, (sim.particles().velocity[p] - Vec<D>::Constant(0.3)).norm());
    dx = std::max(dx, (sim.particles().position[p] - x0[p] - Vec<D>::Constant(0.3 * t)).norm());
    dF = std::max(dF, (sim.particles().deformation_gradient[p] - Mat3::Identity()).norm());
  }
  if (!x0.empty() && dv < 1e-11 && dx < 1e-11 && dF < 1e-12) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << shape << " D=" << D << ": max |dV| " << dv << ", |dx| " << dx
                                       << ", |F - I| " << dF << " over " << x0.size() << " particles";
}

TEST(Conservation, RigidTranslationStaysRigid) {
  for (std::string shape : {"linear", "ugimp", "bspline2", "bspline3"}) {
    EXPECT_TRUE(stays_rigid<1>(shape));
    EXPECT_TRUE(stays_rigid<2>(shape));
    EXPECT_TRUE(stays_rigid<3>(shape));
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
