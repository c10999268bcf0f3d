// Particle order (docs/architecture.md): a serial run of sort_min_particles or more keeps its
// particles in memory in cell-block order and sorts them again as they move out of it. Its
// results are bit-identical to a run that keeps creation order (every particle compared by id),
// for a list family (CPDI) and a tensor family (bspline2), with two contacting bodies and a
// traction; a failure names the particle by id; output lists particles in id order; a restart
// continues bit-identically.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../support/fresh_dir.hpp"
#include "cairn/io/checkpoint.hpp"
#include "cairn/io/hdf5_util.hpp"
#include "cairn/input/input.hpp"
#include "cairn/parallel/particle_transfer.hpp"
#include "cairn/run/engine.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/util/failure.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

// Two soft blocks spinning fast (about 0.3 cells per step at their corners), so that particles
// change cell blocks within the run and the order is restored more than once; the right block
// pulled by a traction on its x_max faces; 2 x 20 000 particles.
const char* input = R"toml(
[simulation]
dimension = 2
end_time = 1.0
max_steps = 30
cfl = 0.4
[grid]
origin = [0.0, 0.0]
extent = [1.0, 1.0]
cell_size = 0.005
[method]
shape = "cpdi"
[[material]]
name = "soft"
model = "neo_hookean"
density = 1000.0
youngs_modulus = 1.0e4
poissons_ratio = 0.3
[[body]]
name = "left"
material = "soft"
shape = { box = { min = [0.2, 0.25], max = [0.45, 0.75] } }
velocity = ["8*(Y-0.5)", "-8*(X-0.325)"]
[[body]]
name = "right"
material = "soft"
shape = { box = { min = [0.455, 0.25], max = [0.705, 0.75] } }
velocity = ["-8*(Y-0.5)", "8*(X-0.58)"]
[[traction]]
body = "right"
side = "x_max"
traction = [100.0, 0.0]
[contact]
mode = "body"
law = "coulomb"
friction = 0.2
[output]
snapshots = false
checkpoints = false
)toml";

/// Particle state keyed by id.
struct State {
  Vec<2> x, v;
  Mat3 F;
  SymMat3 tau;
};
std::map<std::int64_t, State> by_id(const Particles<2>& p) {
  std::map<std::int64_t, State> out;
  for (std::size_t k = 0; k < p.n(); ++k)
    out[p.id[k]] = {p.position[k], p.velocity[k], p.deformation_gradient[k], p.kirchhoff_stress[k]};
  return out;
}

void expect_same(const std::map<std::int64_t, State>& a, const std::map<std::int64_t, State>& b,
                 const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (const auto& [id, s] : a) {
    const State& t = b.at(id);
    ASSERT_EQ(s.x, t.x) << what << ", particle " << id;
    ASSERT_EQ(s.v, t.v) << what << ", particle " << id;
    ASSERT_EQ(s.F, t.F) << what << ", particle " << id;
    ASSERT_EQ(s.tau, t.tau) << what << ", particle " << id;
  }
}

// The in-place permutation moves every array (state with several values per particle too) as
// the copying reorder does.
TEST(ParticleOrder, InPlacePermutationMatchesTheCopyingReorder) {
  Particles<2> a;
  a.n_state_per_particle = 3;
  a.has_affine = true;
  for (int k = 0; k < 500; ++k) {
    a.add(Vec<2>(k, -k), Vec<2>(2.0 * k, 1.0), 1.0 + k, 2.0 + k, Vec<2>(0.5, 0.25), k % 3, k % 2);
    a.deformation_gradient.back()(0, 1) = k;
  }
  a.affine_velocity.assign(a.n(), Mat3::Zero());
  for (std::size_t k = 0; k < a.n(); ++k) a.affine_velocity[k](2, 2) = static_cast<double>(k);
  a.state.resize(3 * a.n());
  std::iota(a.state.begin(), a.state.end(), 0.0);
  std::vector<std::int32_t> order(a.n());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  Particles<2> b = a;
  reorder_particles(a, order);
  permute_particles(b, order);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.velocity, b.velocity);
  EXPECT_EQ(a.mass, b.mass);
  EXPECT_EQ(a.volume0, b.volume0);
  EXPECT_EQ(a.deformation_gradient, b.deformation_gradient);
  EXPECT_EQ(a.affine_velocity, b.affine_velocity);
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.body, b.body);
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.state, b.state);
  for (std::size_t k = 0; k < a.n(); ++k) ASSERT_EQ(b.id[k], order[k]);
}

