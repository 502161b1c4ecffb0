#include "firmware/base/sym2_eigen.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fw {
namespace {

// A v = λ v for the returned weak eigenvector, on rotated diagonal matrices of known spectrum.
TEST(Sym2EigenTest, MatchesRotatedDiagonal) {
  for (double angle : {0.0, 0.3, 1.2, 1.5707963, 2.5, -0.7}) {
    for (const double l0 : {0.0, 0.5, 3.0}) {
      const double l1 = 7.0;
      const double c = std::cos(angle), s = std::sin(angle);
      // A = R diag(l0, l1) Rᵀ: the weak axis is (c, s).
      const double a = l0 * c * c + l1 * s * s, b = (l0 - l1) * c * s, d = l0 * s * s + l1 * c * c;
      const Sym2Eigen e = sym2_eigen(a, b, d);
      EXPECT_NEAR(e.lambda_min, l0, 1e-5) << angle;
      EXPECT_NEAR(e.lambda_max, l1, 1e-5) << angle;
      EXPECT_NEAR(std::hypot(e.vmin_x, e.vmin_y), 1.0, 1e-5);
      EXPECT_NEAR(std::fabs(e.vmin_x * c + e.vmin_y * s), 1.0, 1e-4) << angle << " " << l0;
    }
  }
}

TEST(Sym2EigenTest, IsotropicAndZero) {
  const Sym2Eigen e = sym2_eigen(2.0, 0.0, 2.0);
  EXPECT_FLOAT_EQ(e.lambda_min, 2.0f);
  EXPECT_FLOAT_EQ(e.lambda_max, 2.0f);
  EXPECT_NEAR(std::hypot(e.vmin_x, e.vmin_y), 1.0, 1e-6);
  const Sym2Eigen z = sym2_eigen(0.0, 0.0, 0.0);
  EXPECT_FLOAT_EQ(z.lambda_min, 0.0f);
  EXPECT_FLOAT_EQ(z.vmin_x, 1.0f);
}

}  // namespace
}  // namespace fw
