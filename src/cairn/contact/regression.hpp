// Point-cloud plane fits for multimaterial contact: the logistic-regression (LR) method of
// seed 004 (../shared/seeds/004_29fd5dcef9cf8d62.txt) Sec. 3.1, Eq. 19-21 with the
// implementation details of its Appendix, Eq. 53-57, plus the deformed particle radius of
// Eq. 25 used to measure material separation along the fitted normal (Eq. 22-24).
//
// A contact node collects the material points around it into a cloud with classes c_p = -1
// (material alpha) and c_p = +1 (material beta). The fit looks for the plane x.phi = 0 with the
// augmented position x = (X, 1) (Eq. 19) that best separates the two classes: phi_1..3 is a
// normal pointing from alpha toward beta and phi_4 an offset.
#pragma once

#include <span>

#include "cairn/math/types.hpp"

namespace cairn::contact {

/// Model fitted to the classes. `linear`: f(x, phi) = x.phi, one penalised linear least-squares
/// solve (the "linear regression" of the seed 004 Appendix). `logistic`: the scaled logistic
/// f(x, phi) = 2/(1 + exp(-x.phi)) - 1 of Eq. 20, solved by Gauss-Newton iterations (Eq. 21).
enum class PlaneFitMethod { linear, logistic };

struct PlaneFitOptions {
  int dim = 2;              // 1, 2 or 3: components used (2D drops z, phi_3, lambda_3)
  double cell_size = 1.0;   // dx: penalty lambda = 1e-7 dx^2 (1,1,1,0) (Appendix)
  double penalty = 1e-7;    // the 1e-7 factor
  /// Flat-cloud guard: directions along which the cloud's standard deviation is below this many
  /// cells get a unit-extent penalty (0 = off; see regression.cpp). Not in seed 004.
  double flat_extent = 0.03;
  double tolerance = 1e-5;  // stop when 1 - n_k.n_{k+1} < tolerance (Eq. 57)
  int max_iterations = 15;
};

struct PlaneFit {
  // Unit normal pointing from class -1 (material alpha) toward class +1 (beta); zero if it failed.
  Vec3 normal = Vec3::Zero();
  double offset = 0.0;     // phi_4 / |n| : plane is x.normal + offset = 0
  int iterations = 0;      // Gauss-Newton updates performed (1 for `linear`)
  bool converged = false;  // Eq. 57 met (always true for a successful `linear` fit)
  bool ok = false;         // false when the cloud lacks a class or the system is singular
};

/// Fit the plane separating the two material classes of a point cloud.
///
/// x: positions (only the first opt.dim components matter); cls: class per point, negative =
/// alpha (c = -1), positive = beta (c = +1), zero = point ignored; w: weights w_p (empty = all 1,
/// the Appendix's recommendation; otherwise the same length as x). Mismatched lengths give ok =
/// false.
///
/// Conditioning: the fit works in the local coordinates u = (x - center) / cell_size, where
/// `center` is a point near the cloud (the contact node). This changes neither the plane nor the
/// objective, only how phi is expressed: phi_n(physical) = phi_n(u) / dx and phi_4 shifts by
/// -center.phi_n. The Appendix penalty lambda = 1e-7 dx^2 on the normal components in physical
/// units is therefore exactly lambda = 1e-7 (opt.penalty) in cell units, and 0 on the offset.
/// The returned normal/offset are converted back to physical coordinates. A non-positive
/// cell_size is treated as 1.
///
/// Logistic iterations start from phi^(0) = 0, whose first Gauss-Newton step is the linear
/// regression (Appendix), and stop when 1 - n^(k).n^(k+1) < tolerance (Eq. 57) or after
/// max_iterations updates (the first update counts), returning the last iterate (converged =
/// false) in that case. If a later Gauss-Newton system turns singular the last good iterate is
/// returned the same way; only a failure of the first solve gives ok = false.
///
/// Warm start (optional, `logistic` only): the Appendix suggests reusing the previous step's
/// normal as the initial guess. With `initial_normal` (any length, from alpha toward beta), the
/// first update is still the Gauss-Newton step from phi = 0 (the linear regression up to scale),
/// used only to set the scale |phi_n| of the logistic; phi^(1) is then replaced by that scale times
/// the given direction, with the offset that best fits the classes along it (a one-unknown
/// least-squares fit), and the Gauss-Newton iterations continue from there, checking Eq. 57 against
/// the given direction. A zero or non-finite initial_normal is ignored. On the test clouds this
/// warm start lands within about a degree of the cold fit but does not reliably save iterations:
/// the logistic scale |phi_n| still has to grow from the linear one, which a normal alone cannot
/// carry over (a larger start scale made the iterations unstable in trials).
PlaneFit fit_separating_plane(std::span<const Vec3> x, std::span<const signed char> cls,
                              std::span<const double> w, const Vec3& center,
                              const PlaneFitOptions& opt, PlaneFitMethod method,
                              const Vec3* initial_normal = nullptr);

/// The maximum-margin (hard support-vector) separation of the two classes of a point cloud:
/// the plane that separates them with the widest gap, the limit that the logistic fit of seed
/// 004 Sec. 3.1 approaches as its scale grows without bound ("an alternate approach to obtain
/// nearly the same results as an SVM"). Its normal is along the shortest vector from the convex
/// hull of class -1 to that of class +1 (Gilbert's algorithm on the difference set; exact and
/// finite for point sets). Only the first `dim` components of x matter.
struct MarginFit {
  Vec3 normal = Vec3::Zero();  // unit, from class -1 (alpha) toward class +1 (beta)
  double gap = 0.0;            // distance between the two hulls along normal (> 0 when ok)
  int iterations = 0;
  bool ok = false;             // false when the hulls touch or overlap, or a class is missing
};
MarginFit max_margin_plane(std::span<const Vec3> x, std::span<const signed char> cls, int dim);

/// Distance from a particle centre to its deformed inscribed ellipsoid along the unit vector n
/// (seed 004 Eq. 25): n0 = F^{-1} n and 1/R = sqrt(sum_a n0_a^2 / R0_a^2), where R0 holds the
/// undeformed semi-axes (half the particle edge lengths). Only the first `dim` components of n0
/// enter the sum: in 2D pass R0.z = 1 (unused) and the 3x3 F whose F(2,2) is the out-of-plane
/// stretch (with an in-plane F the in-plane part of n0 does not depend on it); in 1D only the x
/// semi-axis counts. For equal semi-axes (cubes, squares) this reduces to R = R0 / |n0|.
/// Returns +infinity when n0 has no in-plane part (n = 0).
double deformed_radius(const Mat3& F, const Vec3& R0, const Vec3& n, int dim);

}  // namespace cairn::contact
