// The reference explicit FEM (seed 001 Appendix A) on its own: patch test, lumped mass, energy
// and momentum of a free block, and the manufactured-solution convergence in displacement.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "cairn/fem/solver.hpp"
#include "fem_case.hpp"

namespace cairn {
namespace {

using fem::Solver;

// Patch test: a linear displacement u = G X on an unstructured Gmsh mesh gives every element
// F = I + G exactly, the same stress everywhere and no net internal force at interior nodes.
TEST(FemSolver, PatchTestLinearFieldGivesConstantStress) {
  const Config c = test::fem_config(
      "shape = { polygon = { vertices = [[0.0, 0.0], [1.0, 0.1], [0.9, 1.0], [-0.1, 0.8]] } }\n"
      "size = 0.15\n"
      "displacement = [\"0.02*X + 0.01*Y\", \"-0.015*X + 0.03*Y\"]\n");
  const Solver s(c);
  ASSERT_GT(s.mesh().n_elements(), 40u);
  Mat3 expected = Mat3::Identity();
  expected.topLeftCorner<2, 2>() << 1.02, 0.01, -0.015, 1.03;
  const Mat3 tau0 = s.kirchhoff_stresses().front();
  ASSERT_GT(tau0.norm(), 10.0);
  for (std::size_t e = 0; e < s.mesh().n_elements(); ++e) {
    EXPECT_LT((s.deformation_gradients()[e] - expected).norm(), 1e-13) << "element " << e;
    EXPECT_LT((s.kirchhoff_stresses()[e] - tau0).norm(), 1e-10 * tau0.norm()) << "element " << e;
  }
  // interior nodes: the element forces cancel (acceleration ~ round-off of f / M)
  Vec<2> lo = s.mesh().nodes.front(), hi = lo;
  std::vector<bool> boundary(s.mesh().n_nodes(), false);
  {
    // boundary nodes: on an edge used by one element only
    std::map<std::pair<int, int>, int> edges;
    for (const auto& t : s.mesh().triangles)
      for (int k = 0; k < 3; ++k) ++edges[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
    for (const auto& [e, n] : edges)
      if (n == 1) boundary[e.first] = boundary[e.second] = true;
  }
  const double scale = tau0.norm() / (1.0 * 0.15);  // stress / (density * size): a boundary node's acceleration
  int interior = 0;
  for (std::size_t i = 0; i < s.mesh().n_nodes(); ++i) {
    if (boundary[i]) continue;
    ++interior;
    EXPECT_LT(s.accelerations()[i].norm(), 1e-10 * scale) << "node " << i;
  }
  EXPECT_GT(interior, 10);
  double max_boundary = 0.0;
  for (std::size_t i = 0; i < s.mesh().n_nodes(); ++i)
    if (boundary[i]) max_boundary = std::max(max_boundary, s.accelerations()[i].norm());
  EXPECT_GT(max_boundary, 0.1 * scale);  // the unbalanced boundary forces are there
  (void)lo;
  (void)hi;
}

// Plane stress: the same patch, F_zz solves tau_zz = 0 in every element (the MPM's solver).
TEST(FemSolver, PlaneStressPatchHasNoOutOfPlaneStress) {
  const Config c = test::fem_config(
      "shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\nsize = 0.25\n"
      "displacement = [\"0.05*X\", \"0.02*Y\"]\n",
      "", 1.0e4, 0.3, "plane_stress");
  const Solver s(c);
  const double fzz = s.deformation_gradients().front()(2, 2);
  EXPECT_LT(fzz, 1.0);  // stretched in-plane: thinner
  for (std::size_t e = 0; e < s.mesh().n_elements(); ++e) {
    EXPECT_LT(std::abs(s.kirchhoff_stresses()[e](2, 2)), 1e-9 * s.kirchhoff_stresses()[e].norm());
    EXPECT_NEAR(s.deformation_gradients()[e](2, 2), fzz, 1e-12);
  }
}

// Eq. A2: each node carries a third of the mass of its elements; the total is rho * area.
TEST(FemSolver, LumpedMassSumsToTotalMass) {
  for (const char* mesher : {"gmsh", "structured"}) {
    const Config c = test::fem_config(
        fmt::format("shape = {{ box = {{ min = [0.0, 0.0], max = [2.0, 0.5] }} }}\nsize = 0.1\nmesher = \"{}\"\n",
                    mesher));
    const Solver s(c);
    double total = 0.0;
    for (double m : s.masses()) total += m;
    EXPECT_NEAR(total, 1.0 * 2.0 * 0.5, 1e-12) << mesher;
    std::vector<double> third(s.mesh().n_nodes(), 0.0);
    for (std::size_t e = 0; e < s.mesh().n_elements(); ++e)
      for (const auto i : s.mesh().triangles[e]) third[i] += s.reference_volumes()[e] / 3.0;
    for (std::size_t i = 0; i < third.size(); ++i) EXPECT_DOUBLE_EQ(s.masses()[i], third[i]);
  }
  // an annulus: the polygonal mesh area approaches pi (Ro^2 - Ri^2) as the size shrinks
  const Config ring = test::fem_config(
      "shape = { annulus = { center = [0.0, 0.0], inner_radius = 0.5, outer_radius = 1.0 } }\nsize = 0.02\n");
  const Solver r(ring);
  double total = 0.0;
  for (double m : r.masses()) total += m;
  EXPECT_NEAR(total, std::numbers::pi * 0.75, 2e-3);
  EXPECT_LT(total, std::numbers::pi * 0.75);  // inscribed polygons
}

/// Energy error |E(t) - E(0)| / E(0) maximum over a run of a free, spinning and vibrating block.
struct FreeBlock {
  double energy_error = 0.0, momentum_error = 0.0, initial_energy = 0.0, strain_energy_max = 0.0;
};
FreeBlock run_free_block(double cfl) {
  Config c = test::fem_config(
      "shape = { box = { min = [0.0, 0.0], max = [1.0, 0.5] } }\nsize = 0.1\n"
      "velocity = [\"3 + 5*sin(_pi*X)\", \"-2 + 4*cos(_pi*Y) + 3*X\"]\n");
  c.simulation.cfl = cfl;
  Solver s(c);
  const fem::FemTotals t0 = s.totals();
  FreeBlock out;
  out.initial_energy = t0.kinetic_energy + t0.strain_energy;
  while (s.time() < 0.05) {
    s.step(s.next_dt());
    const fem::FemTotals t = s.totals();
    out.energy_error = std::max(out.energy_error, std::abs(t.kinetic_energy + t.strain_energy - out.initial_energy));
    out.momentum_error = std::max(out.momentum_error, (t.momentum - t0.momentum).norm());
    out.strain_energy_max = std::max(out.strain_energy_max, t.strain_energy);
  }
  out.energy_error /= out.initial_energy;
  return out;
}

// A free block (no conditions, no body force) keeps its momentum to round-off and its energy to
// the O(dt^2) error of the central difference: halving the CFL number quarters the error.
TEST(FemSolver, FreeBlockConservesEnergyAndMomentum) {
  const FreeBlock a = run_free_block(0.4), b = run_free_block(0.2);
  EXPECT_GT(a.strain_energy_max, 0.05 * a.initial_energy);  // it really vibrates
  EXPECT_LT(a.momentum_error, 1e-12 * std::sqrt(a.initial_energy));
  EXPECT_LT(a.energy_error, 1e-3);
  const double ratio = a.energy_error / b.energy_error;
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 5.5);
  std::printf("free block: energy error %.3e (cfl 0.4), %.3e (cfl 0.2), ratio %.2f\n", a.energy_error,
              b.energy_error, ratio);
}

}  // namespace
}  // namespace cairn
