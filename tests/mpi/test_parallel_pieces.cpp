// The serial-testable pieces of the MPI distribution (docs/parallel.md): exact sums that do not
// depend on the order of their terms, the recursive bisection, grid windows, and the generic
// particle-array transfers. The runs on 2-4 ranks are ctest cases under mpirun (tests/mpi).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "cairn/grid/grid.hpp"
#include "cairn/config/errors.hpp"
#include "cairn/parallel/decomposition.hpp"
#include "cairn/parallel/exact_sum.hpp"
#include "cairn/parallel/particle_transfer.hpp"
#include "cairn/sim/simulation.hpp"
#include "../support/config_builder.hpp"

namespace cairn {
namespace {

TEST(ExactSum, OrderDoesNotChangeTheSum) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-60, 60);
  std::vector<double> terms(5000);
  for (double& t : terms) t = std::ldexp(mantissa(rng), exponent(rng));
  ExactSum forward;
  for (double t : terms) forward.add(t);
  for (int trial = 0; trial < 5; ++trial) {
    std::shuffle(terms.begin(), terms.end(), rng);
    // Split into uneven parts summed separately and merged: a partition over ranks/threads.
    ExactSum parts[3];
    for (std::size_t k = 0; k < terms.size(); ++k) parts[(k * k) % 3].add(terms[k]);
    ExactSum merged = parts[2];
    merged += parts[0];
    merged += parts[1];
    EXPECT_EQ(merged.value(), forward.value());
  }
  // A naive sum in two orders differs here (cancellation over 120 binary orders of magnitude),
  // so the test can fail for an order-dependent sum.
  double a = 0.0, b = 0.0;
  for (double t : terms) a += t;
  std::reverse(terms.begin(), terms.end());
  for (double t : terms) b += t;
  EXPECT_NE(a, b);
}

TEST(ExactSum, IsExactWhereDoublesCancel) {
  ExactSum s;
  s.add(1e300);
  s.add(1.0);
  s.add(-1e300);
  s.add(1e-300);
  EXPECT_EQ(s.value(), 1.0);  // a naive sum gives 0
  ExactSum tiny;
  tiny.add(std::numeric_limits<double>::denorm_min());
  tiny.add(std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(tiny.value(), 2 * std::numeric_limits<double>::denorm_min());
  ExactSum neg;
  neg.add(-3.5);
  neg.add(1.25);
  EXPECT_EQ(neg.value(), -2.25);
  ExactSum special;
  special.add(1.0);
  special.add(std::numeric_limits<double>::infinity());
  EXPECT_EQ(special.value(), std::numeric_limits<double>::infinity());
  special.add(-std::numeric_limits<double>::infinity());
  EXPECT_TRUE(std::isnan(special.value()));
}

TEST(ExactSum, RoundsWithinAnUlp) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  long double reference = 0.0L;
  ExactSum s;
  for (int k = 0; k < 100000; ++k) {
    const double t = u(rng);
    s.add(t);
    reference += t;
  }
  EXPECT_NEAR(s.value(), static_cast<double>(reference), 2e-16 * static_cast<double>(reference));
}

TEST(Decomposition, BisectsByParticlesAndCoversEveryCell) {
  // One rank: the serial Comm gives one box. The splitting itself is exercised on several
  // ranks by the mpirun cases; here the owner lookup and the neighbour test.
  IVec<2> n(40, 10);
  Decomposition<2> d(n, {false, true});
  EXPECT_EQ(d.n_boxes(), 1);
  EXPECT_EQ(d.owner(IVec<2>(-5, 3)), 0);
  EXPECT_EQ(d.domain_cell(IVec<2>(-5, 12)), IVec<2>(0, 2));
  EXPECT_EQ(d.domain_cell(IVec<2>(45, -1)), IVec<2>(39, 9));
  std::vector<IVec<2>> cells{IVec<2>(1, 1), IVec<2>(2, 2)};
  const Decomposition<2> b = Decomposition<2>::bisect(Comm::serial(), n, {false, true}, cells);
  EXPECT_EQ(b.n_boxes(), 1);
  EXPECT_EQ(b.box(0).hi, n);
  EXPECT_TRUE(b.near(0, IVec<2>(41, 3), 2));
  EXPECT_FALSE(b.near(0, IVec<2>(42, 3), 2));
}

