#include "cairn/math/tensor.hpp"

#include <cmath>
#include <limits>

namespace cairn {

// Scaling and squaring with a Taylor series: exp(A) = (exp(A / 2^s))^(2^s) with s chosen so
// that |A| / 2^s <= 1/2, where the series converges fast (each term at most half the last).
// Terms are added until they no longer change the sum at double precision. For the small
// increments of a stable MPM step (|grad V dt| ~ 1e-3) this is s = 0 and 5-6 terms, several
// times cheaper than a general Pade evaluation with its 3x3 solve, and exact to round-off.
Mat3 tensor_exp(const Mat3& a) {
  const double norm = a.cwiseAbs().rowwise().sum().maxCoeff();  // infinity norm
  if (!std::isfinite(norm)) return Mat3::Constant(std::numeric_limits<double>::quiet_NaN());
  int s = 0;
  if (norm > 0.5) s = static_cast<int>(std::ceil(std::log2(norm / 0.5)));
  const Mat3 scaled = (s > 0) ? Mat3(a / std::ldexp(1.0, s)) : a;
  Mat3 sum = Mat3::Identity();
  Mat3 term = Mat3::Identity();
  for (int k = 1; k <= 30; ++k) {
    term = (term * scaled).eval() / static_cast<double>(k);
    sum += term;
    if (term.cwiseAbs().maxCoeff() <= 1e-17 * sum.cwiseAbs().maxCoeff()) break;
  }
  for (int i = 0; i < s; ++i) sum = (sum * sum).eval();
  return sum;
}

Mat3 tensor_exp_series(const Mat3& a, int n_terms) {
  Mat3 sum = Mat3::Identity();
  Mat3 term = Mat3::Identity();
  for (int k = 1; k <= n_terms; ++k) {
    term = term * a / static_cast<double>(k);
    sum += term;
  }
  return sum;
}

}  // namespace cairn
