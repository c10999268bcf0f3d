#include "cairn/math/tensor.hpp"

namespace cairn {

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