/// A 128 x 128 grid with 4 particles per cell, those left of x = 64 costing 3 (weight 3000),
/// the others 1 (weight 1000): one entry per particle.
struct TwoCostField {
  IVec<2> n{128, 128};
  std::vector<IVec<2>> cells;
  std::vector<std::int64_t> weights;
  TwoCostField() {
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (int k = 0; k < 4; ++k) {
          cells.emplace_back(i, j);
          weights.push_back(i < 64 ? 3000 : 1000);
        }
  }
};

/// Largest weight of a box over the mean.
double cost_imbalance(const Decomposition<2>& d, const std::vector<IVec<2>>& cells,
                      const std::vector<std::int64_t>& weights) {
  std::vector<std::int64_t> cost(static_cast<std::size_t>(d.n_boxes()), 0);
  std::int64_t total = 0;
  for (std::size_t p = 0; p < cells.size(); ++p) {
    cost[static_cast<std::size_t>(d.owner(cells[p]))] += weights[p];
    total += weights[p];
  }
  return static_cast<double>(*std::max_element(cost.begin(), cost.end())) * d.n_boxes() / static_cast<double>(total);
}

bool same_boxes(const Decomposition<2>& a, const Decomposition<2>& b) {
  if (a.n_boxes() != b.n_boxes()) return false;
  for (int r = 0; r < a.n_boxes(); ++r)
    if (a.box(r).lo != b.box(r).lo || a.box(r).hi != b.box(r).hi) return false;
  return true;
}

TEST(Decomposition, WeightedBisectionGivesEveryBoxTheSameCost) {
  // Within 3 %: a cut can miss the balancing share by half a slab of cells (at most 1.2 % of a
  // box's cost here), and the cuts of up to three levels compound. Balancing particle counts
  // instead leaves the boxes of the costly half 50 % above the mean (2 boxes: 3 x 64 against
  // 1 x 64 columns).
  const TwoCostField f;
  for (int boxes : {2, 3, 4, 5, 8}) {
    const Decomposition<2> weighted = Decomposition<2>::bisect(Comm::serial(), f.n, {false, false}, f.cells, f.weights, boxes);
    ASSERT_EQ(weighted.n_boxes(), boxes);
    EXPECT_LE(cost_imbalance(weighted, f.cells, f.weights), 1.03) << boxes << " boxes";
    const Decomposition<2> counted = Decomposition<2>::bisect(Comm::serial(), f.n, {false, false}, f.cells, {}, boxes);
    EXPECT_GE(cost_imbalance(counted, f.cells, f.weights), 1.2) << boxes << " boxes";
    // The boxes tile the grid: every cell has one owner, and the boxes' cells add up.
    long long covered = 0;
    for (int r = 0; r < boxes; ++r) covered += weighted.box(r).n_cells();
    EXPECT_EQ(covered, 128LL * 128LL);
  }
}

TEST(Decomposition, WeightedBisectionIsDeterministic) {
  // The same particles in another order give the same boxes (integer histograms), and so does
  // the same run again.
  TwoCostField f;
  const Decomposition<2> a = Decomposition<2>::bisect(Comm::serial(), f.n, {false, true}, f.cells, f.weights, 6);
  const Decomposition<2> b = Decomposition<2>::bisect(Comm::serial(), f.n, {false, true}, f.cells, f.weights, 6);
  EXPECT_TRUE(same_boxes(a, b));
  std::vector<std::size_t> order(f.cells.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937_64(11));
  std::vector<IVec<2>> cells;
  std::vector<std::int64_t> weights;
  for (std::size_t p : order) {
    cells.push_back(f.cells[p]);
    weights.push_back(f.weights[p]);
  }
  EXPECT_TRUE(same_boxes(a, Decomposition<2>::bisect(Comm::serial(), f.n, {false, true}, cells, weights, 6)));
  EXPECT_THROW(Decomposition<2>::bisect(Comm::serial(), f.n, {false, true}, cells, {1, 2}, 6), std::invalid_argument);
}

