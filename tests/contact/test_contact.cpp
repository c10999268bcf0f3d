// Multimaterial contact (contact/contact.hpp, contact/law.hpp; seed 004).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "../support/config_builder.hpp"
#include "cairn/contact/contact.hpp"
#include "cairn/contact/law.hpp"
#include "cairn/input/input.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

ContactInput approaching(double tangential) {
  ContactInput in;
  in.normal = Vec3(0.0, 1.0, 0.0);
  in.dp0 = Vec3(tangential, -2.0, 0.0);  // beta approaches alpha: dp0.n < 0
  in.reduced_mass = 0.5;
  in.area = 0.1;
  in.dt = 0.01;
  return in;
}

/// A law's configuration as [contact] would give it: law name, friction, dynamic_friction, slide.
ContactLawConfig law_config(const std::string& name, double friction, double dynamic, const std::string& slide) {
  ContactLawConfig c;
  c.law = name;
  c.plugin.set("friction", friction);
  c.plugin.set("dynamic_friction", dynamic);
  c.plugin.set("slide", slide);
  return c;
}

TEST(ContactLaws, FrictionlessKeepsOnlyTheNormalChange) {
  auto law = make_contact_law(law_config("frictionless", 0.0, -1.0, "0"), {});
  const Vec3 dp = law->momentum_change(approaching(1.5));
  EXPECT_DOUBLE_EQ(dp[0], 0.0);
  EXPECT_DOUBLE_EQ(dp[1], -2.0);
  EXPECT_FALSE(law->bonded());
}

TEST(ContactLaws, CoulombSticksBelowMuNAndSlidesAtMuDynamicNAbove) {
  // N_c A dt = -dp0.n = 2; stick needs |dp0_t| <= mu_s * 2.
  auto law = make_contact_law(law_config("coulomb", 0.5, 0.25, "0"), {});
  const Vec3 stick = law->momentum_change(approaching(0.9));
  EXPECT_DOUBLE_EQ(stick[0], 0.9);
  const Vec3 slide = law->momentum_change(approaching(1.5));
  EXPECT_NEAR(slide[0], 0.25 * 2.0, 1e-14);  // mu_d N A dt along t, t along +x (dp0.t > 0)
  EXPECT_DOUBLE_EQ(slide[1], -2.0);
  const Vec3 back = law->momentum_change(approaching(-1.5));
  EXPECT_NEAR(back[0], -0.5, 1e-14);  // t follows the tangential part of dp0
}

TEST(ContactLaws, GeneralLawWithMuNcMatchesCoulombAndIsCappedAtStick) {
  auto general = make_contact_law(law_config("general", 0.0, -1.0, "0.25*Nc"), {});
  auto coulomb = make_contact_law(law_config("coulomb", 0.25, -1.0, "0"), {});
  for (double t : {0.1, 0.4, 1.5, -3.0}) {
    const Vec3 a = general->momentum_change(approaching(t)), b = coulomb->momentum_change(approaching(t));
    EXPECT_NEAR((a - b).norm(), 0.0, 1e-13) << t;
  }
  // A slide expression using the slip speed: 10 * vslip with vslip = |dp0_t| / m_red.
  // vslip = 0.01 / 0.5 = 0.02: S = 0.2, S A dt = 2e-4 < 0.01 slides; 1e4 vslip would stick.
  auto viscous = make_contact_law(law_config("general", 0.0, -1.0, "10*vslip"), {});
  const ContactInput in = approaching(0.01);
  EXPECT_NEAR(viscous->momentum_change(in)[0], 2e-4, 1e-15);
  auto stiff = make_contact_law(law_config("general", 0.0, -1.0, "1e4*vslip"), {});
  EXPECT_NEAR(stiff->momentum_change(in)[0], 0.01, 1e-15);
  EXPECT_THROW(make_contact_law(law_config("general", 0.0, -1.0, "2*bogus"), {}), std::invalid_argument);
}

