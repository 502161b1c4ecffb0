#include "firmware/runtime/odometry_localizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace {

hal::Odometry odom(float x, float y, float th) {
  hal::Odometry o;
  o.x = x;
  o.y = y;
  o.theta = th;
  return o;
}

TEST(OdometryLocalizer, ReportsOdometryRelativeToTheFirstPoseAndSearching) {
  fw::OdometryLocalizer loc;
  hal::LaserScan scan;
  hal::PoseEstimate e;
  ASSERT_TRUE(loc.step(scan, odom(10.0f, 5.0f, 1.5707964f), &e).is_ok());
  EXPECT_FLOAT_EQ(e.x, 0.0f);
  EXPECT_FLOAT_EQ(e.y, 0.0f);
  EXPECT_EQ(e.status, hal::LocalizationStatus::kSearching);
  // Driving 1 m along odometry +y is driving 1 m forward.
  ASSERT_TRUE(loc.step(scan, odom(10.0f, 6.0f, 1.5707964f), &e).is_ok());
  EXPECT_NEAR(e.x, 1.0f, 1e-5f);
  EXPECT_NEAR(e.y, 0.0f, 1e-5f);
  EXPECT_NEAR(e.theta, 0.0f, 1e-6f);
  EXPECT_GT(e.cov[0], 0.0f);  // uncertainty grows with motion
  const float var1 = e.cov[0] + e.cov[4];
  ASSERT_TRUE(loc.step(scan, odom(10.0f, 8.0f, 1.5707964f), &e).is_ok());
  EXPECT_GT(e.cov[0] + e.cov[4], var1);
  EXPECT_EQ(e.status, hal::LocalizationStatus::kSearching);

  loc.reset();
  ASSERT_TRUE(loc.step(scan, odom(-3.0f, 0.0f, 0.0f), &e).is_ok());
  EXPECT_FLOAT_EQ(e.x, 0.0f);
  EXPECT_FLOAT_EQ(e.cov[0], 0.0f);
}

TEST(OdometryLocalizer, InitialPoseAnchorsTheTrack) {
  fw::OdometryLocalizerOptions opt;
  opt.initial_pose = fw::Se2f(5.0f, 5.0f, 3.14159265f);
  fw::OdometryLocalizer loc(opt);
  hal::LaserScan scan;
  hal::PoseEstimate e;
  ASSERT_TRUE(loc.step(scan, odom(0, 0, 0), &e).is_ok());
  ASSERT_TRUE(loc.step(scan, odom(2, 0, 0), &e).is_ok());
  EXPECT_NEAR(e.x, 3.0f, 1e-5f);
  EXPECT_NEAR(e.y, 5.0f, 1e-5f);
}

TEST(OdometryLocalizer, NonFiniteOdometryIsAnError) {
  fw::OdometryLocalizer loc;
  hal::LaserScan scan;
  hal::PoseEstimate e;
  const fw::Status s = loc.step(scan, odom(std::numeric_limits<float>::quiet_NaN(), 0, 0), &e);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("not finite"), std::string::npos);
  fw::OdometryLocalizerOptions bad;
  bad.sigma_trans_per_m = -1.0f;
  EXPECT_FALSE(bad.validate().is_ok());
}

}  // namespace