TEST(ParticleOrder, SortedRunsAreBitIdenticalToCreationOrder) {
  for (const std::string shape : {"cpdi", "bspline2"}) {
    std::map<std::int64_t, State> result[2];
    for (const bool sort : {false, true}) {
      const Config cfg = load_config_string(input, "order.toml",
                                            {"method.shape=\"" + shape + "\"",
                                             std::string("simulation.sort_particles=") + (sort ? "true" : "false")});
      Simulation<2> sim(cfg);
      ASSERT_GE(sim.particles().n(), Simulation<2>::sort_min_particles);
      for (int s = 0; s < 30; ++s) sim.step(sim.next_dt());
      if (sort) {
        // Sorted at the set-up and again during the run; storage order is no longer id order.
        EXPECT_GE(sim.particle_sorts(), 2) << shape;
        EXPECT_EQ(sim.output_order().size(), sim.particles().n());
        bool moved = false;
        for (std::size_t k = 0; k < sim.particles().n() && !moved; ++k) moved = sim.particles().id[k] != std::int64_t(k);
        EXPECT_TRUE(moved) << shape;
      } else {
        EXPECT_EQ(sim.particle_sorts(), 0);
        EXPECT_TRUE(sim.output_order().empty());
      }
      result[sort] = by_id(sim.particles());
    }
    expect_same(result[0], result[1], shape);
  }
}

TEST(ParticleOrder, SortedWlsRunsAreBitIdenticalToCreationOrder) {
  // The WLS engine (seed 001) colours its particles in its own cache; sorted by that colouring it
  // must add every node's particles in the same order as a run in creation order. The blocks as
  // above without contact (WLS bodies in contact keep their storage order), the traction on, 2 x 20 000 particles.
  std::string wls_input = input;
  wls_input = wls_input.substr(0, wls_input.find("[contact]")) + wls_input.substr(wls_input.find("[output]"));
  std::map<std::int64_t, State> result[2];
  for (const bool sort : {false, true}) {
    const Config cfg = load_config_string(wls_input, "order.toml",
                                          {"method.integration=\"wls\"", "method.shape=\"bspline2\"",
                                           std::string("simulation.sort_particles=") + (sort ? "true" : "false")});
    Simulation<2> sim(cfg);
    ASSERT_GE(sim.particles().n(), Simulation<2>::sort_min_particles_wls);
    for (int s = 0; s < 30; ++s) sim.step(sim.next_dt());
    EXPECT_EQ(sim.particle_sorts() >= 2, sort);
    result[sort] = by_id(sim.particles());
  }
  expect_same(result[0], result[1], "wls");
}

TEST(ParticleOrder, SmallRunsKeepCreationOrder) {
  const Config cfg = load_config_string(input, "order.toml", {"grid.cell_size=0.02"});
  Simulation<2> sim(cfg);
  ASSERT_LT(sim.particles().n(), Simulation<2>::sort_min_particles);
  for (int s = 0; s < 3; ++s) sim.step(sim.next_dt());
  EXPECT_EQ(sim.particle_sorts(), 0);
  for (std::size_t k = 0; k < sim.particles().n(); ++k) ASSERT_EQ(sim.particles().id[k], std::int64_t(k));
}

