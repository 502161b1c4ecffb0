#include "firmware/rbsm/increment_fusion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "firmware/rbsm/fusion_tour_test_util.h"
#include "tests/alloc_counter.h"

namespace fw {
namespace {

using testing::dist;
using testing::fuse;
using testing::make_tour;
using testing::rms_error;
using testing::short_error;
using testing::Tour;

TEST(IncrementFusionTest, KeepsTheIncrementsPrecisionAndTheAbsolutePosesAnchor) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Tour t = make_tour(seed);
    IncrementFusion f;
    ASSERT_TRUE(f.init(IncrementFusionOptions{}).is_ok());
    const std::vector<Se2d> fused = fuse(t, &f);
    // Short relations (5 scans): far more precise than the absolute poses' scatter …
    EXPECT_LT(short_error(fused, t.truth, 5), 0.5 * short_error(t.absolute, t.truth, 5)) << "seed " << seed;
    // … and no drift: closer to the truth than the chained increments at the end, and on average
    // no farther from it than the absolute poses themselves.
    EXPECT_LT(dist(fused.back(), t.truth.back()), 0.1) << "seed " << seed;
    EXPECT_LT(rms_error(fused, t.truth), rms_error(t.absolute, t.truth)) << "seed " << seed;
    // The gate is a 99.9 % χ² bound: ~0.6 of 600 consistent innovations exceed it by chance.
    EXPECT_LE(f.gated_updates(), 3u) << "seed " << seed;
  }
  // The chained increments alone drift (the reason for the absolute anchor): checked on one seed.
  const Tour t = make_tour(1);
  EXPECT_GT(rms_error(t.relative, t.truth), rms_error(t.absolute, t.truth));
}

TEST(IncrementFusionTest, ASlideOfTheIncrementsIsPulledBackToTheAbsolutePoses) {
  IncrementFusion f;
  ASSERT_TRUE(f.init(IncrementFusionOptions{}).is_ok());
  ASSERT_TRUE(f.update(Se2d(0, 0, 0), false, Se2d()).is_ok());
  for (int i = 1; i <= 20; ++i) ASSERT_TRUE(f.update(Se2d(0.1 * i, 0, 0), true, Se2d(0.1, 0, 0)).is_ok());
  EXPECT_EQ(f.gated_updates(), 0u);
  // The laser-to-laser matcher slides 1 m along a corridor in one scan; RBSM does not.
  ASSERT_TRUE(f.update(Se2d(2.1, 0, 0), true, Se2d(1.1, 0, 0)).is_ok());
  EXPECT_EQ(f.gated_updates(), 1u);
  // One scan moves the pose by a bounded amount (RBSM may be the one that jumped) …
  EXPECT_GT(f.pose().x, 2.6);
  EXPECT_LT(f.pose().x, 3.1);
  // … and a lasting disagreement ends at the drift-free pose.
  for (int i = 22; i <= 120; ++i) ASSERT_TRUE(f.update(Se2d(0.1 * i, 0, 0), true, Se2d(0.1, 0, 0)).is_ok());
  EXPECT_NEAR(f.pose().x, 12.0, 0.05);
  EXPECT_NEAR(f.pose().y, 0.0, 1e-6);
}

TEST(IncrementFusionTest, WithoutIncrementsFollowsTheAbsolutePoses) {
  IncrementFusion f;
  ASSERT_TRUE(f.init(IncrementFusionOptions{}).is_ok());
  for (int i = 0; i <= 50; ++i) ASSERT_TRUE(f.update(Se2d(0.1 * i, 0.02 * i, 0.01 * i), false, Se2d()).is_ok());
  EXPECT_NEAR(f.pose().x, 5.0, 1e-6);
  EXPECT_NEAR(f.pose().y, 1.0, 1e-6);
  EXPECT_NEAR(f.pose().theta, 0.5, 1e-6);
}

TEST(IncrementFusionTest, RefusesNonFiniteInputAndBadOptions) {
  IncrementFusion f;
  EXPECT_FALSE(f.update(Se2d(0, 0, 0), false, Se2d()).is_ok());  // before init
  ASSERT_TRUE(f.init(IncrementFusionOptions{}).is_ok());
  ASSERT_TRUE(f.update(Se2d(1, 2, 0.3), false, Se2d()).is_ok());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(f.update(Se2d(nan, 2, 0.3), true, Se2d(0.1, 0, 0)).is_ok());
  EXPECT_FALSE(f.update(Se2d(1, 2, 0.3), true, Se2d(0.1, nan, 0)).is_ok());
  EXPECT_DOUBLE_EQ(f.pose().x, 1.0);  // unchanged
  IncrementFusionOptions o;
  o.absolute_sigma_m = 0;
  EXPECT_FALSE(o.validate().is_ok());
  o = IncrementFusionOptions{};
  o.relative_sigma_rad = -1;
  EXPECT_FALSE(o.validate().is_ok());
  o = IncrementFusionOptions{};
  o.gate_chi2 = nan;
  EXPECT_FALSE(o.validate().is_ok());
  o = IncrementFusionOptions{};
  o.unknown_increment_scale = 0.5;
  EXPECT_FALSE(f.init(o).is_ok());
}

TEST(IncrementFusionTest, NoHeapAllocationPerScan) {
  if (!mmlfw_test::AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  IncrementFusion f;
  ASSERT_TRUE(f.init(IncrementFusionOptions{}).is_ok());
  mmlfw_test::AllocCounter::begin();
  for (int i = 0; i < 1000; ++i) (void)f.update(Se2d(0.1 * i, 0, 0), i > 0, Se2d(0.1, 0, 0));
  EXPECT_EQ(mmlfw_test::AllocCounter::end(), 0);
}

}  // namespace
}  // namespace fw
