#include "firmware/track/protection_level.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "firmware/base/rng.h"

namespace fw {
namespace track {
namespace {

TEST(ProtectionLevelTest, FactorsForOneInAThousand) {
  EXPECT_NEAR(radial_factor(1e-3f), 3.7169f, 1e-3f);      // sqrt(-2 ln 1e-3)
  EXPECT_NEAR(two_sided_factor(1e-3f), 3.2905f, 1e-3f);   // normal quantile 0.9995
  EXPECT_NEAR(two_sided_factor(0.3173f), 1.0f, 1e-3f);    // 1 σ
  EXPECT_GT(radial_factor(1e-6f), radial_factor(1e-3f));
}

TEST(ProtectionLevelTest, BiasAddsAndLargestAxisCounts) {
  const ProtectionFactors k = ProtectionFactors::for_risk(1e-3f);
  Eigen::Matrix3f c = Eigen::Matrix3f::Zero();
  c(0, 0) = 0.01f;     // σ_x = 10 cm
  c(1, 1) = 0.0001f;   // σ_y = 1 cm
  c(2, 2) = 0.0004f;   // σ_θ = 0.02 rad
  const ProtectionLevel pl = protection_level(c, k, 0.05f, 0.01f);
  EXPECT_NEAR(pl.xy_m, k.k_xy * 0.1f + 0.05f, 1e-5f);
  EXPECT_NEAR(pl.theta_rad, k.k_theta * 0.02f + 0.01f, 1e-5f);
  // A correlated block: λ_max of [[a b][b d]].
  c(0, 1) = c(1, 0) = 0.0009f;
  const float a = 0.01f, d = 0.0001f, b = 0.0009f;
  const float lmax = 0.5f * (a + d) + std::sqrt(0.25f * (a - d) * (a - d) + b * b);
  EXPECT_NEAR(protection_level(c, k, 0.0f, 0.0f).xy_m, k.k_xy * std::sqrt(lmax), 1e-5f);
  // Non-finite covariance: an infinite bound, never a small one.
  c(0, 0) = NAN;
  EXPECT_FALSE(protection_level(c, k, 0.0f, 0.0f).xy_m < 1e30f);
}

// The stochastic part alone holds: Gaussian errors with the covariance exceed the PL in ≤ α.
TEST(ProtectionLevelTest, GaussianErrorsExceedAtMostTheRisk) {
  const float risk = 1e-2f;  // 1e-2 keeps the Monte Carlo count meaningful with 200k draws
  const ProtectionFactors k = ProtectionFactors::for_risk(risk);
  Eigen::Matrix3f c = Eigen::Matrix3f::Zero();
  c(0, 0) = 0.04f; c(1, 1) = 0.01f; c(0, 1) = c(1, 0) = 0.01f; c(2, 2) = 0.0025f;
  const ProtectionLevel pl = protection_level(c, k, 0.0f, 0.0f);
  const Eigen::Matrix2f l = c.topLeftCorner<2, 2>().llt().matrixL();
  RandomStream rng(7, 0);
  int over_xy = 0, over_th = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const float zy = static_cast<float>(rng.gaussian());  // one draw per statement (argument order is unspecified)
    const Eigen::Vector2f z(static_cast<float>(rng.gaussian()), zy);
    const Eigen::Vector2f e = l * z;
    over_xy += e.norm() > pl.xy_m;
    over_th += std::fabs(0.05f * static_cast<float>(rng.gaussian())) > pl.theta_rad;
  }
  EXPECT_LE(over_xy, static_cast<int>(risk * n));
  EXPECT_LE(over_th, static_cast<int>(1.1f * risk * n));  // exact quantile: within sampling noise
}

}  // namespace
}  // namespace track
}  // namespace fw