TEST(ContactLaws, PerfectIsBondedAndUnknownNamesAreListed) {
  auto perfect = make_contact_law(law_config("perfect", 0.0, -1.0, "0"), {});
  EXPECT_TRUE(perfect->bonded());
  try {
    (void)make_contact_law(law_config("glue", 0.0, -1.0, "0"), {});
    FAIL() << "no error";
  } catch (const UnknownName& e) {
    EXPECT_NE(std::string(e.what()).find("coulomb"), std::string::npos);
  }
}

/// Two boxes of two materials with identical properties side by side (x < 0.5 and x > 0.5).
Config split_block(const std::string& update, int order, const std::string& law) {
  Config c = test::box_config(2, "bspline2", "neo_hookean");
  c.method.update = update;
  c.method.order = order;
  c.simulation.cfl = 0.3;
  MaterialConfig second = c.materials[0];
  second.name = "mat2";
  c.materials.push_back(second);
  BodyConfig right = c.bodies[0];
  c.bodies[0].shape.max = {0.5, 0.7};
  c.bodies[0].velocity = {"0.3*sin(3*y)", "-0.2*x"};
  right.name = "right";
  right.material = law.empty() ? "mat" : "mat2";
  right.shape.min = {0.5, 0.3};
  right.velocity = c.bodies[0].velocity;
  c.bodies.push_back(right);
  if (!law.empty()) {
    c.contact.mode = "material";
    c.contact.law.law = law;
  }
  return c;
}

template <int D>
double max_stress_difference(const Simulation<D>& a, const Simulation<D>& b) {
  double worst = 0.0, scale = 0.0;
  for (std::size_t p = 0; p < a.particles().n(); ++p) {
    worst = std::max(worst, (a.particles().kirchhoff_stress[p].full() - b.particles().kirchhoff_stress[p].full()).norm());
    scale = std::max(scale, a.particles().kirchhoff_stress[p].full().norm());
  }
  return worst / scale;
}

TEST(Contact, PerfectInterfaceUnderFlipIsSingleMaterialToRoundOff) {
  // seed 004 Sec. 3.2: with two corrections per step and a^a = (v^a+ - v^a) / dt, a perfect
  // interface reverts to single-material MPM.
  Simulation<2> single(split_block("flip", 1, ""));
  Simulation<2> multi(split_block("flip", 1, "perfect"));
  ASSERT_NE(multi.contact(), nullptr);
  EXPECT_EQ(single.contact(), nullptr);
  for (int k = 0; k < 25; ++k) {
    const double dt = single.next_dt();
    single.step(dt);
    multi.step(dt);
  }
  EXPECT_GT(multi.contact()->contact_nodes(), 0u);
  EXPECT_LT(max_stress_difference(single, multi), 1e-11);
  for (std::size_t p = 0; p < single.particles().n(); ++p)
    ASSERT_LT((single.particles().velocity[p] - multi.particles().velocity[p]).norm(), 1e-12);
}

TEST(Contact, OnceCorrectionDoesNotRevertToSingleMaterial) {
  Config once = split_block("flip", 1, "perfect");
  once.contact.corrections = "once";
  Simulation<2> single(split_block("flip", 1, "")), multi(once);
  for (int k = 0; k < 25; ++k) {
    const double dt = single.next_dt();
    single.step(dt);
    multi.step(dt);
  }
  EXPECT_GT(max_stress_difference(single, multi), 1e-6);  // Sec. 4.1 "LR Once"
}

TEST(Contact, MultimaterialXpicWithTheDvTermStaysCloserToSingleMaterialThanWithout) {
  // seed 004 Eq. 45-48: corrected multimaterial XPIC(m) differs from single material by a term
  // in V - S v; the uncorrected one by a term in S v, which is larger.
  Simulation<2> single(split_block("xpic", 4, ""));
  Simulation<2> corrected(split_block("xpic", 4, "perfect"));
  Config u = split_block("xpic", 4, "perfect");
  u.contact.xpic_correction = false;
  Simulation<2> uncorrected(u);
  for (int k = 0; k < 25; ++k) {
    const double dt = single.next_dt();
    single.step(dt);
    corrected.step(dt);
    uncorrected.step(dt);
  }
  const double dc = max_stress_difference(single, corrected), du = max_stress_difference(single, uncorrected);
  EXPECT_LT(dc, 0.5 * du) << dc << " " << du;
}

