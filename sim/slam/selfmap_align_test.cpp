// align_rigid_2d (sim/slam/selfmap.h), the rule that moves the public reference into the AntSLAM
// map's frame for D_selfmap_*: a known rotation + translation is recovered to 1e-6, a mirrored
// trajectory is not "aligned" (no reflection, no identity with zero residual), degenerate input fails.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/slam/selfmap.h"

namespace {

// A non-symmetric path (a spiral with a tail), so a mirror image cannot be rotated onto it.
std::vector<fw::Se2d> path() {
  std::vector<fw::Se2d> p;
  for (int i = 0; i < 400; ++i) {
    const double t = 0.05 * i;
    p.emplace_back(0.3 * t * std::cos(t) + 0.02 * i, 0.3 * t * std::sin(t), t);
  }
  return p;
}

std::vector<fw::Se2d> moved(const std::vector<fw::Se2d>& p, const fw::Se2d& T) {
  std::vector<fw::Se2d> o;
  for (const auto& q : p) o.push_back(T.compose(q));
  return o;
}

TEST(SelfMapAlign, RecoversKnownRotationAndTranslation) {
  const std::vector<fw::Se2d> ref = path();
  for (const fw::Se2d T : {fw::Se2d(12.5, -7.25, 2.1), fw::Se2d(-3.0, 40.0, -2.9), fw::Se2d(0.1, 0.2, 0.0)}) {
    const std::vector<fw::Se2d> slam = moved(ref, T);
    sim::RigidAlignment2d a;
    std::string err;
    ASSERT_TRUE(sim::align_rigid_2d(ref, slam, &a, &err)) << err;
    EXPECT_NEAR(a.transform.x, T.x, 1e-6);
    EXPECT_NEAR(a.transform.y, T.y, 1e-6);
    EXPECT_NEAR(a.transform.theta, T.theta, 1e-6);
    EXPECT_LT(a.rms_m, 1e-6);
    EXPECT_EQ(a.pairs, ref.size());
  }
}

TEST(SelfMapAlign, NoisyDistortionShowsInResidualNotInTransform) {
  const std::vector<fw::Se2d> ref = path();
  const fw::Se2d T(5.0, 1.0, 0.7);
  std::vector<fw::Se2d> slam = moved(ref, T);
  // Zero-mean alternating offsets of 0.1 m along x of the SLAM frame: RMS 0.1 m, the transform unchanged
  // to first order.
  for (std::size_t i = 0; i < slam.size(); ++i) slam[i].x += (i % 2 == 0) ? 0.1 : -0.1;
  sim::RigidAlignment2d a;
  std::string err;
  ASSERT_TRUE(sim::align_rigid_2d(ref, slam, &a, &err)) << err;
  EXPECT_NEAR(a.rms_m, 0.1, 2e-3);
  EXPECT_NEAR(a.transform.theta, T.theta, 1e-3);
}

TEST(SelfMapAlign, MirroredTrajectoryIsNotAligned) {
  const std::vector<fw::Se2d> ref = path();
  std::vector<fw::Se2d> mirrored;
  for (const auto& q : ref) mirrored.emplace_back(q.x, -q.y, -q.theta);
  sim::RigidAlignment2d a;
  std::string err;
  ASSERT_TRUE(sim::align_rigid_2d(ref, mirrored, &a, &err)) << err;
  // A reflection would fit it exactly; a proper rotation leaves a large residual.
  EXPECT_GT(a.rms_m, 0.5);
  // The reported residual is the one of the returned transform, and no other rotation does better.
  auto rms_of = [&](const fw::Se2d& T) {
    double sq = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      const fw::Se2d p = T.compose(fw::Se2d(ref[i].x, ref[i].y, 0));
      sq += (p.x - mirrored[i].x) * (p.x - mirrored[i].x) + (p.y - mirrored[i].y) * (p.y - mirrored[i].y);
    }
    return std::sqrt(sq / static_cast<double>(ref.size()));
  };
  EXPECT_NEAR(rms_of(a.transform), a.rms_m, 1e-9);
  EXPECT_GT(rms_of(fw::Se2d(0, 0, 0)), a.rms_m);
  for (double th = -3.1; th < 3.15; th += 0.1) {
    fw::Se2d T = a.transform;
    T.theta = th;
    // Best translation for this rotation is μ_to − R μ_from; the returned transform must not lose to it.
    double fx = 0, fy = 0, tx = 0, ty = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      fx += ref[i].x, fy += ref[i].y, tx += mirrored[i].x, ty += mirrored[i].y;
    }
    const double n = static_cast<double>(ref.size());
    T.x = tx / n - (std::cos(th) * fx / n - std::sin(th) * fy / n);
    T.y = ty / n - (std::sin(th) * fx / n + std::cos(th) * fy / n);
    EXPECT_GE(rms_of(T) + 1e-9, a.rms_m) << "theta " << th;
  }
}

TEST(SelfMapAlign, DegenerateInputFails) {
  sim::RigidAlignment2d a;
  std::string err;
  EXPECT_FALSE(sim::align_rigid_2d({fw::Se2d(1, 2, 0)}, {fw::Se2d(1, 2, 0)}, &a, &err));
  EXPECT_FALSE(err.empty());
  const std::vector<fw::Se2d> still(10, fw::Se2d(3, 4, 0));
  EXPECT_FALSE(sim::align_rigid_2d(still, path(), &a, &err));
}

}  // namespace
