// Manufactured solution for the FEM (docs/fem.md, "Verification"): on the unit square with
// symmetry on all four faces,
//   u = (f(X, t), g(Y, t)),  f = A sin(pi X) cos(w t),  g = A sin(pi Y) cos(w t),
// is an exact large-deformation solution of the neo-Hookean balance (seed 001 Eq. 31-32, plane
// strain) under the body force, with p = 1 + f', q = 1 + g' and J = p q,
//   b_x = f_tt - f''/rho [lambda (1 - ln(p q)) + mu (p^2 + 1)] / p^2,
//   b_y = g_tt - g''/rho [lambda (1 - ln(p q)) + mu (q^2 + 1)] / q^2,
// (F = diag(p, q): P_xx = (lambda ln J + mu (p^2 - 1)) / p depends on X through p only, and the
// shear stress vanishes, so the symmetry faces carry exactly the solution's tractions). The error
// is Eq. 38's L_inf over all nodes and steps; it must fall as h^2.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "cairn/fem/solver.hpp"
#include "cairn/input/input.hpp"
#include "fem_case.hpp"

namespace cairn {
namespace {

constexpr double E = 1.0e4, nu = 0.3, A = 0.05, w = 300.0, end_time = 0.01;

double mms_error(double size, const std::string& mesher) {
  const double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const std::string fem = fmt::format(
      "shape = {{ box = {{ min = [0.0, 0.0], max = [1.0, 1.0] }} }}\nsize = {}\nmesher = \"{}\"\n"
      "displacement = [\"A*sin(_pi*X)\", \"A*sin(_pi*Y)\"]\n"
      "exact_displacement = [\"A*sin(_pi*X)*cos(w*t)\", \"A*sin(_pi*Y)*cos(w*t)\"]\n",
      size, mesher);
  const std::string extra = fmt::format(
      "[constants]\nA = {}\nw = {}\nlam = {:.17g}\nmu = {:.17g}\n\n"
      "[boundary]\nx_min = \"symmetry\"\nx_max = \"symmetry\"\ny_min = \"symmetry\"\ny_max = \"symmetry\"\n\n"
      "[body_force]\nexpression = [\n"
      "  \"-A*w^2*sin(_pi*X)*cos(w*t) + A*_pi^2*sin(_pi*X)*cos(w*t) * (lam*(1 - ln((1 + A*_pi*cos(_pi*X)*cos(w*t))*(1 + "
      "A*_pi*cos(_pi*Y)*cos(w*t)))) + mu*((1 + A*_pi*cos(_pi*X)*cos(w*t))^2 + 1)) / (1 + A*_pi*cos(_pi*X)*cos(w*t))^2\",\n"
      "  \"-A*w^2*sin(_pi*Y)*cos(w*t) + A*_pi^2*sin(_pi*Y)*cos(w*t) * (lam*(1 - ln((1 + A*_pi*cos(_pi*X)*cos(w*t))*(1 + "
      "A*_pi*cos(_pi*Y)*cos(w*t)))) + mu*((1 + A*_pi*cos(_pi*Y)*cos(w*t))^2 + 1)) / (1 + A*_pi*cos(_pi*Y)*cos(w*t))^2\"]\n",
      A, w, lam, mu);
  Config c = test::fem_config(fem, extra, E, nu);
  c.simulation.end_time = end_time;
  fem::Solver s(c);
  const auto& X = s.mesh().nodes;
  double err = 0.0;
  while (s.time() < end_time * (1 - 1e-12)) {
    s.step(s.next_dt());
    const double ct = std::cos(w * s.time());
    for (std::size_t i = 0; i < X.size(); ++i) {
      const Vec<2> u(A * std::sin(std::numbers::pi * X[i][0]) * ct, A * std::sin(std::numbers::pi * X[i][1]) * ct);
      err = std::max(err, (s.positions()[i] - X[i] - u).norm());  // seed 001 Eq. 38
    }
  }
  // the solver's own Eq. 38 measurement (fem.exact_displacement, history.csv) agrees
  EXPECT_NEAR(s.displacement_error_max(), err, 1e-12 * A);  // round-off of x - X at the scale A
  return err;
}

/// Order 2 asserted as > 1.8 for every pair of successive meshes, whatever the mesher. Gmsh's
/// meshes of a sequence are not nested (element shapes differ from mesh to mesh), so the
/// least-squares slope of log error against log h over the sequence is printed beside the pairwise
/// orders as a second reading; it is not a substitute for the pairwise assertion.
void check_orders(const std::string& label, const std::string& mesher, const std::vector<double>& sizes,
                  const std::vector<double>& errors) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const auto n = static_cast<double>(sizes.size());
  for (std::size_t k = 0; k < sizes.size(); ++k) {
    const double x = std::log(sizes[k]), y = std::log(errors[k]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
    if (k + 1 == sizes.size()) break;
    const double order = std::log(errors[k] / errors[k + 1]) / std::log(sizes[k] / sizes[k + 1]);
    std::printf("%s %s h = %.5g -> %.5g: L_inf %.4e -> %.4e, order %.3f\n", label.c_str(), mesher.c_str(), sizes[k],
                sizes[k + 1], errors[k], errors[k + 1], order);
    EXPECT_GT(order, 1.8) << label << " " << mesher << " h = " << sizes[k + 1];
  }
  const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
  std::printf("%s %s least-squares order %.3f\n", label.c_str(), mesher.c_str(), slope);
}

void expect_second_order(const std::string& mesher, const std::vector<double>& sizes) {
  std::vector<double> errors;
  for (double h : sizes) errors.push_back(mms_error(h, mesher));
  check_orders("square", mesher, sizes, errors);
}

TEST(FemMms, SecondOrderInDisplacementStructured) { expect_second_order("structured", {1.0 / 8, 1.0 / 16, 1.0 / 32}); }

// Seed 001 Sec. 5.1's ring on the FEM (tests/fem/ring_mms.toml has the body force): structured
// annulus meshes, L_inf of Eq. 38 over all nodes and steps from the solver's history measure.
void expect_ring_second_order(const std::string& mesher, const std::vector<double>& sizes) {
  std::vector<double> errors;
  for (double h : sizes) {
    Config c = load_config(std::string(CAIRN_SOURCE_DIR) + "/tests/fem/ring_mms.toml",
                           {fmt::format("fem.size={}", h), "fem.mesher=" + mesher});
    fem::Solver s(c);
    while (s.time() < c.simulation.end_time * (1 - 1e-12)) s.step(s.next_dt());
    errors.push_back(s.displacement_error_max());
  }
  check_orders("ring", mesher, sizes, errors);
}

TEST(FemMms, RingSecondOrderInDisplacement) { expect_ring_second_order("structured", {0.1, 0.05, 0.025}); }

// The fuller sweep, under the `long` label (tests/CMakeLists.txt): finer structured meshes.
TEST(FemLong, DISABLED_SecondOrderInDisplacementSweep) {
  expect_second_order("structured", {1.0 / 16, 1.0 / 32, 1.0 / 64, 1.0 / 128});
  expect_ring_second_order("structured", {0.1, 0.05, 0.025, 0.0125, 0.00625});
}

// Unstructured Gmsh sequences, label `known-failure` (tests/CMakeLists.txt): the square passes
// pair by pair (1.98, 2.01, 2.02), but the ring's coarsest pair measured 1.78 < 1.8 (then 2.12,
// 1.98; least-squares slope 1.97) because the non-nested meshes change element shapes between
// sizes. Recorded in docs/fem.md; the assertion stays as for the structured sequences.
TEST(FemKnownFailure, DISABLED_GmshSecondOrderInDisplacementSweep) {
  expect_second_order("gmsh", {1.0 / 8, 1.0 / 16, 1.0 / 32, 1.0 / 64});
  expect_ring_second_order("gmsh", {0.1, 0.05, 0.025, 0.0125});
}

}  // namespace
}  // namespace cairn