TEST(Contact, FrictionlessImpactConservesMomentumAndRebounds) {
  // Two identical bars (nu = 0: every row is a 1D bar), x velocities 0.8 and -0.2 (total
  // momentum 0.6 M, not zero by symmetry), sliding along the frictionless interface at 0.1 and
  // -0.05. An elastic impact of identical bars exchanges the normal velocities (-0.2 and 0.8
  // after, +-0.5 about the centre of mass) and a frictionless one leaves the tangential ones.
  // MPM contact falls short of the full exchange by a discretization error: with LR detection and
  // LR normals the left bar ends at -0.102, -0.140, -0.155 for h = 0.05, 0.025, 0.0125 (1D:
  // -0.151, -0.165, -0.180 for h = 0.025, 0.0125, 0.00625), so at h = 0.025 the rebound must be
  // within 0.075 (15 % of the 0.5 exchanged about the centre of mass). The other detections
  // (velocity difference, CP, DF) detect early or late (seed 004 Sec. 2.3) and are held to the
  // momentum balance and to a rebound of at least half the ideal.
  for (const char* detection : {"lr", "velocity", "cp", "df"}) {
    Config c = test::box_config(2, "gimp", "neo_hookean");
    c.materials[0].numbers["poissons_ratio"] = 0.0;
    c.simulation.cfl = 0.3;
    c.grid.cell_size = {0.025, 0.025};  // 12 cells along each bar
    c.bodies[0].shape.min = {0.05, 0.3};
    c.bodies[0].shape.max = {0.35, 0.7};
    c.bodies[0].velocity = {"0.8", "0.1"};
    BodyConfig right = c.bodies[0];
    right.name = "right";
    right.shape.min = {0.55, 0.3};
    right.shape.max = {0.85, 0.7};
    right.velocity = {"-0.2", "-0.05"};
    c.bodies.push_back(right);
    c.contact.mode = "body";
    c.contact.detection = detection;
    c.contact.normal = "lr";
    Simulation<2> sim(c);
    Vec<2> initial = Vec<2>::Zero();
    double mass = 0.0;
    for (std::size_t p = 0; p < sim.particles().n(); ++p) {
      initial += sim.particles().mass[p] * sim.particles().velocity[p];
      mass += sim.particles().mass[p];
    }
    ASSERT_NEAR(initial[0], 0.3 * mass, 1e-12 * mass);
    bool touched = false;
    while (sim.time() < 0.3) {
      sim.step(sim.next_dt());
      touched = touched || sim.contact()->active_nodes() > 0;
      Vec<2> now = Vec<2>::Zero();
      for (std::size_t p = 0; p < sim.particles().n(); ++p) now += sim.particles().mass[p] * sim.particles().velocity[p];
      ASSERT_LT((now - initial).norm(), 1e-12 * initial.norm()) << detection << " t = " << sim.time();
      ASSERT_LT((sim.totals().momentum.head<2>() - now).norm(), 1e-10 * initial.norm()) << detection;
    }
    EXPECT_TRUE(touched) << detection;
    Vec<2> vl = Vec<2>::Zero(), vr = Vec<2>::Zero();
    double ml = 0.0, mr = 0.0;
    for (std::size_t p = 0; p < sim.particles().n(); ++p) {
      const double m = sim.particles().mass[p];
      (sim.particles().body[p] == 0 ? vl : vr) += m * sim.particles().velocity[p];
      (sim.particles().body[p] == 0 ? ml : mr) += m;
    }
    vl /= ml;
    vr /= mr;
    if (std::string(detection) == "lr") {
      EXPECT_NEAR(vl[0], -0.2, 0.075) << detection;
      EXPECT_NEAR(vr[0], 0.8, 0.075) << detection;
      EXPECT_NEAR(vl[1], 0.1, 0.025) << detection;
      EXPECT_NEAR(vr[1], -0.05, 0.025) << detection;
    } else {
      EXPECT_LT(vl[0], 0.3 - 0.25) << detection;  // centre of mass 0.3, ideal 0.3 -+ 0.5
      EXPECT_GT(vr[0], 0.3 + 0.25) << detection;
    }
  }
}

