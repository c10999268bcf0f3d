#include <gtest/gtest.h>

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

TEST(TensorExp, NonFiniteArgumentGivesNaNInsteadOfLooping) {
  Mat3 a = Mat3::Zero();
  a(0, 0) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(tensor_exp(a).allFinite());
  a(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(tensor_exp(a).allFinite());
}

}  // namespace
}  // namespace cairn
