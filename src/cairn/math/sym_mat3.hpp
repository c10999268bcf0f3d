// SymMat3: a symmetric 3x3 tensor (the Kirchhoff stress) stored as its six independent
// components in Voigt order xx, yy, zz, yz, xz, xy: 48 bytes instead of the 72 of a Mat3 (one
// sixth of a 2D particle's storage; docs/performance.md).
#pragma once

#include <array>
#include <cmath>

#include "cairn/math/types.hpp"

namespace cairn {

class SymMat3 {
 public:
  SymMat3() = default;  ///< zero
  /// The symmetric part (m + m^T) / 2 of a 3x3 matrix expression; bit for bit m itself when m
  /// is symmetric (as every Kirchhoff stress of an isotropic model is).
  template <class Derived>
  SymMat3(const Eigen::EigenBase<Derived>& matrix) {  // NOLINT: implicit, like a Mat3 assignment
    const Mat3 m = matrix.derived();
    v_ = {m(0, 0), m(1, 1), m(2, 2), mean(m(1, 2), m(2, 1)), mean(m(0, 2), m(2, 0)), mean(m(0, 1), m(1, 0))};
  }

  [[nodiscard]] Mat3 full() const {
    Mat3 m;
    m << v_[0], v_[5], v_[4], v_[5], v_[1], v_[3], v_[4], v_[3], v_[2];
    return m;
  }
  operator Mat3() const { return full(); }  // NOLINT: implicit, reads like a Mat3

  [[nodiscard]] double operator()(int i, int j) const { return v_[index(i, j)]; }
  /// Component (i, j), which is also (j, i).
  [[nodiscard]] double& operator()(int i, int j) { return v_[index(i, j)]; }
  [[nodiscard]] const std::array<double, 6>& voigt() const { return v_; }
  [[nodiscard]] std::array<double, 6>& voigt() { return v_; }

  [[nodiscard]] double trace() const { return v_[0] + v_[1] + v_[2]; }
  [[nodiscard]] bool allFinite() const {
    for (double x : v_)
      if (!std::isfinite(x)) return false;
    return true;
  }
  /// The top-left D x D block as a full matrix.
  template <int D>
  [[nodiscard]] Eigen::Matrix<double, D, D> block() const {
    Eigen::Matrix<double, D, D> m;
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) m(i, j) = (*this)(i, j);
    return m;
  }
  /// The top-left D x D block times g, summed in the order of a Mat3 block product.
  template <int D>
  [[nodiscard]] Vec<D> times(const Vec<D>& g) const {
    Vec<D> out;
    for (int i = 0; i < D; ++i) {
      double s = (*this)(i, 0) * g[0];
      for (int j = 1; j < D; ++j) s += (*this)(i, j) * g[j];
      out[i] = s;
    }
    return out;
  }
  friend bool operator==(const SymMat3& a, const SymMat3& b) { return a.v_ == b.v_; }

 private:
  static double mean(double a, double b) { return a == b ? a : 0.5 * a + 0.5 * b; }
  static int index(int i, int j) {
    static constexpr int k[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};
    return k[i][j];
  }
  std::array<double, 6> v_{};
};

}  // namespace cairn
