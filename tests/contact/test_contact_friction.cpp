// Contact accuracy for friction (issue 17; docs/contact.md "Flat interfaces", "Chatter"): the
// first correction's impulse on the particles and velocity conditions at contact nodes.
#include <gtest/gtest.h>

#include <cmath>

#include "../support/config_builder.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

/// Two blocks of one material (body mode) moving toward each other along x at +-0.5.
Config approaching_blocks(const std::string& first_correction) {
  Config c = test::box_config(2, "gimp", "neo_hookean");
  c.simulation.cfl = 0.3;
  c.bodies[0].shape.min = {0.1, 0.3};
  c.bodies[0].shape.max = {0.45, 0.7};
  c.bodies[0].velocity = {"0.5", "0.0"};
  BodyConfig right = c.bodies[0];
  right.name = "right";
  right.shape.min = {0.55, 0.3};
  right.shape.max = {0.9, 0.7};
  right.velocity = {"-0.5", "0.0"};
  c.bodies.push_back(right);
  c.contact.mode = "body";
  c.contact.law.law = "coulomb";
  c.contact.law.friction = 0.4;
  c.contact.first_correction = first_correction;
  return c;
}

/// Mean x velocity of the particles within `band` of the interface plane x = 0.5, per body.
double interface_velocity_jump(const Simulation<2>& sim, double band) {
  double v[2] = {0.0, 0.0}, m[2] = {0.0, 0.0};
  for (std::size_t p = 0; p < sim.particles().n(); ++p) {
    if (std::abs(sim.particles().position[p][0] - 0.5) > band) continue;
    const int b = sim.particles().body[p];
    v[b] += sim.particles().mass[p] * sim.particles().velocity[p][0];
    m[b] += sim.particles().mass[p];
  }
  return v[0] / m[0] - v[1] / m[1];
}

TEST(ContactImpulse, ParticlesTakeTheFirstCorrectionOfAContact) {
  // seed 004 Eq. 34 (a = a^a,1) keeps the first correction off the particles: under FLIP the
  // particles next to the interface go on approaching each other in their own velocities while
  // the grid has stopped them, until stress waves slow them down. With first_correction =
  // "impulse" the particles take the change and their velocities obey the contact at once.
  double jump[2] = {0.0, 0.0};
  int k = 0;
  for (const char* mode : {"impulse", "extrapolation"}) {
    Simulation<2> sim(approaching_blocks(mode));
    int steps_in_contact = 0;
    while (steps_in_contact < 3 && sim.time() < 0.2) {
      sim.step(sim.next_dt());
      if (sim.contact()->active_nodes() > 0) ++steps_in_contact;
    }
    ASSERT_EQ(steps_in_contact, 3) << mode;
    jump[k++] = interface_velocity_jump(sim, 0.1);
  }
  EXPECT_GT(jump[1], 0.5);            // extrapolation: the approach is still in the particles
  EXPECT_LT(jump[0], 0.25 * jump[1]);  // impulse: most of it is gone
}

TEST(ContactImpulse, BondedInterfacesAreUnchanged) {
  // A perfect interface under FLIP reverts to single material with either setting (the bonded
  // change is part of the extrapolation, seed 004 Eq. 34).
  for (const char* mode : {"impulse", "extrapolation"}) {
    Config a = approaching_blocks(mode), b = approaching_blocks(mode);
    a.contact.law.law = "perfect";
    b.contact.law.law = "perfect";
    b.contact.first_correction = std::string(mode) == "impulse" ? "extrapolation" : "impulse";
    Simulation<2> sa(a), sb(b);
    for (int s = 0; s < 40; ++s) {
      const double dt = sa.next_dt();
      sa.step(dt);
      sb.step(dt);
    }
    for (std::size_t p = 0; p < sa.particles().n(); ++p)
      ASSERT_EQ((sa.particles().velocity[p] - sb.particles().velocity[p]).norm(), 0.0);
  }
}

TEST(ContactImpulse, HeldContactNodeKeepsItsConditionUnderMultimaterialXpic) {
  // seed 004 Eq. 37: the dv term of multimaterial XPIC is subtracted after the full-mass
  // expansion imposed the velocity conditions; a node that is held and a contact node must still
  // hold its prescribed value afterwards.
  for (const char* law : {"perfect", "coulomb"}) {
    Config c = approaching_blocks("impulse");
    c.contact.law.law = law;
    c.method.update = "xpic";
    c.method.order = 4;
    c.bodies[0].velocity = {"0.5", "0.3*sin(5*y)"};
    c.bodies[1].velocity = {"-0.5", "-0.2*x"};
    VelocityConditionConfig hold;
    hold.name = "line";
    hold.plane_axis = 1;
    hold.plane_at = 0.5;
    hold.direction = {0.0, 1.0};
    c.velocity_conditions.push_back(hold);
    Simulation<2> sim(c);
    const auto& grid = sim.grid();
    int checked = 0;
    while (sim.time() < 0.25) {
      sim.step(sim.next_dt());
      if (sim.contact()->active_nodes() == 0) continue;
      for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
        if (std::abs(grid.node_position(i)[1] - 0.5) > 1e-9) continue;
        for (int f = 0; f < 2; ++f) {
          const std::size_t s = static_cast<std::size_t>(f * grid.n_nodes() + i);
          if (!(sim.nodes().mass[s] > 0.0)) continue;
          ASSERT_NEAR(sim.nodes().velocity_full[s][1], 0.0, 1e-12) << law << " node " << i << " field " << f;
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 0) << law;
  }
}

}  // namespace
}  // namespace cairn
