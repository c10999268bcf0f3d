// Tensor helpers: the matrix exponential used for the incremental deformation gradient
// dF = exp(grad V dt) (seed 000 Table 1, Task 5) and small invariants.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "cairn/math/types.hpp"

namespace cairn {

namespace exp_detail {

/// Degrees of the truncated series used for small arguments: degree m is enough when
/// b^(m+1) / (m+1)! <= 1e-17 (b = |A|_inf), since then the whole tail sum_{k>m} |A|^k / k! is
/// at most 1e-17 / (1 - b) ~ 1e-17, below round-off of the sum (whose norm is at least 1 - b).
/// threshold[m] is the largest such b for degree m = 1 .. 7.
inline const std::array<double, 8> threshold = [] {
  std::array<double, 8> t{};
  double factorial = 1.0;
  for (int m = 1; m < 8; ++m) {
    factorial *= m + 1;  // (m+1)!
    t[m] = std::pow(1e-17 * factorial, 1.0 / (m + 1)) * (1.0 - 1e-12);
  }
  return t;
}();
inline const double small_limit = threshold[7];

/// exp(A) for |A|_inf = b <= small_limit: the degree-m Taylor polynomial, m from the table
/// above (no data-dependent loop), evaluated Paterson-Stockmeyer style on A^2 and A^3 so that
/// degree 4 costs 2 matrix products, degree 6 three, degree 7 four (the plain series needs m - 1).
/// M is an Eigen matrix or Scalar3 (below); I its identity. M(...) evaluates a product.
template <class M>
[[gnu::always_inline]] inline M exp_small(const M& A, const M& I, double b) {
  int m = 1;
  for (int k = 1; k < 7; ++k) m += b > threshold[k];  // branch-free: m = 1 .. 7
  if (m == 1) return I + A;
  const M A2 = M(A * A);
  switch (m) {
    case 2:
      return I + A + 0.5 * A2;
    case 3:
      return I + A + M(A2 * (0.5 * I + (1.0 / 6) * A));
    case 4:
      return I + A + M(A2 * (0.5 * I + (1.0 / 6) * A + (1.0 / 24) * A2));
    default: {
      const M A3 = M(A2 * A);
      const M head = I + A + 0.5 * A2;
      if (m == 5) return head + M(A3 * ((1.0 / 6) * I + (1.0 / 24) * A + (1.0 / 120) * A2));
      if (m == 6) return head + M(A3 * ((1.0 / 6) * I + (1.0 / 24) * A + (1.0 / 120) * A2 + (1.0 / 720) * A3));
      const M A4 = M(A2 * A2);
      return head + (1.0 / 6) * A3 +
             M(A4 * ((1.0 / 24) * I + (1.0 / 120) * A + (1.0 / 720) * A2 + (1.0 / 5040) * A3));
    }
  }
}

/// A 3x3 matrix as scalars for the inlined 3D exponential, columns padded to four (the fourth
/// entry of each column is zero). Eigen's SSE code for a 3x3 matrix stores a product column by
/// column (a 2-double packet and a scalar) and reads a sum linearly in packets (elements 0-1,
/// 2-3, ...), so a packet read straddled two earlier stores and waited for them (store-forwarding
/// stalls, 40 % of the 3D stress-update function in a profile of problem (c),
/// docs/performance.md). With padded columns, element-wise and column-wise access pair the same
/// elements, so whatever the compiler keeps in memory is read back as it was stored.
struct Scalar3 {
  alignas(16) double v[12];
  [[gnu::always_inline]] static Scalar3 identity() {
    return {{1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0}};
  }
  [[gnu::always_inline]] static Scalar3 of(const Eigen::Matrix3d& m) {
    Scalar3 r;
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) r.v[i + 4 * j] = m(i, j);
      r.v[3 + 4 * j] = 0.0;
    }
    return r;
  }
  [[gnu::always_inline]] Eigen::Matrix3d matrix() const {
    Eigen::Matrix3d m;
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) m(i, j) = v[i + 4 * j];
    return m;
  }
};
[[gnu::always_inline]] inline Scalar3 operator+(const Scalar3& x, const Scalar3& y) {
  Scalar3 r;
  for (int k = 0; k < 12; ++k) r.v[k] = x.v[k] + y.v[k];
  return r;
}
[[gnu::always_inline]] inline Scalar3 operator*(double c, const Scalar3& x) {
  Scalar3 r;
  for (int k = 0; k < 12; ++k) r.v[k] = c * x.v[k];
  return r;
}
/// The matrix product.
[[gnu::always_inline]] inline Scalar3 operator*(const Scalar3& x, const Scalar3& y) {
  Scalar3 r;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 4; ++i)  // i = 3: the zero padding (0 * y + ...)
      r.v[i + 4 * j] = x.v[i] * y.v[4 * j] + x.v[i + 4] * y.v[4 * j + 1] + x.v[i + 8] * y.v[4 * j + 2];
  return r;
}

