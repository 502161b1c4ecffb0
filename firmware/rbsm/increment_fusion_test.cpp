#include "firmware/rbsm/increment_fusion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "firmware/base/rng.h"
#include "tests/alloc_counter.h"

namespace fw {
namespace {

// A tour: drive 0.1 m per scan, turn in place, stand still, drive again (600 scans).
std::vector<Se2d> truth_tour() {
  std::vector<Se2d> t{Se2d(0, 0, 0)};
  for (int i = 1; i < 600; ++i) {
    Se2d u(0.1, 0.0, 0.0);
    if (i % 150 >= 100 && i % 150 < 120) u = Se2d(0.0, 0.0, 0.08);  // in-place turn
    if (i % 150 >= 120 && i % 150 < 135) u = Se2d(0.0, 0.0, 0.0);   // standing
    t.push_back(t.back().compose(u));
  }
  return t;
}

double dist(const Se2d& a, const Se2d& b) { return std::hypot(a.x - b.x, a.y - b.y); }

struct Tour {
  std::vector<Se2d> truth, absolute, relative;  // relative: the precise matcher's chained poses
};

// RBSM-like absolute poses: truth + N(0, 3 cm, 0.5°) per scan; PL-ICP-like increments: truth's +
// N(0, 2 mm + 1 % of the motion, 0.05° + 1 %) each, chained (so they drift).
Tour make_tour(std::uint64_t seed) {
  RandomStream rng;
  rng.reseed(seed, 7);
  Tour t;
  t.truth = truth_tour();
  t.relative.push_back(t.truth[0]);
  for (std::size_t i = 0; i < t.truth.size(); ++i) {
    // One draw per statement (argument order is unspecified): θ, y, x as x86-64 GCC drew them.
    const double at = 0.0087 * rng.gaussian(), ay = 0.03 * rng.gaussian(), ax = 0.03 * rng.gaussian();
    t.absolute.push_back(Se2d(t.truth[i].x + ax, t.truth[i].y + ay, wrap_angle(t.truth[i].theta + at)));
    if (i == 0) continue;
    const Se2d u = t.truth[i - 1].between(t.truth[i]);
    const double st = 0.002 + 0.01 * std::hypot(u.x, u.y), sr = 0.0009 + 0.01 * std::fabs(u.theta);
    const double rt = sr * rng.gaussian(), ry = st * rng.gaussian(), rx = st * rng.gaussian();
    t.relative.push_back(t.relative.back().compose(Se2d(u.x + rx, u.y + ry, u.theta + rt)));
  }
  return t;
}

std::vector<Se2d> fuse(const Tour& t, IncrementFusion* f) {
  std::vector<Se2d> out;
  for (std::size_t i = 0; i < t.truth.size(); ++i) {
    const Se2d u = i == 0 ? Se2d() : t.relative[i - 1].between(t.relative[i]);
    EXPECT_TRUE(f->update(t.absolute[i], i > 0, u).is_ok());
    out.push_back(f->pose());
  }
  return out;
}

// RMS of the error of the relative motion over `k` scans (the "short relations").
double short_error(const std::vector<Se2d>& est, const std::vector<Se2d>& truth, std::size_t k) {
  double s = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i + k < est.size(); ++i, ++n) {
    const Se2d e = est[i].between(est[i + k]), g = truth[i].between(truth[i + k]);
    s += (e.x - g.x) * (e.x - g.x) + (e.y - g.y) * (e.y - g.y);
  }
  return std::sqrt(s / static_cast<double>(n));
}

double rms_error(const std::vector<Se2d>& est, const std::vector<Se2d>& truth) {
  double s = 0;
  for (std::size_t i = 0; i < est.size(); ++i) s += dist(est[i], truth[i]) * dist(est[i], truth[i]);
  return std::sqrt(s / static_cast<double>(est.size()));
}

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