TEST(ParticleOrder, AFailureNamesTheParticleById) {
  // A third body of one particle flies out of the grid: both runs name it by its id (the last
  // one created), though the sorted run stores it first (its cell block is the first).
  const std::string flyer =
      "[[body]]\nname = \"flyer\"\nmaterial = \"soft\"\n"
      "shape = { box = { min = [0.05, 0.05], max = [0.055, 0.055] } }\nparticles_per_cell = 1\n"
      "velocity = [-400.0, 0.0]\n";
  std::string message[2];
  for (const bool sort : {false, true}) {
    const Config cfg = load_config_string(std::string(input) + flyer, "order.toml",
                                          {std::string("simulation.sort_particles=") + (sort ? "true" : "false"),
                                           "contact.mode=\"none\""});
    Simulation<2> sim(cfg);
    const std::int64_t last = static_cast<std::int64_t>(sim.particles().n()) - 1;
    if (sort) {
      EXPECT_EQ(sim.particles().id[0], last);
    }
    try {
      for (int s = 0; s < 200; ++s) sim.step(sim.next_dt());
      FAIL() << "the flyer should leave the grid";
    } catch (const SimulationFailure& f) {
      EXPECT_EQ(f.particle(), last);
      message[sort] = f.what();
    }
  }
  EXPECT_NE(message[1].find("particle "), std::string::npos) << message[1];
  EXPECT_EQ(message[0], message[1]);
}

TEST(ParticleOrder, OutputListsParticlesInIdOrderAndRestartsAreBitIdentical) {
  // The same run sorted and unsorted writes the same snapshots; the sorted run restarted from
  // its mid-way checkpoint ends where it ends.
  const std::vector<std::string> common = {"simulation.max_steps=0", "simulation.end_time=3.6e-3",
                                           "method.shape=\"bspline2\"", "output.snapshots=true",
                                           "output.every=1.2e-3", "output.checkpoints=true",
                                           "output.checkpoint_every=1.8e-3"};
  RunOptions quiet{true};
  fs::path dir[2];
  RunSummary summary[2];
  for (const bool sort : {false, true}) {
    dir[sort] = test::fresh_dir(sort ? "order_sorted" : "order_unsorted");
    std::vector<std::string> sets = common;
    sets.push_back(std::string("simulation.sort_particles=") + (sort ? "true" : "false"));
    sets.push_back("output.directory=\"" + dir[sort].string() + "\"");
    summary[sort] = run(load_config_string(input, "order.toml", sets), quiet);
  }
  EXPECT_GE(summary[1].particle_sorts, 1);
  for (const char* file : {"particles-000001.h5", "particles-000002.h5"}) {
    h5::Handle fa = h5::open_file(dir[0] / "snapshots" / file), fb = h5::open_file(dir[1] / "snapshots" / file);
    h5::Handle ga = h5::open_group(fa.get(), "particles"), gb = h5::open_group(fb.get(), "particles");
    const std::size_t n = summary[0].n_particles;
    const auto ids = h5::read_int64s_rows(gb.get(), "id", 0, n);
    for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(ids[k], std::int64_t(k)) << file;
    for (const auto& [name, cols] : std::vector<std::pair<std::string, std::size_t>>{
             {"position", 3}, {"velocity", 3}, {"stress", 6}, {"deformation_gradient", 9}, {"mass", 0}})
      EXPECT_EQ(h5::read_doubles_rows(ga.get(), name, 0, n, cols), h5::read_doubles_rows(gb.get(), name, 0, n, cols))
          << file << " " << name;
    for (const char* name : {"body", "material"})
      EXPECT_EQ(h5::read_ints_rows(ga.get(), name, 0, n), h5::read_ints_rows(gb.get(), name, 0, n)) << file << " " << name;
  }
  const fs::path again = test::fresh_dir("order_restarted");
  const RunSummary rest = restart(dir[1] / "checkpoint-0000.h5", {"output.directory=\"" + again.string() + "\""}, quiet);
  EXPECT_GT(rest.steps, 0);
  expect_same(by_id(read_checkpoint<2>(summary[1].last_checkpoint).particles),
              by_id(read_checkpoint<2>(rest.last_checkpoint).particles), "restart");
  std::ifstream ha(dir[1] / "history.csv"), hb(again / "history.csv"), hc(dir[0] / "history.csv");
  std::stringstream sa, sb, sc;
  sa << ha.rdbuf();
  sb << hb.rdbuf();
  sc << hc.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
  EXPECT_EQ(sa.str(), sc.str());
  for (const auto& d : {dir[0], dir[1], again}) fs::remove_all(d);
}

}  // namespace
}  // namespace cairn
