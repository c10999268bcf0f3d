// Tensor helpers: the matrix exponential used for the incremental deformation gradient
// dF = exp(grad V dt) (seed 000 Table 1, Task 5) and small invariants.
#pragma once

#include <cmath>

#include "cairn/math/types.hpp"

namespace cairn {

/// exp(A) for a 3x3 matrix by scaling and squaring of a Taylor series run to round-off
/// (see tensor.cpp). Exact to round-off for the |A| << 1 increments of a stable MPM step and
/// still correct for large arguments; tested against Eigen's Pade-based MatrixFunctions.
Mat3 tensor_exp(const Mat3& a);

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