TEST(Contact, ReleaseBySeparationKeepsContactUntilTheFieldsSeparate) {
  // verification/rolling_cylinder's disk at R/h = 5 (radial rings, column separation), 30 ms: with
  // release = "gap" the column gap at a node in contact flickers open under the load and drops
  // it (docs/contact.md, "Detection"); with "separation" a node pair held in contact by a step's
  // second correction is never found with its gap open at the next step, and pairs still leave
  // contact when their fields separate (behind the rolling contact point).
  const std::string text = R"toml(
[simulation]
dimension = 2
mode = "plane_strain"
end_time = 0.03
[grid]
origin = [0.0, 0.0]
extent = [0.04, 0.036]
cell_size = 0.002
[method]
shape = "bspline2"
update = "flip"
stress_update = "usl"
[[material]]
name = "floor"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3
[[material]]
name = "disk"
model = "linear_elastic"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3
[[body]]
name = "floor"
material = "floor"
shape = { box = { min = [0.0, 0.0], max = [0.04, 0.008] } }
[[body]]
name = "disk"
material = "disk"
shape = { circle = { center = [0.015, 0.018], radius = 0.01 } }
arrangement = "radial"
[body_force]
expression = ["4.905*0.5*(1-cos(pi*min(t/0.02,1)))", "-8.4957*0.5*(1-cos(pi*min(t/0.02,1)))"]
[[velocity]]
name = "hold"
box_min = [0.0, 0.0]
box_max = [0.04, 0.004000000002]
direction = [0.0, 1.0]
velocity = 0.0
[[velocity]]
name = "hold_x"
box_min = [0.0, 0.0]
box_max = [0.04, 0.004000000002]
direction = [1.0, 0.0]
velocity = 0.0
[contact]
mode = "material"
law = "coulomb"
friction = 0.5
lr_separation = "column"
)toml";
  for (const char* release : {"gap", "separation"}) {
    Simulation<2> sim(load_config_string(text, "rolling_disk", {std::string("contact.release=") + release}));
    sim.contact()->trace(true);
    using State = Contact<2>::NodeTrace::State;
    std::set<std::tuple<std::int32_t, std::int32_t, std::int32_t>> held, held_now;
    int reopened = 0, released = 0;
    while (sim.time() < 0.03 - 1e-12) {
      sim.step(sim.next_dt());
      held_now.clear();
      for (const auto& e : sim.contact()->last_trace()) {
        const auto key = std::make_tuple(e.node, e.a, e.b);
        if (e.state == State::gap_open && held.count(key)) ++reopened;
        if (e.state == State::separating && held.count(key)) ++released;
        if (e.state == State::stick || e.state == State::slip) held_now.insert(key);
      }
      held.swap(held_now);
    }
    if (std::string(release) == "separation") EXPECT_EQ(reopened, 0);
    else EXPECT_GT(reopened, 0);
    EXPECT_GT(released, 0) << release;
  }
}

TEST(Contact, SingleFieldRunsKeepOneEntryPerNode) {
  Simulation<2> single(split_block("flip", 1, ""));
  EXPECT_EQ(single.nodes().mass.size(), static_cast<std::size_t>(single.grid().n_nodes()));
  Simulation<2> multi(split_block("flip", 1, "perfect"));
  EXPECT_EQ(multi.nodes().mass.size(), 2u * static_cast<std::size_t>(multi.grid().n_nodes()));
}

}  // namespace
}  // namespace cairn
