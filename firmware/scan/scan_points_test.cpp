#include "firmware/scan/scan_points.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace fw {
namespace {

TEST(ScanPointsTest, ConvertsAndDropsBadReadings) {
  static hal::LaserScan scan;
  scan.beam_count = 5;
  scan.angle_min = -static_cast<float>(M_PI) / 2;
  scan.angle_increment = static_cast<float>(M_PI) / 4;
  scan.range_min = 0.1f;
  scan.range_max = 10.0f;
  scan.ranges[0] = 1.0f;
  scan.ranges[1] = std::numeric_limits<float>::quiet_NaN();
  scan.ranges[2] = 2.0f;
  scan.ranges[3] = 10.0f;  // no return
  scan.ranges[4] = 0.05f;  // below min
  Point2f pts[8];
  ScanPointsResult res;
  ASSERT_TRUE(scan_to_points(scan, {}, pts, 8, &res).is_ok());
  EXPECT_EQ(res.count, 2u);
  EXPECT_EQ(res.invalid, 1u);
  EXPECT_EQ(res.out_of_range, 2u);
  EXPECT_NEAR(pts[0].x(), 0.0f, 1e-6);
  EXPECT_NEAR(pts[0].y(), -1.0f, 1e-6);
  EXPECT_NEAR(pts[1].x(), 2.0f, 1e-6);
}

TEST(ScanPointsTest, RejectsMalformedHeader) {
  static hal::LaserScan scan;
  scan.beam_count = hal::LaserScan::kMaxBeams + 1;
  Point2f pts[1];
  ScanPointsResult res;
  EXPECT_EQ(scan_to_points(scan, {}, pts, 1, &res).code(), Errc::kInvalidArgument);
  scan.beam_count = 1;
  scan.angle_increment = std::numeric_limits<float>::quiet_NaN();
  scan.range_max = 5;
  EXPECT_EQ(scan_to_points(scan, {}, pts, 1, &res).code(), Errc::kInvalidArgument);
}

}  // namespace
}  // namespace fw
