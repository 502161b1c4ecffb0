#include "firmware/track/scan_continuity.h"

#include <gtest/gtest.h>

#include "firmware/track/track_test_util.h"

namespace fw {
namespace track {
namespace {

// Two scans 10 cm and 3° apart in the same room: the previous one explains nearly all of the next
// (with the wheels' increment); a scan from the other end of the room does not, nor does the same
// pair with the increment left out when the robot turned a lot. Empty scans: see the header.
TEST(ScanContinuityTest, ExplainsTheNextScanNotAScanFromElsewhere) {
  const auto& world = testing::room();
  RandomStream rng(3, 1);
  const Se2f a(2.0f, 4.0f, 0.3f), b = a.compose(Se2f(0.1f, 0.0f, 0.05f)), far(10.0f, 6.0f, 2.5f);
  const auto sa = testing::scan_at(world, a, &rng), sb = testing::scan_at(world, b, &rng);
  const auto sf = testing::scan_at(world, far, &rng);
  static ScanContinuity c;
  EXPECT_GT(c.explained_fraction(sa.data(), sa.size(), sb.data(), sb.size(), a.between(b), 0.3f), 0.9f);
  EXPECT_LT(c.explained_fraction(sa.data(), sa.size(), sf.data(), sf.size(), a.between(b), 0.3f), 0.5f);
  const Se2f turned = a.compose(Se2f(0.0f, 0.0f, 0.6f));
  const auto st = testing::scan_at(world, turned, &rng);
  EXPECT_GT(c.explained_fraction(sa.data(), sa.size(), st.data(), st.size(), a.between(turned), 0.3f), 0.75f);
  EXPECT_LT(c.explained_fraction(sa.data(), sa.size(), st.data(), st.size(), Se2f(), 0.3f), 0.5f);
  EXPECT_EQ(c.explained_fraction(sa.data(), sa.size(), sb.data(), 0, Se2f(), 0.3f), 1.0f);
  EXPECT_EQ(c.explained_fraction(sa.data(), 0, sb.data(), sb.size(), Se2f(), 0.3f), 0.0f);
}

// Wheels that err by 4° a step (the corpus's white model): the increment they report leaves the
// next scan of a robot that drove on unexplained, unless the increments within their bound are tried;
// a scan from elsewhere stays unexplained whatever increment is tried.
TEST(ScanContinuityTest, WithinTheWheelsBoundANoisyIncrementStillExplainsTheNextScan) {
  const auto& world = testing::room();
  RandomStream rng(5, 1);
  const Se2f a(2.0f, 4.0f, 0.3f), b = a.compose(Se2f(0.1f, 0.0f, 0.05f)), far(10.0f, 6.0f, 2.5f);
  const auto sa = testing::scan_at(world, a, &rng), sb = testing::scan_at(world, b, &rng);
  const auto sf = testing::scan_at(world, far, &rng);
  static ScanContinuity c;
  const Se2f reported = a.between(b).compose(Se2f(0.03f, -0.03f, 0.105f));  // 3 cm, 3 cm and 6° off (1.5 σ)
  const float sigma_xy = 0.04f, sigma_theta = 0.0698f;                      // 4 cm, 4°: the wheels' σ
  const float exact = c.explained_fraction(sa.data(), sa.size(), sb.data(), sb.size(), reported, 0.3f);
  const float within = c.explained_fraction_within(sa.data(), sa.size(), sb.data(), sb.size(), reported, sigma_xy,
                                                   sigma_theta, 0.3f);
  EXPECT_LT(exact, 0.6f);
  EXPECT_GT(within, 0.9f);
  EXPECT_LT(c.explained_fraction_within(sa.data(), sa.size(), sf.data(), sf.size(), reported, sigma_xy, sigma_theta,
                                        0.3f),
            0.5f);
  // No noise: the wheels' increment alone.
  EXPECT_EQ(c.explained_fraction_within(sa.data(), sa.size(), sb.data(), sb.size(), reported, 0.0f, 0.0f, 0.3f), exact);
}

}  // namespace
}  // namespace track
}  // namespace fw
