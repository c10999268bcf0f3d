// Tests of the logistic / linear regression plane fits and the deformed particle radius of
// seed 004 (../shared/seeds/004_29fd5dcef9cf8d62.txt) Sec. 3.1 (Eq. 19-25) and Appendix
// (Eq. 53-57).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "cairn/contact/regression.hpp"

namespace cairn::contact {
namespace {

constexpr double kPi = std::numbers::pi;

double angle_between(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

struct Cloud {
  std::vector<Vec3> x;
  std::vector<signed char> cls;
  void add(const Vec3& p, int c) {
    x.push_back(p);
    cls.push_back(static_cast<signed char>(c));
  }
};

/// 2 particles per cell direction at cell-relative 0.25 and 0.75 in the 2^dim cells around `node`
/// (the cloud a grid node sees in MPM: 16 points in 2D, 64 in 3D). `classify` gets the offset
/// from the node in cell units and returns -1, +1 or 0 (no particle there).
template <class Classify>
Cloud lattice_cloud(int dim, double h, const Vec3& node, Classify classify) {
  Cloud cloud;
  const double q[4] = {-0.75, -0.25, 0.25, 0.75};
  for (int k = 0; k < (dim == 3 ? 4 : 1); ++k) {
    for (int j = 0; j < 4; ++j) {
      for (int i = 0; i < 4; ++i) {
        const Vec3 r(q[i], q[j], dim == 3 ? q[k] : 0.0);
        const int c = classify(r);
        if (c != 0) cloud.add(node + h * r, c);
      }
    }
  }
  return cloud;
}

/// A tilted interface: particles on a lattice aligned with the plane (a tilted body discretised
/// with its own 2-per-cell lattice), alpha rows at t = -0.25, -0.75 cells below the plane and
/// beta at the mirror images above it. Only alpha particles inside the axis-aligned box of the
/// 2^dim cells around the node are kept (so the cloud is not symmetric along the plane), each with
/// its mirror image; by the mirror symmetry the exact separating plane is the given one.
Cloud tilted_cloud(int dim, double h, const Vec3& node, const Vec3& normal) {
  // Orthonormal frame (e1, e2, normal).
  Vec3 e1 = (std::abs(normal.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY());
  if (dim == 2) e1 = Vec3(normal.y(), -normal.x(), 0.0);
  e1 = (e1 - e1.dot(normal) * normal).normalized();
  const Vec3 e2 = normal.cross(e1);
  Cloud cloud;
  const Vec3 origin = node + h * Vec3(0.13, -0.07, dim == 3 ? 0.05 : 0.0);  // plane point
  for (int b = -6; b <= 6; ++b) {
    for (int a = -6; a <= 6; ++a) {
      for (double t : {-0.25, -0.75}) {
        const double s1 = 0.25 + 0.5 * a;
        const double s2 = dim == 3 ? 0.25 + 0.5 * b : 0.0;
        if (dim == 2 && b != 0) continue;
        const Vec3 p = origin + h * (s1 * e1 + s2 * e2 + t * normal);
        const Vec3 r = (p - node) / h;
        bool inside = std::abs(r.x()) < 1.0 && std::abs(r.y()) < 1.0;
        if (dim == 3) inside = inside && std::abs(r.z()) < 1.0;
        if (!inside) continue;
        cloud.add(p, -1);
        cloud.add(p - 2.0 * h * t * normal, +1);
      }
    }
  }
  return cloud;
}

PlaneFit fit(const Cloud& c, const Vec3& center, const PlaneFitOptions& opt, PlaneFitMethod m,
             const Vec3* init = nullptr) {
  return fit_separating_plane(c.x, c.cls, {}, center, opt, m, init);
}

/// Fraction of points on the side of the plane their class says (beta: x.n + d > 0).
double fraction_on_correct_side(const Cloud& c, const PlaneFit& f) {
  int good = 0;
  for (std::size_t p = 0; p < c.x.size(); ++p) {
    const double s = c.x[p].dot(f.normal) + f.offset;
    if ((c.cls[p] > 0 && s > 0.0) || (c.cls[p] < 0 && s < 0.0)) ++good;
  }
  return static_cast<double>(good) / static_cast<double>(c.x.size());
}

TEST(RegressionPlaneFit, AxisAlignedInterface2DOnAGridLine) {
  const double h = 2.0;
  const Vec3 node(4.0, 6.0, 0.0);
  const Cloud c = lattice_cloud(2, h, node, [](const Vec3& r) { return r.y() > 0 ? 1 : -1; });
  ASSERT_EQ(c.x.size(), 16u);
  PlaneFitOptions opt;
  opt.dim = 2;
  opt.cell_size = h;
  for (auto m : {PlaneFitMethod::linear, PlaneFitMethod::logistic}) {
    const PlaneFit f = fit(c, node, opt, m);
    ASSERT_TRUE(f.ok);
    EXPECT_TRUE(f.converged);
    EXPECT_LE(f.iterations, 15);
    EXPECT_LT(angle_between(f.normal, Vec3::UnitY()), 1e-3);
    EXPECT_NEAR(f.normal.norm(), 1.0, 1e-14);
    EXPECT_EQ(f.normal.z(), 0.0);
    // The plane is y = 6, by the mirror symmetry of the cloud about it.
    EXPECT_NEAR(f.offset, -6.0, 1e-9);
    EXPECT_EQ(fraction_on_correct_side(c, f), 1.0);
  }
  EXPECT_GT(fit(c, node, opt, PlaneFitMethod::logistic).iterations, 1);
}

TEST(RegressionPlaneFit, AxisAlignedInterface2DInsideACell) {
  // Interface half a cell above the node: three alpha rows, one beta row.
  const double h = 0.5;
  const Vec3 node(-1.0, 0.5, 0.0);
  const Cloud c = lattice_cloud(2, h, node, [](const Vec3& r) { return r.y() > 0.5 ? 1 : -1; });
  PlaneFitOptions opt;
  opt.cell_size = h;
  const PlaneFit f = fit(c, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.converged);
  EXPECT_LT(angle_between(f.normal, Vec3::UnitY()), 1e-3);
  EXPECT_EQ(fraction_on_correct_side(c, f), 1.0);
  // The plane lies between the last alpha row (y = 0.625) and the beta row (y = 0.875).
  const double y_plane = -f.offset / f.normal.y();
  EXPECT_GT(y_plane, 0.625);
  EXPECT_LT(y_plane, 0.875);
}

TEST(RegressionPlaneFit, TiltedThirtyDegrees2D) {
  const double h = 1.5;
  const Vec3 node(3.0, -1.5, 0.0);
  const double th = 30.0 * kPi / 180.0;
  const Vec3 n_true(std::sin(th), std::cos(th), 0.0);
  const Cloud c = tilted_cloud(2, h, node, n_true);
  ASSERT_GE(c.x.size(), 8u);
  PlaneFitOptions opt;
  opt.cell_size = h;
  for (auto m : {PlaneFitMethod::linear, PlaneFitMethod::logistic}) {
    const PlaneFit f = fit(c, node, opt, m);
    ASSERT_TRUE(f.ok);
    EXPECT_TRUE(f.converged);
    EXPECT_LE(f.iterations, 15);
    EXPECT_LT(angle_between(f.normal, n_true), 1e-3) << "method " << static_cast<int>(m);
    EXPECT_EQ(fraction_on_correct_side(c, f), 1.0);
    // The plane passes through the mirror plane's point.
    const Vec3 origin = node + h * Vec3(0.13, -0.07, 0.0);
    EXPECT_NEAR(origin.dot(f.normal) + f.offset, 0.0, 1e-3 * h);
  }
}

TEST(RegressionPlaneFit, TiltedLatticesSelectedByGridCells2D) {
  // Two 30-degree tilted bodies with their own 2-per-cell lattices, touching along the plane
  // through `origin`, with the cloud taken as everything in the four cells around the node (no
  // mirror symmetry). The separating plane is then not unique; the logistic fit should still be
  // close to the interface and much closer than the linear fit.
  const double th = 30.0 * kPi / 180.0;
  const Vec3 n(std::sin(th), std::cos(th), 0.0), e1(n.y(), -n.x(), 0.0);
  for (double shift : {0.0, 0.1, 0.3}) {
    Cloud c;
    const Vec3 origin(shift, 0.05, 0.0);
    for (int a = -8; a <= 8; ++a) {
      for (double t : {-0.75, -0.25, 0.25, 0.75}) {
        const Vec3 p = origin + (0.25 + 0.5 * a) * e1 + t * n;
        if (std::abs(p.x()) < 1.0 && std::abs(p.y()) < 1.0) c.add(p, t > 0 ? 1 : -1);
      }
    }
    PlaneFitOptions opt;
    const PlaneFit lr = fit(c, Vec3::Zero(), opt, PlaneFitMethod::logistic);
    const PlaneFit lin = fit(c, Vec3::Zero(), opt, PlaneFitMethod::linear);
    ASSERT_TRUE(lr.ok && lin.ok);
    EXPECT_TRUE(lr.converged);
    EXPECT_LT(angle_between(lr.normal, n), 1.0 * kPi / 180.0) << "shift " << shift;
    EXPECT_LT(angle_between(lr.normal, n), angle_between(lin.normal, n)) << "shift " << shift;
    EXPECT_EQ(fraction_on_correct_side(c, lr), 1.0);
  }
}

TEST(RegressionPlaneFit, AxisAlignedAndTilted3D) {
  const double h = 0.1;
  const Vec3 node(0.2, 0.3, -0.4);
  PlaneFitOptions opt;
  opt.dim = 3;
  opt.cell_size = h;
  {
    // Interface on the grid plane z = node.z, normal +z (64 points).
    const Cloud c = lattice_cloud(3, h, node, [](const Vec3& r) { return r.z() > 0 ? 1 : -1; });
    ASSERT_EQ(c.x.size(), 64u);
    const PlaneFit f = fit(c, node, opt, PlaneFitMethod::logistic);
    ASSERT_TRUE(f.ok);
    EXPECT_TRUE(f.converged);
    EXPECT_LT(angle_between(f.normal, Vec3::UnitZ()), 1e-3);
    EXPECT_NEAR(f.offset, 0.4, 1e-9);
    EXPECT_EQ(fraction_on_correct_side(c, f), 1.0);
  }
  {
    // Normal tilted 30 degrees from z, in an azimuth of 20 degrees.
    const double th = 30.0 * kPi / 180.0, az = 20.0 * kPi / 180.0;
    const Vec3 n_true(std::sin(th) * std::cos(az), std::sin(th) * std::sin(az), std::cos(th));
    const Cloud c = tilted_cloud(3, h, node, n_true);
    ASSERT_GE(c.x.size(), 32u);
    for (auto m : {PlaneFitMethod::linear, PlaneFitMethod::logistic}) {
      const PlaneFit f = fit(c, node, opt, m);
      ASSERT_TRUE(f.ok);
      EXPECT_TRUE(f.converged);
      EXPECT_LE(f.iterations, 15);
      EXPECT_LT(angle_between(f.normal, n_true), 1e-3) << "method " << static_cast<int>(m);
      EXPECT_EQ(fraction_on_correct_side(c, f), 1.0);
    }
  }
}

/// Seed 004 Fig. 3C: a node at the corner of material alpha (lower-left cell only) with a full
/// edge of material beta (the whole upper row of cells); the lower-right cell is empty.
Cloud figure_3c_cloud(double h, const Vec3& node) {
  return lattice_cloud(2, h, node, [](const Vec3& r) {
    if (r.y() > 0) return 1;
    return r.x() < 0 ? -1 : 0;
  });
}

TEST(RegressionPlaneFit, Figure3CLogisticStaysHorizontalLinearTilts) {
  const double h = 1.0;
  const Vec3 node(2.0, 3.0, 0.0);
  const Cloud c = figure_3c_cloud(h, node);
  ASSERT_EQ(c.x.size(), 12u);
  PlaneFitOptions opt;
  const PlaneFit lin = fit(c, node, opt, PlaneFitMethod::linear);
  const PlaneFit lr = fit(c, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(lin.ok);
  ASSERT_TRUE(lr.ok);
  EXPECT_TRUE(lr.converged);
  EXPECT_LE(lr.iterations, 15);
  const double tilt_lin = angle_between(lin.normal, Vec3::UnitY());
  const double tilt_lr = angle_between(lr.normal, Vec3::UnitY());
  EXPECT_LT(tilt_lr, 5.0 * kPi / 180.0);
  EXPECT_LT(tilt_lr, tilt_lin);
  // The linear fit is visibly tilted (the seed's "still tilted in Fig. 3C"), toward +x since beta
  // extends to the right where alpha is absent.
  EXPECT_GT(tilt_lin, 5.0 * kPi / 180.0);
  EXPECT_GT(lin.normal.x(), 0.0);
  EXPECT_GT(lin.normal.y(), 0.0);
  EXPECT_EQ(fraction_on_correct_side(c, lr), 1.0);
}

TEST(RegressionPlaneFit, FirstLogisticIterateIsTheLinearRegression) {
  // Appendix: from phi^(0) = 0 the first Gauss-Newton step is the linear regression. Use the
  // Fig. 3C cloud, where the converged logistic normal differs from the linear one, so that a
  // comparison against the converged fit would fail.
  const double h = 0.25;
  const Vec3 node(1.0, 1.0, 0.0);
  const Cloud c = figure_3c_cloud(h, node);
  PlaneFitOptions opt;
  opt.cell_size = h;
  PlaneFitOptions one = opt;
  one.max_iterations = 1;

  const PlaneFit lin = fit(c, node, opt, PlaneFitMethod::linear);
  const PlaneFit first = fit(c, node, one, PlaneFitMethod::logistic);
  const PlaneFit full = fit(c, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(lin.ok && first.ok && full.ok);
  EXPECT_EQ(first.iterations, 1);
  EXPECT_FALSE(first.converged);
  EXPECT_EQ(lin.iterations, 1);
  // With the 1e-7 penalty the two differ only through the penalty (4 lambda vs lambda).
  EXPECT_LT(angle_between(first.normal, lin.normal), 1e-6);
  EXPECT_NEAR(first.offset, lin.offset, 1e-6 * h);
  EXPECT_GT(angle_between(full.normal, lin.normal), 1e-2);

  // Without penalty they are the same plane to round-off.
  opt.penalty = 0.0;
  one.penalty = 0.0;
  const PlaneFit lin0 = fit(c, node, opt, PlaneFitMethod::linear);
  const PlaneFit first0 = fit(c, node, one, PlaneFitMethod::logistic);
  ASSERT_TRUE(lin0.ok && first0.ok);
  EXPECT_LT(angle_between(first0.normal, lin0.normal), 1e-12);
  EXPECT_NEAR(first0.offset, lin0.offset, 1e-12);
}

/// Reference for Eq. 20-21 written independently of the implementation: dense N x K Jacobian
/// from central differences of the logistic f, dynamic-size Eigen, physical coordinates (no
/// centring or scaling), k updates from phi = 0.
Eigen::VectorXd reference_logistic(const Cloud& c, int dim, const Eigen::VectorXd& lambda, int k) {
  const int n = static_cast<int>(c.x.size()), kk = dim + 1;
  Eigen::MatrixXd X(n, kk);
  Eigen::VectorXd cls(n);
  for (int p = 0; p < n; ++p) {
    X.row(p).head(dim) = c.x[p].head(dim).transpose();
    X(p, dim) = 1.0;
    cls(p) = c.cls[p];
  }
  auto f = [](double z) { return 2.0 / (1.0 + std::exp(-z)) - 1.0; };
  Eigen::VectorXd phi = Eigen::VectorXd::Zero(kk);
  for (int it = 0; it < k; ++it) {
    Eigen::MatrixXd J(n, kk);
    Eigen::VectorXd r(n);
    for (int p = 0; p < n; ++p) {
      const double z = X.row(p).dot(phi), dz = 1e-6;
      J.row(p) = X.row(p) * (f(z + dz) - f(z - dz)) / (2.0 * dz);
      r(p) = cls(p) - f(z);
    }
    const Eigen::MatrixXd A = J.transpose() * J + Eigen::MatrixXd(lambda.asDiagonal());
    phi += A.ldlt().solve(J.transpose() * r - lambda.cwiseProduct(phi));
  }
  return phi;
}

TEST(RegressionPlaneFit, IteratesFollowEquation21) {
  // The Appendix penalty, and a large one so that every term of Eq. 21 (including -Lambda phi)
  // shows in the iterates.
  const double h = 0.5;
  const Vec3 node(1.0, 2.0, 0.0);
  const Cloud c = figure_3c_cloud(h, node);
  for (double penalty : {1e-7, 0.05}) {
    PlaneFitOptions opt;
    opt.cell_size = h;
    opt.penalty = penalty;
    opt.tolerance = 0.0;  // never stop early
    Eigen::VectorXd lambda(3);
    lambda << penalty * h * h, penalty * h * h, 0.0;  // Appendix: 1e-7 dx^2 (1, 1, 0)
    for (int k = 1; k <= 4; ++k) {
      opt.max_iterations = k;
      const PlaneFit f = fit(c, node, opt, PlaneFitMethod::logistic);
      ASSERT_TRUE(f.ok);
      ASSERT_EQ(f.iterations, k);
      // The reference works in physical units with lambda = penalty dx^2; Gauss-Newton is
      // invariant under the implementation's linear change of unknowns (centring and scaling),
      // so both must produce the same planes iterate by iterate.
      const Eigen::VectorXd ref = reference_logistic(c, 2, lambda, k);
      const double len = ref.head(2).norm();
      const Vec3 n_ref(ref(0) / len, ref(1) / len, 0.0);
      EXPECT_LT(angle_between(f.normal, n_ref), 1e-7) << "penalty " << penalty << " k " << k;
      EXPECT_NEAR(f.offset, ref(2) / len, 1e-7) << "penalty " << penalty << " k " << k;
    }
  }
}

TEST(RegressionPlaneFit, CenterAndCellSizeOnlyConditionTheFit) {
  const double h = 0.3;
  const Vec3 node(10.0, -20.0, 0.0);
  const Cloud c = figure_3c_cloud(h, node);
  PlaneFitOptions opt;
  opt.cell_size = h;
  const PlaneFit a = fit(c, node, opt, PlaneFitMethod::logistic);
  const PlaneFit b = fit(c, node + Vec3(0.4 * h, -0.3 * h, 0.0), opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(a.ok && b.ok);
  EXPECT_LT(angle_between(a.normal, b.normal), 1e-9);
  EXPECT_NEAR(a.offset, b.offset, 1e-9);

  // The same cloud in cell units with cell_size 1 (penalty 1e-7 dx^2 scales consistently).
  Cloud unit = c;
  for (auto& p : unit.x) p = (p - node) / h;
  PlaneFitOptions opt1;
  const PlaneFit u = fit(unit, Vec3::Zero(), opt1, PlaneFitMethod::logistic);
  ASSERT_TRUE(u.ok);
  EXPECT_LT(angle_between(a.normal, u.normal), 1e-9);
  EXPECT_EQ(a.iterations, u.iterations);
  // offset in cell units is the physical plane x.n + d = 0 moved to the node and scaled.
  EXPECT_NEAR(u.offset, (a.offset + node.dot(a.normal)) / h, 1e-9);
}

TEST(RegressionPlaneFit, SwappingClassesFlipsThePlane) {
  const Vec3 node(0.0, 0.0, 0.0);
  const double th = 30.0 * kPi / 180.0;
  Cloud c = tilted_cloud(2, 1.0, node, Vec3(std::sin(th), std::cos(th), 0.0));
  PlaneFitOptions opt;
  const PlaneFit a = fit(c, node, opt, PlaneFitMethod::logistic);
  for (auto& k : c.cls) k = static_cast<signed char>(-k);
  const PlaneFit b = fit(c, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(a.ok && b.ok);
  EXPECT_LT((a.normal + b.normal).norm(), 1e-9);
  EXPECT_NEAR(a.offset, -b.offset, 1e-9);
  EXPECT_EQ(fraction_on_correct_side(c, b), 1.0);
}

TEST(RegressionPlaneFit, ZeroWeightsEqualRemovedPoints) {
  const Vec3 node(0.0, 0.0, 0.0);
  // Full 16-point cloud with an interface on the grid line; drop the lower-right cell.
  const Cloud full = lattice_cloud(2, 1.0, node, [](const Vec3& r) { return r.y() > 0 ? 1 : -1; });
  const Cloud part = figure_3c_cloud(1.0, node);
  std::vector<double> w(full.x.size(), 1.0);
  for (std::size_t p = 0; p < full.x.size(); ++p) {
    const Vec3 r = full.x[p] - node;
    if (r.y() < 0 && r.x() > 0) w[p] = 0.0;
  }
  PlaneFitOptions opt;
  const PlaneFit a = fit_separating_plane(full.x, full.cls, w, node, opt, PlaneFitMethod::logistic);
  const PlaneFit b = fit(part, node, opt, PlaneFitMethod::logistic);
  const PlaneFit unweighted = fit(full, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(a.ok && b.ok && unweighted.ok);
  EXPECT_LT(angle_between(a.normal, b.normal), 1e-12);
  EXPECT_NEAR(a.offset, b.offset, 1e-12);
  EXPECT_EQ(a.iterations, b.iterations);
  // and the weights do change the answer compared with unit weights (the full cloud is exact).
  EXPECT_GT(angle_between(a.normal, unweighted.normal), 1e-6);
}

TEST(RegressionPlaneFit, WarmStartFromPreviousNormal) {
  const Vec3 node(0.0, 0.0, 0.0);
  const Cloud c = figure_3c_cloud(1.0, node);
  PlaneFitOptions opt;
  const PlaneFit cold = fit(c, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(cold.ok && cold.converged);
  // Restart from the converged normal: converges to nearly the same direction. Eq. 57 stops on
  // the change per step (~0.25 degrees for 1e-5) while the penalty-limited iterates still drift
  // slowly, so restarts from different points agree to about a degree, not to round-off.
  const PlaneFit warm = fit(c, node, opt, PlaneFitMethod::logistic, &cold.normal);
  ASSERT_TRUE(warm.ok);
  EXPECT_TRUE(warm.converged);
  EXPECT_LE(warm.iterations, 15);
  EXPECT_LT(angle_between(warm.normal, cold.normal), 2.0 * kPi / 180.0);
  EXPECT_LT(angle_between(warm.normal, Vec3::UnitY()), 5.0 * kPi / 180.0);
  EXPECT_EQ(fraction_on_correct_side(c, warm), 1.0);
  // From a poor guess (20 degrees off, not unit length) it still finds the plane.
  const double g = 20.0 * kPi / 180.0;
  const Vec3 guess = 3.0 * Vec3(-std::sin(g), std::cos(g), 0.0);
  const PlaneFit off = fit(c, node, opt, PlaneFitMethod::logistic, &guess);
  ASSERT_TRUE(off.ok);
  EXPECT_LT(angle_between(off.normal, Vec3::UnitY()), 5.0 * kPi / 180.0);
  // With a single update the warm start is exactly the guess direction (header contract), while
  // the cold first update is the tilted linear regression.
  PlaneFitOptions one = opt;
  one.max_iterations = 1;
  const PlaneFit w1 = fit(c, node, one, PlaneFitMethod::logistic, &guess);
  ASSERT_TRUE(w1.ok);
  EXPECT_LT(angle_between(w1.normal, guess), 1e-14);
  EXPECT_GT(angle_between(fit(c, node, one, PlaneFitMethod::logistic).normal, guess), 0.1);
  // A zero guess is ignored.
  const Vec3 zero = Vec3::Zero();
  const PlaneFit z = fit(c, node, opt, PlaneFitMethod::logistic, &zero);
  ASSERT_TRUE(z.ok);
  EXPECT_EQ(z.normal, cold.normal);
  EXPECT_EQ(z.iterations, cold.iterations);
}

TEST(RegressionPlaneFit, NonConvergenceReturnsLastIterate) {
  const Cloud c = figure_3c_cloud(1.0, Vec3::Zero());
  PlaneFitOptions opt;
  opt.max_iterations = 2;
  opt.tolerance = 0.0;  // unreachable
  const PlaneFit f = fit(c, Vec3::Zero(), opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(f.ok);
  EXPECT_FALSE(f.converged);
  EXPECT_EQ(f.iterations, 2);
  EXPECT_NEAR(f.normal.norm(), 1.0, 1e-14);
}

TEST(RegressionPlaneFit, OneClassOrBadInputIsNotOk) {
  const Vec3 node(0.0, 0.0, 0.0);
  const Cloud alpha_only = lattice_cloud(2, 1.0, node, [](const Vec3&) { return -1; });
  const Cloud beta_only = lattice_cloud(2, 1.0, node, [](const Vec3&) { return 1; });
  PlaneFitOptions opt;
  for (auto m : {PlaneFitMethod::linear, PlaneFitMethod::logistic}) {
    for (const Cloud* c : {&alpha_only, &beta_only}) {
      const PlaneFit f = fit(*c, node, opt, m);
      EXPECT_FALSE(f.ok);
      EXPECT_EQ(f.normal, Vec3::Zero());
    }
  }
  // Both classes present but one has zero total weight.
  const Cloud c = lattice_cloud(2, 1.0, node, [](const Vec3& r) { return r.y() > 0 ? 1 : -1; });
  std::vector<double> w(c.x.size(), 1.0);
  for (std::size_t p = 0; p < c.x.size(); ++p)
    if (c.cls[p] > 0) w[p] = 0.0;
  EXPECT_FALSE(fit_separating_plane(c.x, c.cls, w, node, opt, PlaneFitMethod::logistic).ok);
  // Mismatched lengths and an invalid dimension.
  std::vector<signed char> short_cls(c.cls.begin(), c.cls.end() - 1);
  EXPECT_FALSE(fit_separating_plane(c.x, short_cls, {}, node, opt, PlaneFitMethod::logistic).ok);
  PlaneFitOptions bad = opt;
  bad.dim = 4;
  EXPECT_FALSE(fit(c, node, bad, PlaneFitMethod::logistic).ok);
  // Sanity: the same cloud with both classes and unit weights is fine.
  EXPECT_TRUE(fit(c, node, opt, PlaneFitMethod::logistic).ok);

  // All points on the line x = 0.5: without penalty the x column equals 0.5 times the offset
  // column and the normal system is singular; the Appendix penalty regularises it.
  Cloud line;
  for (double y : {-0.75, -0.25}) line.add(Vec3(0.5, y, 0.0), -1);
  for (double y : {0.25, 0.75}) line.add(Vec3(0.5, y, 0.0), 1);
  PlaneFitOptions no_penalty = opt;
  no_penalty.penalty = 0.0;
  no_penalty.flat_extent = 0.0;  // the flat-cloud guard would regularise it too
  for (auto m : {PlaneFitMethod::linear, PlaneFitMethod::logistic})
    EXPECT_FALSE(fit(line, node, no_penalty, m).ok);
  const PlaneFit reg = fit(line, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(reg.ok);
  EXPECT_LT(angle_between(reg.normal, Vec3::UnitY()), 1e-3);
  PlaneFitOptions guard_only = no_penalty;
  guard_only.flat_extent = 0.03;
  EXPECT_TRUE(fit(line, node, guard_only, PlaneFitMethod::logistic).ok);
}

TEST(RegressionPlaneFit, FlatCloudGuardKeepsTheNormalAlongTheRow) {
  // One row of particles next to a node beyond a body's edge (the row y ~ 1.25 cells), alpha on
  // the left and beta on the right, with 1e-3-cell position noise that happens to correlate with
  // the class. The normal must be along the row (x), not across it.
  Cloud row;
  const double xs[] = {-1.186, -0.686, -0.187, 0.298, 0.772, 1.228};
  const double ys[] = {1.24994, 1.24973, 1.2494, 1.24908, 1.24878, 1.24878};
  for (int k = 0; k < 6; ++k) row.add(Vec3(xs[k], ys[k], 0.0), k < 5 ? -1 : 1);
  PlaneFitOptions opt;
  opt.dim = 2;
  const Vec3 node = Vec3::Zero();
  const PlaneFit guarded = fit(row, node, opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(guarded.ok);
  EXPECT_LT(angle_between(guarded.normal, Vec3::UnitX()), 0.05);
  PlaneFitOptions off = opt;
  off.flat_extent = 0.0;
  const PlaneFit unguarded = fit(row, node, off, PlaneFitMethod::logistic);
  EXPECT_GT(angle_between(unguarded.normal, Vec3::UnitX()), 0.5);  // what the guard prevents
}

TEST(RegressionPlaneFit, OneDimensionalFit) {
  Cloud c;
  for (double x : {-0.75, -0.25}) c.add(Vec3(x, 5.0, 1.0), -1);
  for (double x : {0.25, 0.75, 1.25}) c.add(Vec3(x, -3.0, 2.0), 1);
  PlaneFitOptions opt;
  opt.dim = 1;
  const PlaneFit f = fit(c, Vec3::Zero(), opt, PlaneFitMethod::logistic);
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.normal, Vec3::UnitX());
  EXPECT_EQ(fraction_on_correct_side(c, f), 1.0);
}

TEST(RegressionDeformedRadius, IdentityGivesUndeformedSemiAxes) {
  const Vec3 r0(0.3, 0.2, 0.1);
  const Mat3 I = Mat3::Identity();
  EXPECT_NEAR(deformed_radius(I, r0, Vec3::UnitX(), 3), 0.3, 1e-15);
  EXPECT_NEAR(deformed_radius(I, r0, Vec3::UnitY(), 3), 0.2, 1e-15);
  EXPECT_NEAR(deformed_radius(I, r0, Vec3::UnitZ(), 3), 0.1, 1e-15);
  EXPECT_NEAR(deformed_radius(I, r0, -Vec3::UnitY(), 2), 0.2, 1e-15);
  // Off-axis direction of the 2D ellipse: 1/R^2 = cos^2/a^2 + sin^2/b^2.
  const double t = 0.4;
  const Vec3 n(std::cos(t), std::sin(t), 0.0);
  const double expect =
      1.0 / std::sqrt(std::pow(std::cos(t) / 0.3, 2) + std::pow(std::sin(t) / 0.2, 2));
  EXPECT_NEAR(deformed_radius(I, Vec3(0.3, 0.2, 1.0), n, 2), expect, 1e-15);
  // 1D: only the x semi-axis.
  EXPECT_NEAR(deformed_radius(I, r0, Vec3::UnitX(), 1), 0.3, 1e-15);
}

TEST(RegressionDeformedRadius, UniaxialStretch) {
  const Vec3 r0(0.25, 0.5, 0.125);
  const Mat3 F = Vec3(2.0, 1.0, 1.0).asDiagonal();
  EXPECT_NEAR(deformed_radius(F, r0, Vec3::UnitX(), 3), 0.5, 1e-15);
  EXPECT_NEAR(deformed_radius(F, r0, Vec3::UnitY(), 3), 0.5, 1e-15);
  EXPECT_NEAR(deformed_radius(F, r0, Vec3::UnitZ(), 3), 0.125, 1e-15);
  EXPECT_NEAR(deformed_radius(F, Vec3(0.25, 0.5, 1.0), Vec3::UnitX(), 2), 0.5, 1e-15);
}

TEST(RegressionDeformedRadius, RotationKeepsACircleAndCarriesAnEllipse) {
  const double a = 0.7;
  Mat3 Q = Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix();
  for (double t : {0.0, 0.3, 1.1, 2.5, -0.8}) {
    const Vec3 n(std::cos(t), std::sin(t), 0.0);
    EXPECT_NEAR(deformed_radius(Q, Vec3(0.4, 0.4, 1.0), n, 2), 0.4, 1e-15);
  }
  // A rotated ellipse: the direction of the rotated x semi-axis sees R0x, the rotated y sees R0y.
  EXPECT_NEAR(deformed_radius(Q, Vec3(0.4, 0.1, 1.0), Q * Vec3::UnitX(), 2), 0.4, 1e-15);
  EXPECT_NEAR(deformed_radius(Q, Vec3(0.4, 0.1, 1.0), Q * Vec3::UnitY(), 2), 0.1, 1e-15);
  // Sphere in 3D under a general rotation.
  const Mat3 Q3 = Eigen::AngleAxisd(1.2, Vec3(1.0, -2.0, 0.5).normalized()).toRotationMatrix();
  EXPECT_NEAR(deformed_radius(Q3, Vec3(0.3, 0.3, 0.3), Vec3(1, 2, 3).normalized(), 3), 0.3, 1e-15);
}

TEST(RegressionDeformedRadius, CubeSimplification) {
  Mat3 F;
  F << 1.2, 0.3, -0.1, 0.05, 0.9, 0.2, 0.1, -0.15, 1.1;
  const Vec3 n = Vec3(0.3, -0.5, 0.8).normalized();
  const double r0 = 0.25;
  const double expect = r0 / (F.inverse() * n).norm();
  EXPECT_NEAR(deformed_radius(F, Vec3::Constant(r0), n, 3), expect, 1e-15);
  // ... and differs from the undeformed radius (so the check is not trivially r0).
  EXPECT_GT(std::abs(expect - r0), 1e-3);

  // 2D square with an in-plane F: the out-of-plane stretch F(2,2) does not enter.
  Mat3 F2 = Mat3::Identity();
  F2.topLeftCorner<2, 2>() << 1.1, 0.3, 0.1, 0.9;
  const Vec3 n2 = Vec3(0.6, 0.8, 0.0);
  const double expect2 = r0 / (F2.inverse() * n2).head<2>().norm();
  const double got = deformed_radius(F2, Vec3(r0, r0, 1.0), n2, 2);
  EXPECT_NEAR(got, expect2, 1e-15);
  F2(2, 2) = 1.7;
  EXPECT_NEAR(deformed_radius(F2, Vec3(r0, r0, 1.0), n2, 2), got, 1e-15);
}

TEST(RegressionDeformedRadius, OnlyTheFirstDimComponentsOfN0Enter) {
  // Contract check with an F that couples x into z (not a physical 2D F): n0 = F^{-1} e_x has a z
  // part, which must be ignored for dim < 3.
  Mat3 F = Mat3::Identity();
  F(2, 0) = 0.5;
  F(1, 0) = 0.25;
  const Vec3 r0(0.2, 0.3, 0.05);
  const Vec3 n0 = F.inverse() * Vec3::UnitX();
  ASSERT_GT(std::abs(n0.z()), 0.1);
  ASSERT_GT(std::abs(n0.y()), 0.1);
  EXPECT_NEAR(deformed_radius(F, r0, Vec3::UnitX(), 1), r0.x() / std::abs(n0.x()), 1e-15);
  const double r2 = 1.0 / std::sqrt(std::pow(n0.x() / r0.x(), 2) + std::pow(n0.y() / r0.y(), 2));
  EXPECT_NEAR(deformed_radius(F, r0, Vec3::UnitX(), 2), r2, 1e-15);
  const double r3 = 1.0 / std::sqrt(std::pow(n0.x() / r0.x(), 2) + std::pow(n0.y() / r0.y(), 2) +
                                    std::pow(n0.z() / r0.z(), 2));
  EXPECT_NEAR(deformed_radius(F, r0, Vec3::UnitX(), 3), r3, 1e-15);
}


// ---- Flat interfaces through particle lattices (docs/contact.md, "Flat interfaces") ----------

/// A floor (class -1, y < 0) and a block (class +1, y > 0) filled with 2-per-cell lattices
/// (spacing 0.5 cells), the block's lattice shifted by `s` cells along the interface and its rear
/// face at x = `rear` (-inf: no face). The cloud of the node at (xn, 0) holds the particles within
/// `support` cells of it along both axes (the particles whose stencil holds the node); w holds
/// the node's linear hat at each particle (a shape-function weight S_ip).
struct FlatCloud : Cloud {
  std::vector<double> w;
};
FlatCloud flat_cloud(double s, double xn, double rear, double support) {
  FlatCloud c;
  auto add = [&](const Vec3& p, int cls) {
    const Vec3 d = p - Vec3(xn, 0.0, 0.0);
    if (std::abs(d.x()) >= support || std::abs(d.y()) >= support) return;
    c.add(p, cls);
    c.w.push_back(std::max(0.0, 1.0 - std::abs(d.x())) * std::max(0.0, 1.0 - std::abs(d.y())));
  };
  for (int i = -20; i < 20; ++i)
    for (int j = 0; j < 4; ++j) {
      add(Vec3(0.25 + 0.5 * i, -0.25 - 0.5 * j, 0.0), -1);
      const Vec3 b(s + 0.25 + 0.5 * i, 0.25 + 0.5 * j, 0.0);
      if (b.x() > rear) add(b, +1);
    }
  return c;
}

double tilt(const Vec3& n) { return std::atan2(n.x(), n.y()); }

TEST(RegressionFlatInterface, UniformLogisticFitTiltsWithTheLatticeOffset) {
  // The finite-scale logistic fit with w_p = 1 turns the normal toward the class whose points
  // stand off-centre along the interface: a tilt of milliradians that changes sign with the
  // offset, also when converged far beyond the Eq. 57 tolerance.
  PlaneFitOptions opt, tight;
  opt.dim = tight.dim = 2;
  tight.tolerance = 1e-15;
  tight.max_iterations = 200;
  double worst = 0.0, worst_tight = 0.0;
  for (int k = 1; k < 10; ++k) {
    const FlatCloud c = flat_cloud(0.05 * k, 0.0, -1e9, 1.5);
    worst = std::max(worst, std::abs(tilt(fit(c, Vec3::Zero(), opt, PlaneFitMethod::logistic).normal)));
    worst_tight = std::max(worst_tight, std::abs(tilt(fit(c, Vec3::Zero(), tight, PlaneFitMethod::logistic).normal)));
  }
  EXPECT_GT(worst, 3e-3);
  EXPECT_GT(worst_tight, 1e-3);
}

TEST(RegressionFlatInterface, ShapeWeightsMakeTheInteriorNormalExact) {
  // With w_p = N_i(X_p), a B-spline of the grid whose width is a multiple of the particle
  // spacing, every row of a class has its weighted centroid on the node: the fit's tangential
  // gradient vanishes at a level normal, for any lattice offset.
  PlaneFitOptions opt;
  opt.dim = 2;
  for (auto m : {PlaneFitMethod::linear, PlaneFitMethod::logistic})
    for (int k = 0; k < 10; ++k) {
      const FlatCloud c = flat_cloud(0.05 * k, 0.0, -1e9, 1.25);
      const PlaneFit f = fit_separating_plane(c.x, c.cls, c.w, Vec3::Zero(), opt, m);
      ASSERT_TRUE(f.ok);
      EXPECT_LT(std::abs(tilt(f.normal)), 1e-12) << "offset " << 0.05 * k;
    }
}

TEST(RegressionFlatInterface, MaxMarginIsExactInsideAndAtACorner) {
  for (double rear : {-1e9, 0.0, -0.5, -1.0})
    for (int k = 0; k < 10; ++k) {
      const FlatCloud c = flat_cloud(0.05 * k, 0.0, rear, 1.5);
      const MarginFit m = max_margin_plane(c.x, c.cls, 2);
      ASSERT_TRUE(m.ok);
      EXPECT_LT(std::abs(tilt(m.normal)), 1e-12) << "rear " << rear << " offset " << 0.05 * k;
      EXPECT_NEAR(m.gap, 0.5, 1e-12);
    }
  // At the block's rear corner the logistic fit (either weighting) tilts by tens of mrad.
  const FlatCloud c = flat_cloud(0.1, 0.0, 0.0, 1.5);
  PlaneFitOptions opt;
  opt.dim = 2;
  EXPECT_GT(std::abs(tilt(fit(c, Vec3::Zero(), opt, PlaneFitMethod::logistic).normal)), 1e-2);
}

TEST(RegressionMaxMargin, TiltedPlanesAndThreeDimensions) {
  const double th = 30.0 * kPi / 180.0;
  const Vec3 n2(std::sin(th), std::cos(th), 0.0);
  const Cloud c2 = tilted_cloud(2, 1.5, Vec3(3.0, -1.5, 0.0), n2);
  const MarginFit m2 = max_margin_plane(c2.x, c2.cls, 2);
  ASSERT_TRUE(m2.ok);
  EXPECT_LT(angle_between(m2.normal, n2), 1e-12);
  EXPECT_NEAR(m2.gap, 2.0 * 0.25 * 1.5, 1e-12);
  const Vec3 n3 = Vec3(0.3, -0.5, 0.8).normalized();
  const Cloud c3 = tilted_cloud(3, 0.7, Vec3(0.2, 0.1, -0.4), n3);
  const MarginFit m3 = max_margin_plane(c3.x, c3.cls, 3);
  ASSERT_TRUE(m3.ok);
  EXPECT_LT(angle_between(m3.normal, n3), 1e-12);
  // Swapping the classes flips the normal.
  Cloud swapped = c3;
  for (auto& k : swapped.cls) k = static_cast<signed char>(-k);
  EXPECT_LT(angle_between(max_margin_plane(swapped.x, swapped.cls, 3).normal, -n3), 1e-12);
}

TEST(RegressionMaxMargin, OverlappingOrOneClassCloudsAreNotSeparable) {
  // Interleaved classes: a checkerboard has no separating plane.
  const Cloud board = lattice_cloud(2, 1.0, Vec3::Zero(), [](const Vec3& r) {
    return (static_cast<int>(std::floor(2 * r.x())) + static_cast<int>(std::floor(2 * r.y()))) % 2 == 0 ? 1 : -1;
  });
  EXPECT_FALSE(max_margin_plane(board.x, board.cls, 2).ok);
  // One point of beta inside alpha's hull.
  Cloud inside = lattice_cloud(2, 1.0, Vec3::Zero(), [](const Vec3&) { return -1; });
  inside.add(Vec3(0.01, 0.02, 0.0), +1);
  EXPECT_FALSE(max_margin_plane(inside.x, inside.cls, 2).ok);
  const Cloud one = lattice_cloud(2, 1.0, Vec3::Zero(), [](const Vec3&) { return 1; });
  EXPECT_FALSE(max_margin_plane(one.x, one.cls, 2).ok);
  // Touching hulls (a shared point) have no gap either.
  Cloud touch;
  touch.add(Vec3(0, 0, 0), -1);
  touch.add(Vec3(1, 0, 0), -1);
  touch.add(Vec3(1, 0, 0), +1);
  touch.add(Vec3(2, 1, 0), +1);
  EXPECT_FALSE(max_margin_plane(touch.x, touch.cls, 2).ok);
}

}  // namespace
}  // namespace cairn::contact
