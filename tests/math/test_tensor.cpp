#include <gtest/gtest.h>

#include <vector>

#include "cairn/math/tensor.hpp"

namespace cairn {
namespace {

TEST(TensorExp, MatchesALongTaylorSeries) {
  Mat3 a;
  a << 0.01, -0.02, 0.003, 0.015, -0.007, 0.02, -0.004, 0.011, 0.006;
  for (double scale : {1.0, 10.0, 50.0}) {
    const Mat3 m = scale * a;
    EXPECT_LT((tensor_exp(m) - tensor_exp_series(m, 60)).norm(), 1e-13 * tensor_exp_series(m, 60).norm())
        << "scale " << scale;
  }
}

TEST(TensorExp, RotationRateGivesARotation) {
  Mat3 w = Mat3::Zero();
  w(0, 1) = -0.3;
  w(1, 0) = 0.3;
  const Mat3 r = tensor_exp(w);
  EXPECT_LT((r * r.transpose() - Mat3::Identity()).norm(), 1e-14);
  EXPECT_NEAR(r(0, 0), std::cos(0.3), 1e-15);
  EXPECT_NEAR(r(1, 0), std::sin(0.3), 1e-15);
}

TEST(TensorExp, DeterminantIsExpOfTrace) {
  Mat3 a;
  a << 0.2, 0.1, 0.0, -0.05, 0.1, 0.3, 0.02, 0.0, -0.15;
  EXPECT_NEAR(tensor_exp(a).determinant(), std::exp(a.trace()), 1e-14);
}

}  // namespace
}  // namespace cairn

#include <unsupported/Eigen/MatrixFunctions>

namespace cairn {
namespace {

TEST(TensorExp, AgreesWithEigensPadeForLargeArguments) {
  Mat3 a;
  a << 1.2, -0.7, 0.3, 2.0, -0.4, 0.9, -1.1, 0.5, 0.8;
  const Mat3 reference = a.exp();
  EXPECT_LT((tensor_exp(a) - reference).norm(), 1e-13 * reference.norm());
}

}  // namespace
}  // namespace cairn

namespace cairn {
namespace {

// The small-argument polynomials (exp_detail::exp_small, degrees 1 .. 7) against a 40-term
// series summed in long double: every entry within 2 ulp of 1 for arguments on both sides of
// each degree threshold, in 2D and 3D, and the two sides of the switch to the general loop.
TEST(TensorExp, SmallArgumentPolynomialsAreExactToRoundOff) {
  using LMat3 = Eigen::Matrix<long double, 3, 3>;
  Mat3 shape;
  shape << 0.3, -0.7, 0.1, 0.5, -0.2, 0.4, -0.1, 0.6, 0.25;  // |shape|_inf = 1.1
  shape /= shape.cwiseAbs().rowwise().sum().maxCoeff();   // now 1
  std::vector<double> norms;
  for (int m = 1; m < 8; ++m)
    for (double f : {0.5, 0.999, 1.001}) norms.push_back(f * exp_detail::threshold[m]);
  norms.push_back(1.0001 * exp_detail::small_limit);  // general loop
  for (double b : norms) {
    const Mat3 a = b * shape;
    LMat3 sum = LMat3::Identity(), term = LMat3::Identity();
    for (int k = 1; k <= 40; ++k) {
      term = (term * a.cast<long double>()).eval() / static_cast<long double>(k);
      sum += term;
    }
    const Mat3 reference = sum.cast<double>();
    EXPECT_LT((tensor_exp(a) - reference).cwiseAbs().maxCoeff(), 4.5e-16) << "|A| = " << b;
    const Eigen::Matrix2d a2 = a.topLeftCorner<2, 2>();
    const Eigen::Matrix2d e2 = tensor_exp<2>(a2);
    Mat3 embedded = Mat3::Zero();
    embedded.topLeftCorner<2, 2>() = a2;
    const Eigen::Matrix2d r2 = tensor_exp(embedded).topLeftCorner<2, 2>();
    EXPECT_LT((e2 - r2).cwiseAbs().maxCoeff(), 4.5e-16) << "2D, |A| = " << b;
  }
}

TEST(TensorExp, NonFiniteArgumentGivesNaNInsteadOfLooping) {
  Mat3 a = Mat3::Zero();
  a(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(tensor_exp(a).allFinite());
  a(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(tensor_exp(a).allFinite());
}

}  // namespace
}  // namespace cairn