TEST(Decomposition, RebalanceWithinToleranceMovesNoParticle) {
  // A small imbalance (a few particles more in one box): a rebalance keeps every cut, so no
  // particle changes box, where a fresh bisection would move cuts.
  const TwoCostField f;
  const Decomposition<2> d = Decomposition<2>::bisect(Comm::serial(), f.n, {false, false}, f.cells, f.weights, 4);
  std::vector<IVec<2>> cells = f.cells;
  std::vector<std::int64_t> weights = f.weights;
  const CellBox<2>& first = d.box(0);
  for (int j = first.lo[1]; j < first.lo[1] + 12; ++j)
    for (int i = first.lo[0]; i < first.hi[0]; ++i) {
      cells.emplace_back(i, j);
      weights.push_back(i < 64 ? 3000 : 1000);
    }
  const double before = cost_imbalance(d, cells, weights);
  EXPECT_GT(before, 1.02);
  EXPECT_LT(before, 1.05);
  EXPECT_FALSE(same_boxes(d, Decomposition<2>::bisect(Comm::serial(), f.n, {false, false}, cells, weights, 4)));
  const Decomposition<2> kept = d.rebalanced(Comm::serial(), cells, weights, 0.05);
  EXPECT_TRUE(same_boxes(d, kept));
  for (std::size_t p = 0; p < cells.size(); ++p) ASSERT_EQ(kept.owner(cells[p]), d.owner(cells[p]));
  // A large imbalance (box 0's particles twice over) moves the cuts out of balance and brings
  // the cost back within the tolerance compounded over the two levels (and a slab).
  for (int j = first.lo[1]; j < first.hi[1]; ++j)
    for (int i = first.lo[0]; i < first.hi[0]; ++i)
      for (int k = 0; k < 4; ++k) {
        cells.emplace_back(i, j);
        weights.push_back(i < 64 ? 3000 : 1000);
      }
  EXPECT_GT(cost_imbalance(d, cells, weights), 1.5);
  const Decomposition<2> moved = d.rebalanced(Comm::serial(), cells, weights, 0.02);
  EXPECT_FALSE(same_boxes(d, moved));
  EXPECT_LE(cost_imbalance(moved, cells, weights), 1.06);
}

template <int D>
void check_index_round_trip(const Grid<D>& g) {
  for (std::int32_t i = 0; i < g.n_nodes(); ++i) ASSERT_EQ(g.node_index(g.multi_index(i)), i) << i;
}

TEST(GridIndex, MultiIndexInvertsNodeIndexIn1D2D3D) {
  // Ghost layers (negative multi-indices), a periodic axis and unequal extents.
  check_index_round_trip(Grid<1>(Vec<1>(0.0), IVec<1>(7), Vec<1>(0.5), 2, {false}));
  check_index_round_trip(Grid<2>(Vec<2>(0.0, 0.0), IVec<2>(5, 9), Vec<2>(0.5, 0.25), 1, {true, false}));
  check_index_round_trip(Grid<3>(Vec<3>(0.0, 0.0, 0.0), IVec<3>(4, 6, 3), Vec<3>(1.0, 1.0, 1.0), 2, {false, true, false}));
  const Grid<3> g(Vec<3>(0.0, 0.0, 0.0), IVec<3>(4, 6, 3), Vec<3>(1.0, 1.0, 1.0), 0, {false, false, false});
  EXPECT_EQ(g.multi_index(g.n_nodes() - 1), IVec<3>(4, 6, 3));
  EXPECT_EQ(g.multi_index(5 + 5 * 7), IVec<3>(0, 1, 1));  // 5 nodes along x, 7 along y
}

