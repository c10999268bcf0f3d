// Per-node weighted least squares with the planar basis (seed 001 Sec. 3.2, Eq. 7-12).
//
// A node i fits f^LS(r) = c0 + c . r to the particle values f_p around it, with r = x_p - x_i
// measured in cells (r_a / h_a, so that the moment matrix is O(1) whatever the units), minimising
// sum_p W_ip (f^LS(r_p) - f_p)^2 (Eq. 8). The normal equations M c = l (Eq. 9) have the moment
// matrix M = sum_p W [1 r][1 r]^T and one load vector l = sum_p W f_p [1 r] per field. The node
// value is c0 (Eq. 11) and the gradient (c_1 .. c_D) / h (Eq. 12).
//
// Spurious nodes (Sec. 3.5): when every particle's weight is below the trigger weight TW, or
// fewer than D + 1 particles contribute, or M is numerically singular, the basis is reduced to
// the constant c0: the inverse keeps only M00^-1 = 1 / M00 (a weighted average).
#pragma once

#include <Eigen/Dense>
#include <cmath>

#include "cairn/math/types.hpp"

namespace cairn::wls {

template <int D>
struct PlaneFit {
  static constexpr int n = D + 1;
  using Matrix = Eigen::Matrix<double, n, n>;
  using Vector = Eigen::Matrix<double, n, 1>;

  /// The basis [1, r_1 .. r_D] at r (in cells).
  static Vector basis(const Vec<D>& r) {
    Vector b;
    b[0] = 1.0;
    b.template tail<D>() = r;
    return b;
  }

  /// Inverse of the moment matrix, or the reduced inverse (only entry (0,0) = 1/M00) when
  /// `reduce` is set or M is singular to working precision. `reduced` tells which was used.
  static Matrix inverse(const Matrix& M, bool reduce, bool* reduced = nullptr) {
    Matrix inv = Matrix::Zero();
    if (!reduce) {
      // Relative singularity test: det M against the product of its diagonal (Hadamard bound).
      const double det = M.determinant();
      const double scale = M.diagonal().prod();
      if (scale > 0.0 && det > 1e-10 * scale) {
        inv = M.inverse();
        if (reduced) *reduced = false;
        return inv;
      }
    }
    if (M(0, 0) > 0.0) inv(0, 0) = 1.0 / M(0, 0);
    if (reduced) *reduced = true;
    return inv;
  }
};

}  // namespace cairn::wls