/// Scaling and squaring for |A|_inf = norm > small_limit (see tensor_exp), out of line.
template <int N>
[[gnu::noinline]] Eigen::Matrix<double, N, N> exp_large(const Eigen::Matrix<double, N, N>& a, double norm) {
  using M = Eigen::Matrix<double, N, N>;
  static constexpr double inverse[] = {0.0,        1.0,        1.0 / 2,  1.0 / 3,  1.0 / 4,  1.0 / 5,
                                       1.0 / 6,    1.0 / 7,    1.0 / 8,  1.0 / 9,  1.0 / 10, 1.0 / 11,
                                       1.0 / 12,   1.0 / 13,   1.0 / 14, 1.0 / 15, 1.0 / 16, 1.0 / 17,
                                       1.0 / 18,   1.0 / 19,   1.0 / 20, 1.0 / 21, 1.0 / 22, 1.0 / 23,
                                       1.0 / 24,   1.0 / 25,   1.0 / 26, 1.0 / 27, 1.0 / 28, 1.0 / 29};
  int s = 0;
  if (norm > 0.5) s = static_cast<int>(std::ceil(std::log2(norm / 0.5)));
  const double scale = s > 0 ? std::ldexp(1.0, -s) : 1.0;
  const M scaled = s > 0 ? M(a * scale) : a;
  const double b = norm * scale;
  M sum = M::Identity() + scaled;
  M term = scaled;
  double bound = b;  // >= |term|_inf
  for (int k = 2; k < 30 && bound > 1e-17; ++k) {
    term = (term * scaled).eval() * inverse[k];
    sum += term;
    bound *= b * inverse[k];
  }
  for (int i = 0; i < s; ++i) sum = (sum * sum).eval();
  return sum;
}

}  // namespace exp_detail

/// exp(a) of a 3x3 matrix as nine scalars (exp_detail::Scalar3), for a caller that goes on in
/// scalars (the 3D deformation-gradient update, sim/simulation.cpp): tensor_exp<3> below.
[[gnu::always_inline]] inline exp_detail::Scalar3 tensor_exp_scalars(const Eigen::Matrix3d& a) {
  const exp_detail::Scalar3 s = exp_detail::Scalar3::of(a);
  double norm = 0.0;  // infinity norm
  for (int i = 0; i < 3; ++i) norm = std::max(norm, std::abs(s.v[i]) + std::abs(s.v[i + 4]) + std::abs(s.v[i + 8]));
  if (!std::isfinite(norm)) {
    exp_detail::Scalar3 nan;
    for (double& x : nan.v) x = std::numeric_limits<double>::quiet_NaN();
    return nan;
  }
  if (norm <= exp_detail::small_limit) return exp_detail::exp_small(s, exp_detail::Scalar3::identity(), norm);
  return exp_detail::Scalar3::of(exp_detail::exp_large<3>(a, norm));
}

/// exp(A) for an N x N matrix (N = 1, 2, 3) by scaling and squaring of a Taylor series run to
/// round-off: exp(A) = (exp(A / 2^s))^(2^s) with s chosen so that b = |A|_inf / 2^s <= 1/2, and
/// the series sum_k B^k / k! taken until the bound b^k / k! on its last term is below 1e-17 (the
/// sum is at least 1 - b >= 1/2 in norm). The term count comes from that scalar bound, not from
/// the terms themselves, so the loop does no matrix reductions, and 1/k is a multiplication. For
/// the small increments of a stable MPM step (|grad V dt| <= 0.028) exp_small is used instead:
/// a polynomial of degree 1 .. 7 with 0 .. 4 matrix products, its degree chosen without a
/// data-dependent loop (that loop took a third of a 3D linear-elastic step). Both are several
/// times cheaper than a general Pade evaluation with its solve, and exact to round-off;
/// still correct for large arguments (tested against Eigen's Pade-based MatrixFunctions). A 2D
/// step calls it with N = 2: exp of a block-diagonal [[A, 0], [0, 0]] is [[exp A, 0], [0, 1]].
///
/// The common path is inlined into its caller: passed through memory, a matrix the caller has
/// just stored element by element was reloaded in 16-byte halves, each straddling two stores (a
/// store-forwarding stall, 40 % of the function in a 3D profile; docs/performance.md).
template <int N>
[[gnu::always_inline]] inline Eigen::Matrix<double, N, N> tensor_exp(const Eigen::Matrix<double, N, N>& a) {
  using M = Eigen::Matrix<double, N, N>;
  if constexpr (N == 3) {
    return tensor_exp_scalars(a).matrix();
  } else {
    const double norm = a.cwiseAbs().rowwise().sum().maxCoeff();  // infinity norm
    if (!std::isfinite(norm)) return M::Constant(std::numeric_limits<double>::quiet_NaN());
    if (norm <= exp_detail::small_limit) return exp_detail::exp_small<M>(a, M::Identity(), norm);
    return exp_detail::exp_large<N>(a, norm);
  }
}

/// The 3x3 case, also for matrix expressions (tensor_exp(L * dt)).
inline Mat3 tensor_exp(const Mat3& a) { return tensor_exp<3>(a); }

/// Truncated Taylor series sum_{k<=n} A^k / k!, the reference the exponential is tested against.
Mat3 tensor_exp_series(const Mat3& a, int n_terms);

/// Cauchy stress from Kirchhoff stress and F.
inline Mat3 cauchy_from_kirchhoff(const Mat3& tau, const Mat3& F) { return tau / F.determinant(); }

/// von Mises equivalent of a symmetric stress.
inline double von_mises(const Mat3& s) {
  const Mat3 dev = s - (s.trace() / 3.0) * Mat3::Identity();
  return std::sqrt(1.5 * dev.cwiseProduct(dev).sum());
}

}  // namespace cairn