TEST(GridWindow, TranslatesBetweenDomainAndStorage) {
  // 20 x 8 cells, x not periodic with 2 ghost layers, y periodic.
  Grid<2> whole(Vec<2>(0.0, 0.0), IVec<2>(20, 8), Vec<2>(0.5, 0.5), 2, {false, true});
  const Grid<2> w = whole.window(IVec<2>(5, -2), IVec<2>(6, 5), IVec<2>(7, 0), IVec<2>(9, 1));
  EXPECT_EQ(w.n_nodes(), 30);
  EXPECT_EQ(w.first_node(0), 5);
  EXPECT_FALSE(w.is_whole());
  EXPECT_TRUE(whole.is_whole());
  for (std::int32_t i = 0; i < w.n_nodes(); ++i) {
    const IVec<2> j = w.multi_index(i);
    EXPECT_EQ(w.node_index(j), i);
    EXPECT_GE(j[1], 0);  // periodic axes report the domain numbering
    EXPECT_LT(j[1], 8);
    EXPECT_EQ(w.node_position(i), whole.node_position(whole.node_index(j)));
  }
  EXPECT_EQ(w.node_index(IVec<2>(4, 0)), -1);  // left of the window
  EXPECT_GE(w.node_index(IVec<2>(5, 6)), 0);   // y = -2 wraps to 6
  EXPECT_EQ(w.node_index(IVec<2>(5, 3)), -1);  // y = 3 beyond the window's 5 rows
  // Ownership: cells [7, 9) x [0, 1); the upper face and the ghosts count for the last cell.
  EXPECT_TRUE(w.owns(w.node_index(IVec<2>(8, 0))));
  EXPECT_FALSE(w.owns(w.node_index(IVec<2>(9, 0))));
  EXPECT_FALSE(w.owns(w.node_index(IVec<2>(8, 1))));
  // Clipping to the stored ghost layers on the non-periodic axis, the whole ring on y.
  const Grid<2> edge = whole.window(IVec<2>(-10, -10), IVec<2>(15, 40), IVec<2>(0, 0), IVec<2>(3, 8));
  EXPECT_EQ(edge.first_node(0), -2);
  EXPECT_EQ(edge.stored_nodes(0), 7);
  EXPECT_EQ(edge.stored_nodes(1), 8);
  EXPECT_TRUE(edge.owns(edge.node_index(IVec<2>(-2, 5))));
}

TEST(ParticleTransfer, EveryArrayTravels) {
  Particles<2> a;
  a.n_state_per_particle = 2;
  a.has_affine = true;
  a.has_temperature = true;
  for (int p = 0; p < 6; ++p) {
    a.add(Vec<2>(p, 2.0 * p), Vec<2>(-p, 1.0), 1.0 + p, 0.5, Vec<2>(0.1, 0.2), p % 2, p % 3);
    a.state[2 * p] = 10.0 * p;
    a.state[2 * p + 1] = -p;
    a.temperature[p] = 300.0 + p;
    a.affine_velocity[p](0, 1) = p;
    a.deformation_gradient[p](1, 0) = 0.01 * p;
  }
  std::vector<char> buffer;
  pack_particles(a, std::vector<std::int32_t>{4, 1}, buffer);
  EXPECT_EQ(buffer.size(), 2 * particle_bytes(a));
  Particles<2> b;
  b.n_state_per_particle = 2;
  EXPECT_EQ(unpack_particles(b, buffer), 2u);
  ASSERT_EQ(b.n(), 2u);
  EXPECT_EQ(b.id[0], 4);
  EXPECT_EQ(b.id[1], 1);
  EXPECT_EQ(b.state[2], 10.0);
  EXPECT_EQ(b.temperature[0], 304.0);
  EXPECT_EQ(b.affine_velocity[1](0, 1), 1.0);
  EXPECT_DOUBLE_EQ(b.deformation_gradient[0](1, 0), 0.04);
  EXPECT_EQ(b.position[1], Vec<2>(1.0, 2.0));
  EXPECT_EQ(b.body[0], 1);
  reorder_particles(b, {1, 0});
  EXPECT_EQ(b.id[0], 1);
  EXPECT_EQ(b.state[1], -1.0);
}

