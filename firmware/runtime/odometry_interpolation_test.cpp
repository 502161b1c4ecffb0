#include "firmware/runtime/odometry_interpolation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(Se2Interpolation, EndpointsAreExact) {
  const fw::Se2d a(1.0, 2.0, 0.3), b(4.0, -1.0, 2.5);
  const fw::Se2d p0 = fw::interpolate_se2(a, b, 0.0), p1 = fw::interpolate_se2(a, b, 1.0);
  EXPECT_NEAR(p0.x, a.x, 1e-12);
  EXPECT_NEAR(p0.y, a.y, 1e-12);
  EXPECT_NEAR(p0.theta, a.theta, 1e-12);
  EXPECT_NEAR(p1.x, b.x, 1e-9);
  EXPECT_NEAR(p1.y, b.y, 1e-9);
  EXPECT_NEAR(p1.theta, b.theta, 1e-9);
}

TEST(Se2Interpolation, FollowsTheArcOfAConstantTurn) {
  // Quarter circle of radius 2 around (0, 2), starting at the origin heading +x.
  const fw::Se2d a(0, 0, 0), b(2, 2, kPi / 2);
  for (double s : {0.25, 0.5, 0.75}) {
    const fw::Se2d p = fw::interpolate_se2(a, b, s);
    EXPECT_NEAR(std::hypot(p.x, p.y - 2.0), 2.0, 1e-9) << s;  // on the circle (linear x/y would cut it)
    EXPECT_NEAR(p.theta, s * kPi / 2, 1e-12) << s;
  }
  const fw::Se2d mid = fw::interpolate_se2(a, b, 0.5);
  EXPECT_NEAR(mid.x, 2.0 * std::sin(kPi / 4), 1e-9);
}

TEST(Se2Interpolation, StraightLineIsLinearAndAnglesTakeTheShortWay) {
  const fw::Se2d p = fw::interpolate_se2(fw::Se2d(0, 0, 1.0), fw::Se2d(3, 0, 1.0), 1.0 / 3.0);
  EXPECT_NEAR(p.x, 1.0, 1e-12);
  EXPECT_NEAR(p.y, 0.0, 1e-12);
  // 3.1 → −3.1 rad is a 0.083 rad turn through ±π, not a 6.2 rad one.
  const fw::Se2d q = fw::interpolate_se2(fw::Se2d(0, 0, 3.1), fw::Se2d(0, 0, -3.1), 0.5);
  EXPECT_NEAR(std::fabs(q.theta), kPi, 1e-9);
}

TEST(Se2Interpolation, LogExpRoundTrip) {
  for (double th : {0.0, 1e-9, 0.4, -2.9, 3.0}) {
    const fw::Se2d d(0.7, -0.2, th);
    const fw::Se2d r = fw::se2_exp(fw::se2_log(d));
    EXPECT_NEAR(r.x, d.x, 1e-12) << th;
    EXPECT_NEAR(r.y, d.y, 1e-12) << th;
    EXPECT_NEAR(r.theta, d.theta, 1e-12) << th;
  }
}

TEST(OdometryInterpolation, InterpolatesPoseAndVelocityAndRejectsOutsideTimes) {
  hal::Odometry a, b, out;
  a.timestamp_ns = 1000;
  b.timestamp_ns = 2000;
  b.x = 2.0f;
  a.v = 1.0f;
  b.v = 3.0f;
  ASSERT_TRUE(fw::interpolate_odometry(a, b, 1250, &out).is_ok());
  EXPECT_EQ(out.timestamp_ns, 1250u);
  EXPECT_NEAR(out.x, 0.5f, 1e-6f);
  EXPECT_NEAR(out.v, 1.5f, 1e-6f);
  const fw::Status s = fw::interpolate_odometry(a, b, 2500, &out);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("2500"), std::string::npos) << s.message();
}

}  // namespace
