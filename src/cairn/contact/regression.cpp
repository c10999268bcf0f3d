// Logistic / linear regression plane fits of seed 004 (../shared/seeds/004_29fd5dcef9cf8d62.txt)
// Sec. 3.1 and Appendix; see regression.hpp for the contract.
//
// Notation (cell units, see the header): u_p = ((X_p - center) / dx, 1) is the augmented position
// of Eq. 19, phi = (phi_n, phi_4). For the logistic model the Gauss-Newton update of Eq. 21 is
//   phi <- phi + (J^T W J + Lambda)^{-1} (J^T W (c - f) - Lambda phi)
// with J_pj = psi(u_p) u_pj and psi = 2 e^{-z} / (1 + e^{-z})^2, z = u_p.phi (Eq. 53), so that
//   (J^T W J + Lambda)_kl = lambda_k delta_kl + sum_p psi_p^2 w_p u_pk u_pl         (Eq. 54-55)
//   (J^T W (c - f) - Lambda phi)_j = -lambda_j phi_j + sum_p psi_p w_p (c_p - f_p) u_pj (Eq. 56).
// At phi = 0: f = 0 and psi = 1/2, so the first update is
//   phi^(1) = 2 (U^T W U + 4 Lambda)^{-1} U^T W c,
// i.e. the linear regression phi_lin = (U^T W U + Lambda)^{-1} U^T W c up to the factor 2 and a
// fourfold penalty: with the Appendix penalty (1e-7 in cell units) the two directions agree to
// ~1e-7, and exactly without penalty (the Appendix's "first iteration is equivalent to linear
// regression"). The iterations are templated on the dimension so that every matrix is a fixed
// (D+1)x(D+1) Eigen object: no heap allocation inside a fit.
#include "cairn/contact/regression.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <utility>
#include <limits>

#include <Eigen/Eigenvalues>

namespace cairn::contact {
namespace {

/// Smallest LDLT pivot, relative to the largest, for which a normal matrix counts as regular.
constexpr double kMinPivotRatio = 1e-14;

template <int D>
struct Fitter {
  static constexpr int K = D + 1;
  using VecK = Eigen::Matrix<double, K, 1>;
  using MatK = Eigen::Matrix<double, K, K>;

  std::span<const Vec3> x;
  std::span<const signed char> cls;
  std::span<const double> w;
  Vec3 center;
  double inv_h = 1.0;
  MatK lambda;  // Lambda in cell units: diag(penalty, ..., penalty, 0) plus the flat-cloud guard

  VecK local(std::size_t p) const {
    VecK u;
    u.template head<D>() = (x[p].template head<D>() - center.template head<D>()) * inv_h;
    u(D) = 1.0;
    return u;
  }
  double weight(std::size_t p) const { return w.empty() ? 1.0 : w[p]; }

  /// Solve a (D+1) normal system by LDLT; false when (numerically) singular.
  static bool solve(const MatK& a, const VecK& b, VecK& out) {
    const Eigen::LDLT<MatK> ldlt(a);
    if (ldlt.info() != Eigen::Success) return false;
    // Cheap singularity test on the pivots (the normal matrix is symmetric positive
    // semi-definite): the smallest pivot must be positive and not negligible next to the largest.
    const VecK d = ldlt.vectorD();
    if (!(d.minCoeff() > kMinPivotRatio * d.cwiseAbs().maxCoeff())) return false;
    out = ldlt.solve(b);
    return out.allFinite();
  }

  /// Linear least squares with f = u.phi: (U^T W U + Lambda) phi = U^T W c (Appendix).
  bool linear(VecK& phi) const {
    MatK a = lambda;
    VecK b = VecK::Zero();
    for (std::size_t p = 0; p < x.size(); ++p) {
      if (cls[p] == 0) continue;
      const double c = cls[p] > 0 ? 1.0 : -1.0;
      const VecK u = local(p);
      const double wp = weight(p);
      a.noalias() += (wp * u) * u.transpose();
      b += (wp * c) * u;
    }
    return solve(a, b, phi);
  }

  /// One Gauss-Newton update of the logistic model (Eq. 21 with Eq. 53-56), in place.
  bool gauss_newton(VecK& phi) const {
    MatK a = lambda;
    VecK b = -(lambda * phi);
    for (std::size_t p = 0; p < x.size(); ++p) {
      if (cls[p] == 0) continue;
      const double c = cls[p] > 0 ? 1.0 : -1.0;
      const VecK u = local(p);
      const double wp = weight(p);
      // Overflow-free logistic: with e = exp(-|z|) in (0, 1],
      //   f = sign(z) (1 - e) / (1 + e),  psi = 2 e / (1 + e)^2 (psi is even in z).
      // exp only sees non-positive arguments, so nothing can overflow; for |z| > ~745 e
      // underflows to 0, giving f = +-1 and psi = 0 exactly as in the limit.
      const double z = u.dot(phi);
      const double e = std::exp(-std::abs(z));
      const double f = std::copysign((1.0 - e) / (1.0 + e), z);
      const double psi = 2.0 * e / ((1.0 + e) * (1.0 + e));
      a.noalias() += ((psi * psi * wp) * u) * u.transpose();
      b += (psi * wp * (c - f)) * u;
    }
    VecK step;
    if (!solve(a, b, step)) return false;
    phi += step;
    return true;
  }

