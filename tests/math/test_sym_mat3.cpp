// SymMat3: the six-component storage of the Kirchhoff stress.
#include <gtest/gtest.h>

#include "cairn/math/sym_mat3.hpp"

using namespace cairn;

TEST(SymMat3, KeepsTheSymmetricPartAndMultipliesLikeAMat3Block) {
  Mat3 m;
  m << 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0;
  const SymMat3 s = m;
  EXPECT_EQ(s(0, 1), 3.0);
  EXPECT_EQ(s(1, 0), 3.0);
  EXPECT_EQ(s(0, 2), 5.0);
  EXPECT_EQ(s(1, 2), 7.0);
  EXPECT_EQ(s.trace(), 15.0);
  const Mat3 sym = 0.5 * (m + m.transpose());
  EXPECT_EQ(s.full(), sym);
  const SymMat3 t = sym;  // a symmetric matrix is kept bit for bit
  EXPECT_TRUE(t == s);
  EXPECT_EQ((s.times<2>(Vec<2>(1.0, -1.0))), (sym.topLeftCorner<2, 2>() * Vec<2>(1.0, -1.0)).eval());
}
