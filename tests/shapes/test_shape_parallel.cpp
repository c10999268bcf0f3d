// Every shape family reports a colouring reach that makes the particle-to-grid scatter race-free:
// a sheared, spinning block on a grid wide enough for several colour blocks per axis gives
// bit-identical particles for 1, 2 and 4 threads. CPDI domains deform (and grow their stencils)
// during the run; symmetry faces exercise the ghost mirrors, fixed faces the open-knot face values.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <numeric>
#include <random>
#include <thread>

#include "../support/config_builder.hpp"
#include "cairn/input/names.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/parallel.hpp"

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

// The colouring's binning and counting sort run in one team from particle_loop_min particles:
// for 1, 2 and 3 threads they give the serial stable sort by block (storage order within a
// block, or a distributed run's id order), the same block offsets and the same colour lists.
TEST(ParticleAffinity, ColouringSortIsTheStableSortForAnyThreadCount) {
  const Grid<2> grid(Vec<2>(0.0, 0.0), IVec<2>(64, 48), Vec<2>(1.0, 1.0), 2, {false, false});
  Particles<2> particles;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(0.0, 64.0), y(0.0, 48.0);
  const std::size_t n = 3 * particle_loop_min + 5;
  particles.resize(n);
  for (std::size_t p = 0; p < n; ++p) particles.position[p] = Vec<2>(x(rng), y(rng));
  for (const bool by_id : {false, true}) {
    std::vector<std::int32_t> sequence(n);
    std::iota(sequence.begin(), sequence.end(), 0);
    if (by_id) std::shuffle(sequence.begin(), sequence.end(), rng);  // a distributed run's id order
    std::vector<TransferCache<2>> caches;
    for (const int threads : {1, 2, 3}) {
      omp_set_num_threads(threads);
      TransferCache<2>& cache = caches.emplace_back();
      cache.reserve(n, 4);
      if (by_id) cache.id_order = sequence;
      colour_blocks(grid, particles, cache);
    }
    // The reference: the block of every particle, then a serial stable sort of the sequence.
    const TransferCache<2>& first = caches.front();
    std::vector<std::int32_t> block(n);
    for (int b = 0; b + 1 < static_cast<int>(first.block_begin.size()); ++b)
      for (std::int32_t i = first.block_begin[b]; i < first.block_begin[b + 1]; ++i) block[first.order[i]] = b;
    std::vector<std::int32_t> expected = sequence;
    std::stable_sort(expected.begin(), expected.end(), [&](std::int32_t a, std::int32_t b) { return block[a] < block[b]; });
    ASSERT_GT(first.block_begin.size(), 10U);  // several blocks
    for (const auto& cache : caches) {
      ASSERT_EQ(cache.order, expected) << "by id " << by_id;
      ASSERT_EQ(cache.block_begin, first.block_begin);
      ASSERT_EQ(cache.colour_blocks, first.colour_blocks);
      for (std::size_t p = 0; p < n; ++p)  // each particle in the block of its cell
        ASSERT_EQ(block[p], (static_cast<int>(particles.position[p][0]) / 8) +
                                (static_cast<int>(particles.position[p][1]) / 8) * 8)
            << p;
    }
  }
  omp_set_num_threads(omp_get_num_procs());
}

// The particle shares of util/parallel.hpp: the threads' static ranges partition the particles
// in order, each within one particle of n / T.
TEST(ParticleAffinity, StaticRangesPartitionTheParticles) {
  for (const std::int64_t n : {0, 1, 2, 3, 7, 8, 100, 8000, 8001}) {
    for (int T = 1; T <= 5; ++T) {
      std::int64_t next = 0;
      for (int t = 0; t < T; ++t) {
        const auto [first, last] = static_range(n, t, T);
        ASSERT_EQ(first, next) << n << " " << T << " " << t;
        ASSERT_LE(last - first, n / T + 1);
        ASSERT_GE(last - first, n / T);
        next = last;
      }
      ASSERT_EQ(next, n);
    }
  }
}

