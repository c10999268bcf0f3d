// Tensor helpers: the matrix exponential used for the incremental deformation gradient
// dF = exp(grad V dt) (seed 000 Table 1, Task 5) and small invariants.
#pragma once

#include <cmath>
#include <limits>

#include "cairn/math/types.hpp"

namespace cairn {

/// exp(A) for an N x N matrix (N = 1, 2, 3) by scaling and squaring of a Taylor series run to
/// round-off: exp(A) = (exp(A / 2^s))^(2^s) with s chosen so that b = |A|_inf / 2^s <= 1/2, and
/// the series sum_k B^k / k! taken until the bound b^k / k! on its last term is below 1e-17 (the
/// sum is at least 1 - b >= 1/2 in norm). The term count comes from that scalar bound, not from
/// the terms themselves, so the loop does no matrix reductions, and 1/k is a multiplication. For
/// the small increments of a stable MPM step (|grad V dt| ~ 1e-3) this is s = 0 and 5 terms,
/// several times cheaper than a general Pade evaluation with its solve, and exact to round-off;
/// still correct for large arguments (tested against Eigen's Pade-based MatrixFunctions). A 2D
/// step calls it with N = 2: exp of a block-diagonal [[A, 0], [0, 0]] is [[exp A, 0], [0, 1]].
template <int N>
Eigen::Matrix<double, N, N> tensor_exp(const Eigen::Matrix<double, N, N>& a) {
  using M = Eigen::Matrix<double, N, N>;
  static constexpr double inverse[] = {0.0,        1.0,        1.0 / 2,  1.0 / 3,  1.0 / 4,  1.0 / 5,
                                       1.0 / 6,    1.0 / 7,    1.0 / 8,  1.0 / 9,  1.0 / 10, 1.0 / 11,
                                       1.0 / 12,   1.0 / 13,   1.0 / 14, 1.0 / 15, 1.0 / 16, 1.0 / 17,
                                       1.0 / 18,   1.0 / 19,   1.0 / 20, 1.0 / 21, 1.0 / 22, 1.0 / 23,
                                       1.0 / 24,   1.0 / 25,   1.0 / 26, 1.0 / 27, 1.0 / 28, 1.0 / 29};
  const double norm = a.cwiseAbs().rowwise().sum().maxCoeff();  // infinity norm
  if (!std::isfinite(norm)) return M::Constant(std::numeric_limits<double>::quiet_NaN());
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
