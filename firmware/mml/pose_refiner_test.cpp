#include "firmware/mml/pose_refiner.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/mml/mml_test_util.h"
#include "firmware/scan/scan_points.h"

namespace fw {
namespace mml {
namespace {

TEST(PoseRefinerTest, ConvergesFromOffsetPose) {
  static testing::GridWorld g = mcl::testing::unique_room();
  static testing::OwnedGlobalMap gm(g);
  static hal::LaserScan scan;
  for (const Se2f truth : {Se2f(2.5f, 6.5f, 0.0f), Se2f(4.5f, 2.8f, -1.57f), Se2f(7.0f, 3.0f, 0.7f)}) {
    mcl::testing::simulate_scan(g.view(), truth.x, truth.y, truth.theta, &scan);
    static Point2f pts[1081];
    ScanPointsResult sr;
    ASSERT_TRUE(scan_to_points(scan, {}, pts, 1081, &sr).is_ok());
    for (const Se2f off : {Se2f(0.2f, 0.0f, 0.0f), Se2f(-0.15f, 0.1f, 0.05f), Se2f(0.0f, 0.0f, -0.08f)}) {
      const Se2f start(truth.x + off.x, truth.y + off.y, truth.theta + off.theta);
      const RefineResult r = refine_pose(gm.map, pts, sr.count, start, RefineOptions());
      EXPECT_TRUE(r.accepted);
      EXPECT_NEAR(r.pose.x, truth.x, 0.03f) << truth.x << " " << off.x;
      EXPECT_NEAR(r.pose.y, truth.y, 0.03f) << truth.y << " " << off.y;
      EXPECT_NEAR(r.pose.theta, truth.theta, 0.01f);
    }
  }
}

}  // namespace
}  // namespace mml
}  // namespace fw