  /// Unit normal part of phi (zero vector when phi_n = 0).
  static Eigen::Matrix<double, D, 1> unit_normal(const VecK& phi) {
    const double n = phi.template head<D>().norm();
    if (!(n > 0.0) || !std::isfinite(n)) return Eigen::Matrix<double, D, 1>::Zero();
    return phi.template head<D>() / n;
  }
};

template <int D>
PlaneFit fit_impl(std::span<const Vec3> x, std::span<const signed char> cls,
                  std::span<const double> w, const Vec3& center, const PlaneFitOptions& opt,
                  PlaneFitMethod method, const Vec3* initial_normal) {
  using F = Fitter<D>;
  using VecK = typename F::VecK;
  PlaneFit out;

  const double h = opt.cell_size > 0.0 ? opt.cell_size : 1.0;  // guard: non-positive -> 1
  F fit{x, cls, w, center, 1.0 / h, F::MatK::Zero()};

  // Both classes must be present (with positive total weight), or there is nothing to separate.
  double w_alpha = 0.0, w_beta = 0.0;
  for (std::size_t p = 0; p < x.size(); ++p) {
    if (cls[p] < 0) w_alpha += fit.weight(p);
    if (cls[p] > 0) w_beta += fit.weight(p);
  }
  if (!(w_alpha > 0.0) || !(w_beta > 0.0)) return out;
  // lambda = penalty dx^2 (1,1,1,0) in physical units is penalty (1,1,1,0) in cell units, because
  // phi_n(cell) = dx phi_n(physical) (see the header).
  fit.lambda.diagonal().template head<D>().setConstant(opt.penalty);
  // Flat-cloud guard (Cairn's addition, docs/contact.md): a cloud with (almost) no extent along
  // some direction e -- one row of particles next to a node beyond a body's edge -- carries no
  // information about the normal component along e, yet with the Appendix penalty alone the
  // fit would turn the normal along e to separate the classes by tiny position differences.
  // Directions whose weighted variance is below opt.flat_extent^2 (cell units) get the penalty
  // (sum w) e e^T on the normal components, as if the cloud spread one cell that way.
  if (opt.flat_extent > 0.0) {
    Eigen::Matrix<double, D, 1> mean = Eigen::Matrix<double, D, 1>::Zero();
    double sw = 0.0;
    for (std::size_t p = 0; p < x.size(); ++p) {
      if (cls[p] == 0) continue;
      mean += fit.weight(p) * fit.local(p).template head<D>();
      sw += fit.weight(p);
    }
    mean /= sw;
    Eigen::Matrix<double, D, D> cov = Eigen::Matrix<double, D, D>::Zero();
    for (std::size_t p = 0; p < x.size(); ++p) {
      if (cls[p] == 0) continue;
      const Eigen::Matrix<double, D, 1> d = fit.local(p).template head<D>() - mean;
      cov.noalias() += fit.weight(p) * d * d.transpose();
    }
    cov /= sw;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> eig(cov);
    for (int k = 0; k < D; ++k)
      if (eig.eigenvalues()(k) < opt.flat_extent * opt.flat_extent) {
        const Eigen::Matrix<double, D, 1> e = eig.eigenvectors().col(k);
        fit.lambda.template topLeftCorner<D, D>().noalias() += sw * e * e.transpose();
      }
  }

  VecK phi = VecK::Zero();
  // `linear`: one solve. `logistic`: the first Gauss-Newton step from phi^(0) = 0, which is the
  // linear regression up to scale (Appendix; see the top of this file). It is run as a logistic
  // step so that the iterates follow Eq. 21 exactly.
  const bool first_ok = method == PlaneFitMethod::linear ? fit.linear(phi) : fit.gauss_newton(phi);
  if (!first_ok) return out;
  Eigen::Matrix<double, D, 1> n_prev = F::unit_normal(phi);
  if (n_prev.isZero(0.0)) return out;
  int iterations = 1;
  bool converged = method == PlaneFitMethod::linear;

  if (method == PlaneFitMethod::logistic) {
    if (initial_normal != nullptr) {
      const Eigen::Matrix<double, D, 1> n0 = initial_normal->template head<D>();
      const double len = n0.norm();
      if (len > 0.0 && std::isfinite(len)) {
        // Warm start: keep the scale |phi_n| of the first step, take the given direction, and
        // the offset minimising sum_p w_p (m u_p.n0 + phi_4 - c_p)^2 along it.
        const double m = phi.template head<D>().norm();
        const Eigen::Matrix<double, D, 1> dir = n0 / len;
        double num = 0.0, den = 0.0;
        for (std::size_t p = 0; p < x.size(); ++p) {
          if (cls[p] == 0) continue;
          const double wp = fit.weight(p);
          const double c = cls[p] > 0 ? 1.0 : -1.0;
          num += wp * (c - m * fit.local(p).template head<D>().dot(dir));
          den += wp;
        }
        phi.template head<D>() = m * dir;
        phi(D) = num / den;
        n_prev = dir;
      }
    }

    const int max_it = opt.max_iterations > 0 ? opt.max_iterations : 1;
    while (iterations < max_it) {
      VecK next = phi;
      if (!fit.gauss_newton(next)) break;  // keep the last good iterate
      const Eigen::Matrix<double, D, 1> n_next = F::unit_normal(next);
      if (n_next.isZero(0.0)) break;
      phi = next;
      ++iterations;
      const double change = 1.0 - n_prev.dot(n_next);  // Eq. 57
      n_prev = n_next;
      if (change < opt.tolerance) {
        converged = true;
        break;
      }
    }
  }

  // Back to physical coordinates: the plane u.phi_n + phi_4 = 0 with u = (x - center)/dx is
  // (x - center).n_hat + phi_4 dx / |phi_n| = 0.
  const double len = phi.template head<D>().norm();
  out.normal.template head<D>() = phi.template head<D>() / len;
  out.offset = phi(D) * h / len - center.template head<D>().dot(out.normal.template head<D>());
  out.iterations = iterations;
  out.converged = converged;
  out.ok = out.normal.allFinite() && std::isfinite(out.offset);
  if (!out.ok) out = PlaneFit{};
  return out;
}

}  // namespace

PlaneFit fit_separating_plane(std::span<const Vec3> x, std::span<const signed char> cls,
                              std::span<const double> w, const Vec3& center,
                              const PlaneFitOptions& opt, PlaneFitMethod method,
                              const Vec3* initial_normal) {
  if (cls.size() != x.size() || (!w.empty() && w.size() != x.size())) return {};
  switch (opt.dim) {
    case 1: return fit_impl<1>(x, cls, w, center, opt, method, initial_normal);
    case 2: return fit_impl<2>(x, cls, w, center, opt, method, initial_normal);
    case 3: return fit_impl<3>(x, cls, w, center, opt, method, initial_normal);
    default: return {};
  }
}

namespace {

/// Closest point to the origin of the convex hull of the points w[0..n) (n <= 4), by trying the
/// affine hull of every subset and keeping the nearest projection with non-negative barycentric
/// coordinates. Returns the point and reduces w (and the index pairs) to the subset it lies on.
Vec3 closest_on_simplex(std::array<Vec3, 4>& w, std::array<std::pair<int, int>, 4>& id, int& n) {
  double best = std::numeric_limits<double>::infinity();
  Vec3 best_v = w[0];
  int best_mask = 1;
  for (int mask = 1; mask < (1 << n); ++mask) {
    std::array<int, 4> sub{};
    int k = 0;
    for (int i = 0; i < n; ++i)
      if (mask & (1 << i)) sub[static_cast<std::size_t>(k++)] = i;
    Eigen::Vector4d lambda = Eigen::Vector4d::Zero();
    if (k == 1) {
      lambda(0) = 1.0;
    } else {
      // lambda = (1 - sum mu, mu), mu minimising |p0 + sum mu_j (p_j - p0)|.
      Eigen::Matrix<double, 3, Eigen::Dynamic> q(3, k - 1);
      const Vec3& p0 = w[static_cast<std::size_t>(sub[0])];
      for (int j = 1; j < k; ++j) q.col(j - 1) = w[static_cast<std::size_t>(sub[static_cast<std::size_t>(j)])] - p0;
      const Eigen::MatrixXd qtq = q.transpose() * q;
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(qtq);
      const Eigen::VectorXd d = ldlt.vectorD();
      if (ldlt.info() != Eigen::Success || !(d.minCoeff() > 1e-12 * d.cwiseAbs().maxCoeff())) continue;
      const Eigen::VectorXd mu = ldlt.solve(-(q.transpose() * p0));
      lambda(0) = 1.0 - mu.sum();
      for (int j = 1; j < k; ++j) lambda(j) = mu(j - 1);
      if (!(lambda.head(k).minCoeff() > 0.0)) continue;
    }
    Vec3 v = Vec3::Zero();
    for (int j = 0; j < k; ++j) v += lambda(j) * w[static_cast<std::size_t>(sub[static_cast<std::size_t>(j)])];
    if (v.squaredNorm() < best) {
      best = v.squaredNorm();
      best_v = v;
      best_mask = mask;
    }
  }
  int k = 0;
  for (int i = 0; i < n; ++i)
    if (best_mask & (1 << i)) {
      w[static_cast<std::size_t>(k)] = w[static_cast<std::size_t>(i)];
      id[static_cast<std::size_t>(k)] = id[static_cast<std::size_t>(i)];
      ++k;
    }
  n = k;
  return best_v;
}

}  // namespace

MarginFit max_margin_plane(std::span<const Vec3> x, std::span<const signed char> cls, int dim) {
  MarginFit out;
  if (cls.size() != x.size()) return out;
  const int d = dim < 1 ? 1 : (dim > 3 ? 3 : dim);
  auto proj = [&](const Vec3& p) {
    Vec3 q = Vec3::Zero();
    for (int a = 0; a < d; ++a) q[a] = p[a];
    return q;
  };
  int first_a = -1, first_b = -1;
  double scale = 0.0;
  for (std::size_t p = 0; p < x.size(); ++p) {
    if (cls[p] < 0 && first_a < 0) first_a = static_cast<int>(p);
    if (cls[p] > 0 && first_b < 0) first_b = static_cast<int>(p);
  }
  if (first_a < 0 || first_b < 0) return out;
  for (std::size_t p = 0; p < x.size(); ++p)
    if (cls[p] != 0) scale = std::max(scale, (proj(x[p]) - proj(x[static_cast<std::size_t>(first_a)])).norm());
  // Support point of the difference set {a - b} along u: argmax a.u - argmin b.u.
  auto support = [&](const Vec3& u) {
    int ia = first_a, ib = first_b;
    double sa = -std::numeric_limits<double>::infinity(), sb = std::numeric_limits<double>::infinity();
    for (std::size_t p = 0; p < x.size(); ++p) {
      if (cls[p] == 0) continue;
      const double s = proj(x[p]).dot(u);
      if (cls[p] < 0 && s > sa) {
        sa = s;
        ia = static_cast<int>(p);
      } else if (cls[p] > 0 && s < sb) {
        sb = s;
        ib = static_cast<int>(p);
      }
    }
    return std::pair<int, int>(ia, ib);
  };
  auto point = [&](const std::pair<int, int>& id) {
    return Vec3(proj(x[static_cast<std::size_t>(id.first)]) - proj(x[static_cast<std::size_t>(id.second)]));
  };
  std::array<Vec3, 4> w;
  std::array<std::pair<int, int>, 4> id;
  int n = 1;
  id[0] = {first_a, first_b};
  w[0] = point(id[0]);
  Vec3 v = w[0];
  const double tiny = 1e-12 * std::max(scale, 1e-300);
  for (int it = 0; it < 64; ++it) {
    out.iterations = it + 1;
    if (v.norm() <= tiny) return out;  // the hulls touch: no separating gap
    const auto sid = support(-v);
    const Vec3 s = point(sid);
    // Gilbert's stopping rule: the support point gets no closer along v than v itself.
    if (v.squaredNorm() - v.dot(s) <= 1e-12 * v.squaredNorm()) {
      if (!(v.dot(s) > 0.0)) return out;
      out.normal = -v.normalized();
      out.gap = v.norm();
      out.ok = true;
      return out;
    }
    if (n == d + 1) return out;  // cannot grow: numerically stuck
    bool duplicate = false;
    for (int i = 0; i < n; ++i) duplicate = duplicate || id[static_cast<std::size_t>(i)] == sid;
    if (duplicate) {
      out.normal = -v.normalized();
      out.gap = v.norm();
      out.ok = v.dot(s) > 0.0;
      if (!out.ok) out.normal.setZero();
      return out;
    }
    w[static_cast<std::size_t>(n)] = s;
    id[static_cast<std::size_t>(n)] = sid;
    ++n;
    v = closest_on_simplex(w, id, n);
    if (n == d + 1) return out;  // the origin lies inside the simplex: the hulls overlap
  }
  return out;
}

double deformed_radius(const Mat3& F, const Vec3& R0, const Vec3& n, int dim) {
  // Eq. 25: n0 = F^{-1} n is n pulled back to the initial configuration (not a unit vector).
  const Vec3 n0 = F.inverse() * n;
  const int d = dim < 1 ? 1 : (dim > 3 ? 3 : dim);
  double s = 0.0;
  for (int a = 0; a < d; ++a) s += (n0(a) * n0(a)) / (R0(a) * R0(a));
  if (s == 0.0) return std::numeric_limits<double>::infinity();
  return 1.0 / std::sqrt(s);
}

}  // namespace cairn::contact