// Particle affinity with stealing (util/parallel.hpp): for any team, every item is handed out
// exactly once; a thread keeps its static_range while the team runs evenly, and when one thread
// is slowed the others take part of its range.
TEST(ParticleAffinity, StealingShareCoversEveryItemOnceAndHelpsASlowThread) {
  for (int T : {1, 2, 3, 4}) {
    for (std::int64_t n : {0, 1, 17, 1000, 100003}) {
      omp_set_num_threads(T);
      StealingShare share(n);
      std::vector<int> done(static_cast<std::size_t>(n), 0), by(static_cast<std::size_t>(n), -1);
#pragma omp parallel
      {
        auto cursor = share.cursor();
        for (std::int64_t first, last; cursor.next(first, last);)
          for (std::int64_t i = first; i < last; ++i) {
            ++done[i];  // a race (and a count of 2) if two threads got the item
            by[i] = omp_get_thread_num();
          }
      }
      for (std::int64_t i = 0; i < n; ++i) ASSERT_EQ(done[i], 1) << "T " << T << " n " << n << " item " << i;
    }
  }
  // Thread 1 sleeps in every chunk it takes: thread 0 ends up with more than its half. (Thread 0
  // starts once thread 1 holds its first chunk, so that a late thread 1 is not left with nothing.)
  omp_set_num_threads(2);
  const std::int64_t n = 64000;
  StealingShare share(n);
  std::vector<int> by(static_cast<std::size_t>(n), -1);
  int team = 0;
  std::atomic<bool> started{false};
#pragma omp parallel
  {
    team = omp_get_num_threads();
    const int t = omp_get_thread_num();
    auto cursor = share.cursor();
    if (t == 0)
      while (!started.load()) std::this_thread::yield();
    for (std::int64_t first, last; cursor.next(first, last);) {
      if (t == 1) {
        started.store(true);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      for (std::int64_t i = first; i < last; ++i) by[i] = t;
    }
  }
  omp_set_num_threads(omp_get_num_procs());
  ASSERT_EQ(team, 2);
  const auto by_0 = std::count(by.begin(), by.end(), 0);
  EXPECT_EQ(std::count(by.begin(), by.end(), -1), 0);
  EXPECT_GT(by_0, 3 * n / 4);
  // What thread 0 took from thread 1 came from the back of thread 1's half: the front of that
  // half stayed with thread 1.
  EXPECT_EQ(by[n / 2], 1);
  // An if(false) region (a team of 1, not the one the share was made for) gets the static range.
  StealingShare serial(10);
  std::int64_t covered = 0;
#pragma omp parallel if (false)
  {
    auto cursor = serial.cursor();
    for (std::int64_t first, last; cursor.next(first, last);) covered += last - first;
  }
  EXPECT_EQ(covered, 10);
}

// Beyond affinity_max_particles the gathers and scatters hand out work dynamically: the results
// stay bit-identical for any thread count there too.
TEST(ParticleAffinity, DynamicWorkForManyParticlesIsBitIdenticalForAnyThreadCount) {
  Config cfg = test::box_config(2, "linear", "neo_hookean");
  cfg.grid.cell_size.assign(2, 1.0 / 300);
  cfg.bodies[0].shape.min = {0.05, 0.05};
  cfg.bodies[0].shape.max = {0.95, 0.95};
  cfg.bodies[0].velocity = {"3*(Y-0.5)", "-2*(X-0.5)"};
  std::vector<Particles<2>> results;
  for (int threads : {1, 2}) {
    cfg.simulation.threads = threads;
    Simulation<2> sim(cfg);
    ASSERT_GT(static_cast<std::int64_t>(sim.particles().n()), affinity_max_particles);
    for (int s = 0; s < 2; ++s) sim.step(sim.next_dt());
    results.push_back(sim.particles());
  }
  omp_set_num_threads(omp_get_num_procs());
  for (std::size_t p = 0; p < results[0].n(); ++p) {
    ASSERT_EQ(results[1].position[p], results[0].position[p]);
    ASSERT_EQ(results[1].velocity[p], results[0].velocity[p]);
    ASSERT_EQ(results[1].kirchhoff_stress[p], results[0].kirchhoff_stress[p]);
  }
}

}  // namespace
}  // namespace cairn
