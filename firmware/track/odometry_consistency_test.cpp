#include "firmware/track/odometry_consistency.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fw {
namespace track {
namespace {

// AMCL-style noise of one increment (the tracker's defaults, 0.2 per metre / radian).
Eigen::Matrix3f odom_noise(const Se2f& d) {
  const float ds = std::hypot(d.x, d.y), da = std::fabs(d.theta);
  const float st = 0.2f * ds + 0.2f * da, sr = 0.2f * da + 0.2f * ds;
  Eigen::Matrix3f q = Eigen::Matrix3f::Zero();
  q(0, 0) = q(1, 1) = st * st;
  q(2, 2) = sr * sr;
  return q;
}

Eigen::Matrix3f diag(float sxy, float sth) {
  Eigen::Matrix3f c = Eigen::Matrix3f::Zero();
  c(0, 0) = c(1, 1) = sxy * sxy;
  c(2, 2) = sth * sth;
  return c;
}

constexpr float kChi2 = 16.27f;  // χ²(3) at 1 − 1e-3, the tracker's default

// A track that moves with the wheels (a turn and a straight, small scan noise) passes; the same
// track held on one spot while the wheels drive 1.6 m fails, although no single step moved more
// than the per-step bound (0.1 m a step).
TEST(OdometryConsistencyTest, FollowingPassesHeldBackFails) {
  OdometryConsistency follow, held;
  follow.configure(16);
  held.configure(16);
  const Eigen::Matrix3f p = diag(0.03f, 0.01f);
  Se2f truth(1.0f, 2.0f, 0.3f), stuck = truth;
  follow.push(truth, p, 0.08f, 0.01f);
  held.push(stuck, p, 0.08f, 0.01f);
  float worst_follow = 0.0f, worst_held = 0.0f;
  for (int k = 0; k < 16; ++k) {
    const Se2f d(0.1f, 0.0f, k < 4 ? 0.05f : 0.0f);
    truth = truth.compose(d);
    follow.advance(d, odom_noise(d));
    held.advance(d, odom_noise(d));
    // Scan fixes a few centimetres off the truth, alternating (measurement noise).
    const Se2f fix(truth.x + ((k % 2) ? 0.02f : -0.02f), truth.y, truth.theta);
    worst_follow = std::fmax(worst_follow, follow.max_chi2(fix, p, 0.08f, 0.01f));
    follow.push(fix, p, 0.08f, 0.01f);
    const float c = held.max_chi2(stuck, p, 0.08f, 0.01f);
    if (k < 2) EXPECT_LT(c, kChi2) << "step " << k;  // 0.2 m behind: within the bound
    worst_held = std::fmax(worst_held, c);
    held.push(stuck, p, 0.08f, 0.01f);
  }
  EXPECT_LT(worst_follow, 3.0f);
  EXPECT_GT(worst_held, 4.0f * kChi2);
}

// Heading: the wheels turn 90° while the track keeps its heading → contradiction; the noise of the
// turn (0.2 rad/rad) covers a 5° disagreement.
TEST(OdometryConsistencyTest, HeadingDisagreementBeyondTurnNoiseFails) {
  OdometryConsistency oc;
  oc.configure(8);
  const Eigen::Matrix3f p = diag(0.02f, 0.005f);
  const Se2f start(0.0f, 0.0f, 0.0f);
  oc.push(start, p, 0.06f, 0.005f);
  for (int k = 0; k < 6; ++k) {
    const Se2f d(0.0f, 0.0f, 0.2618f);  // 15° in place
    oc.advance(d, odom_noise(d));
  }
  EXPECT_GT(oc.max_chi2(start, p, 0.06f, 0.005f), kChi2);
  EXPECT_LT(oc.max_chi2(Se2f(0.0f, 0.0f, 1.5708f - 0.0873f), p, 0.06f, 0.005f), kChi2);
}

// The window keeps the last `window` poses only; 0 disables; clear() empties.
TEST(OdometryConsistencyTest, WindowCapacityAndClear) {
  OdometryConsistency oc;
  oc.configure(0);
  oc.push(Se2f(), diag(0.01f, 0.01f), 0.05f, 0.01f);
  EXPECT_EQ(oc.size(), 0u);
  EXPECT_EQ(oc.max_chi2(Se2f(100.0f, 0.0f, 0.0f), diag(0.01f, 0.01f), 0.05f, 0.01f), 0.0f);
  oc.configure(3);
  for (int i = 0; i < 5; ++i) oc.push(Se2f(static_cast<float>(i), 0.0f, 0.0f), diag(0.01f, 0.01f), 0.05f, 0.01f);
  EXPECT_EQ(oc.size(), 3u);
  // Kept: x = 2, 3, 4 (no motion since): a pose at x = 4 disagrees with x = 2 by 2 m.
  EXPECT_GT(oc.max_chi2(Se2f(4.0f, 0.0f, 0.0f), diag(0.01f, 0.01f), 0.05f, 0.01f), kChi2);
  oc.clear();
  EXPECT_EQ(oc.size(), 0u);
  oc.configure(1000);  // capped at kMaxWindow
  for (std::size_t i = 0; i < 40; ++i) oc.push(Se2f(), diag(0.01f, 0.01f), 0.05f, 0.01f);
  EXPECT_EQ(oc.size(), OdometryConsistency::kMaxWindow);
}

}  // namespace
}  // namespace track
}  // namespace fw