TEST(ParticleTransfer, TheArrayListCoversTheStruct) {
  // Particles holds n_arrays vectors and three scalars (n_state_per_particle, has_affine,
  // has_temperature). An array added to the struct without for_each_array changes the size.
  Particles<3> p;
  int visited = 0;
  p.for_each_array([&](auto&, int) { ++visited; });
  EXPECT_EQ(visited, Particles<3>::n_arrays);
  struct Scalars {
    int n;
    bool a, t;
  };
  EXPECT_EQ(sizeof(Particles<3>), Particles<3>::n_arrays * sizeof(std::vector<double>) + sizeof(Scalars));
}

TEST(PerRankGeneration, ASelectionStoresItsParticlesWithTheirSerialIds) {
  // Two bodies, a displacement field and a velocity: per-rank generation (a selection by id and
  // position, as each rank of a distributed run makes it) stores exactly the particles of the
  // serial generation that it keeps, bit for bit, numbered as serially; the checks of the
  // generation (overlaps, empty bodies) still count every particle.
  Config c = test::box_config(2, "linear");
  BodyConfig second = c.bodies[0];
  second.name = "second";
  second.shape.min = {0.75, 0.1};
  second.shape.max = {0.95, 0.9};
  second.velocity = {"3*X", "-Y"};
  second.displacement = {"0.01*Y", "0.02*X*X"};
  c.bodies.push_back(second);
  const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1), 1, {false, false});
  std::vector<std::unique_ptr<Material>> materials;
  materials.push_back(make_material(c.materials[0]));
  Particles<2> all;
  create_particles<2>(c, grid, materials, Mode::plane_strain, all);
  ASSERT_GT(all.n(), 100u);
  std::vector<std::int64_t> seen;
  const ParticleSelection<2> select = [&](std::int64_t id, std::int32_t body, const Vec<2>& X, const Vec<2>& x,
                                         bool in_share) {
    EXPECT_FALSE(in_share);  // (one rank: every body generated whole, no rank's share)
    seen.push_back(id);
    const auto p = static_cast<std::size_t>(id);
    EXPECT_EQ(body, all.body[p]);
    EXPECT_EQ(X, all.reference_position[p]);
    EXPECT_EQ(x, all.position[p]);
    return x[0] > 0.5 || id % 3 == 0;
  };
  Particles<2> some;
  create_particles<2>(c, grid, materials, Mode::plane_strain, some, &select);
  ASSERT_EQ(seen.size(), all.n());  // every particle visited, in creation order
  for (std::size_t k = 0; k < seen.size(); ++k) EXPECT_EQ(seen[k], static_cast<std::int64_t>(k));
  std::vector<std::int32_t> kept;
  for (std::size_t p = 0; p < all.n(); ++p)
    if (all.position[p][0] > 0.5 || p % 3 == 0) kept.push_back(static_cast<std::int32_t>(p));
  ASSERT_LT(kept.size(), all.n());
  reorder_particles(all, kept);
  ASSERT_EQ(some.n(), all.n());
  // Every per-particle array, byte for byte (the migration's packing lists them all).
  std::vector<std::int32_t> every(some.n());
  std::iota(every.begin(), every.end(), 0);
  std::vector<char> bytes_some, bytes_all;
  pack_particles(some, every, bytes_some);
  pack_particles(all, every, bytes_all);
  EXPECT_TRUE(bytes_some == bytes_all);
  // An overlap is found the same way when the overlapping particles are not stored.
  c.bodies[1].shape.min = {0.6, 0.1};
  Particles<2> none;
  const ParticleSelection<2> nothing = [](std::int64_t, std::int32_t, const Vec<2>&, const Vec<2>&, bool) {
    return false;
  };
  EXPECT_THROW(create_particles<2>(c, grid, materials, Mode::plane_strain, none, &nothing), InputError);
  EXPECT_EQ(none.n(), 0u);
}

