#include "firmware/mml/pose_refiner.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/mml/mml_test_util.h"
#include "firmware/mml/pose_uniqueness.h"
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

// Issue 58: the refinement's vector sums and batched samples give the scalar build's bits, and the
// cost it reports is truncated_scan_cost's at the pose it returns — from near seeds (accepted) and
// from seeds too far to be accepted (the result is the seed).
TEST(PoseRefinerTest, EveryBuildGivesTheSameBitsAndTheCostOfItsPose) {
  static testing::GridWorld g = mcl::testing::unique_room();
  static testing::OwnedGlobalMap gm(g);
  static hal::LaserScan scan;
  RefineOptions o;
  o.max_shift_m = 0.4f;  // as the alias check's rivals: far seeds are rejected
  int accepted = 0, rejected = 0;
  for (const Se2f truth : {Se2f(2.5f, 6.5f, 0.0f), Se2f(4.5f, 2.8f, -1.57f), Se2f(7.0f, 3.0f, 0.7f)}) {
    mcl::testing::simulate_scan(g.view(), truth.x, truth.y, truth.theta, &scan);
    static Point2f pts[1081];
    ScanPointsResult sr;
    ASSERT_TRUE(scan_to_points(scan, {}, pts, 1081, &sr).is_ok());
    for (const Se2f off : {Se2f(0.2f, 0.0f, 0.0f), Se2f(-0.15f, 0.1f, 0.05f), Se2f(0.8f, -0.6f, 0.2f),
                           Se2f(1.6f, 0.4f, -0.3f), Se2f(0.0f, 0.0f, 0.21f)}) {
      const Se2f start(truth.x + off.x, truth.y + off.y, truth.theta + off.theta);
      const RefineResult a = refine_pose(gm.map, pts, sr.count, start, o);
      const RefineResult b = refine_pose(gm.map, pts, sr.count, start, o, DistanceBatchBuild::kScalar);
      EXPECT_EQ(a.pose.x, b.pose.x);
      EXPECT_EQ(a.pose.y, b.pose.y);
      EXPECT_EQ(a.pose.theta, b.pose.theta);
      EXPECT_EQ(a.inlier_ratio, b.inlier_ratio);
      EXPECT_EQ(a.rms_m, b.rms_m);
      EXPECT_EQ(a.accepted, b.accepted);
      ASSERT_TRUE(a.cost_valid);
      EXPECT_EQ(a.cost, b.cost);
      EXPECT_EQ(a.cost, truncated_scan_cost(gm.map, pts, sr.count, a.pose, o.clip_m)) << start.x << " " << start.y;
      (a.accepted ? accepted : rejected)++;
    }
  }
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace mml
}  // namespace fw