TEST(PerRankGeneration, ALatticeBodyIsMadeIntoArraysReservedForItsCount) {
  // A lattice body is made in two sweeps, the first counting (one bit per lattice point): the
  // particle arrays are reserved for the count, not grown by doubling while they are filled, so
  // the start-up holds no spare capacity (docs/parallel.md, the 2D block's memory). Two bodies:
  // the second reserve grows the arrays to the sum.
  Config c = test::box_config(2, "linear");
  BodyConfig second = c.bodies[0];
  second.name = "second";
  second.shape.min = {0.75, 0.1};
  second.shape.max = {0.95, 0.9};
  c.bodies.push_back(second);
  const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(10), Vec<2>::Constant(0.1), 1, {false, false});
  std::vector<std::unique_ptr<Material>> materials;
  materials.push_back(make_material(c.materials[0]));
  Particles<2> made;
  create_particles<2>(c, grid, materials, Mode::plane_strain, made);
  ASSERT_GT(made.n(), 100u);
  made.for_each_array([&](const auto& array, int width) {
    EXPECT_EQ(array.capacity(), made.n() * static_cast<std::size_t>(width));
  });
  for (std::size_t p = 0; p < made.n(); ++p) EXPECT_EQ(made.id[p], static_cast<std::int64_t>(p));
}

}  // namespace
}  // namespace cairn

namespace cairn {
namespace {

TEST(NodeHalo, SharedNodesAreTheSameListFromBothSidesAndHoldEveryNodeBothCanReach) {
  // 12 x 6 cells, x periodic (the boxes meet twice: at x = 5 and across the seam), y with 2
  // ghost layers. Box a: cells [0, 5) x [0, 6), box b: [5, 12) x [0, 6); margin 2.
  Grid<2> whole(Vec<2>(0.0, 0.0), IVec<2>(12, 6), Vec<2>(1.0, 1.0), 2, {true, false});
  const CellBox<2> a{IVec<2>(0, 0), IVec<2>(5, 6)}, b{IVec<2>(5, 0), IVec<2>(12, 6)};
  const int margin = 2;
  const auto ab = NodeHalo<2>::shared_nodes(a, b, whole, margin);
  const auto ba = NodeHalo<2>::shared_nodes(b, a, whole, margin);
  EXPECT_EQ(ab, ba);
  EXPECT_TRUE(std::is_sorted(ab.begin(), ab.end()));
  // A node with x index i is within `margin` nodes of both boxes' node ranges ([0, 5] and
  // [5, 12] with 12 = 0) exactly when i is in 3..7 or in 10..11, 0..2 (the seam); every y row of
  // the stored grid (6 + 1 + 2 x 2 ghosts = 11 rows).
  std::vector<std::int32_t> expected;
  for (std::int32_t idx = 0; idx < whole.n_nodes(); ++idx) {
    const int i = whole.multi_index(idx)[0];
    if ((i >= 3 && i <= 7) || i >= 10 || i <= 2) expected.push_back(idx);
  }
  EXPECT_EQ(ab, expected);
  EXPECT_EQ(ab.size(), 10u * 11u);
  // Far apart on a non-periodic axis: nothing shared.
  Grid<2> open(Vec<2>(0.0, 0.0), IVec<2>(20, 4), Vec<2>(1.0, 1.0), 1, {false, false});
  const CellBox<2> left{IVec<2>(0, 0), IVec<2>(5, 4)}, right{IVec<2>(10, 0), IVec<2>(20, 4)};
  EXPECT_TRUE(NodeHalo<2>::shared_nodes(left, right, open, margin).empty());
  EXPECT_FALSE(NodeHalo<2>::shared_nodes(left, right, open, 3).empty());  // nodes 7 and 8 both
}

}  // namespace
}  // namespace cairn
