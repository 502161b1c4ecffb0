#include "firmware/mml/pose_uniqueness.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/map/paired_fit_test.h"
#include "firmware/mml/mml_test_util.h"
#include "firmware/scan/scan_points.h"

namespace fw {
namespace mml {
namespace {

using mcl::testing::GridWorld;

// A 40 m corridor, 2 m wide, with a pillar every 3 m on one wall: seen through an 8 m laser, every
// 3 m shift of the robot looks the same (the aliasing of a real office corridor).
GridWorld periodic_corridor() {
  GridWorld g;
  g.w = 800; g.h = 60;
  g.occ.assign(g.w * g.h, 0);
  g.box(0.5f, 0.5f, 39.5f, 2.5f);
  for (float x = 3.0f; x < 39.0f; x += 3.0f) g.box(x, 0.5f, x + 0.3f, 0.8f);
  g.finish();
  return g;
}

// The same corridor without pillars: its walls fit wherever the robot stands along it.
GridWorld plain_corridor() {
  GridWorld g;
  g.w = 800; g.h = 60;
  g.occ.assign(g.w * g.h, 0);
  g.box(0.5f, 0.5f, 39.5f, 2.5f);
  g.finish();
  return g;
}

std::size_t scan_points_at(const GridWorld& g, const Se2f& pose, Point2f* pts) {
  static hal::LaserScan scan;
  mcl::testing::simulate_scan(g.view(), pose.x, pose.y, pose.theta, &scan);
  ScanPointsResult sr;
  EXPECT_TRUE(scan_to_points(scan, {}, pts, 1081, &sr).is_ok());
  return sr.count;
}

TEST(PoseUniquenessTest, UniqueRoomPoseIsUnique) {
  static GridWorld g = mcl::testing::unique_room();
  static testing::OwnedGlobalMap gm(g);
  static Point2f pts[1081];
  for (const Se2f truth : {Se2f(2.5f, 6.5f, 0.0f), Se2f(4.5f, 2.8f, -1.57f), Se2f(7.0f, 3.0f, 0.7f)}) {
    const std::size_t n = scan_points_at(g, truth, pts);
    const UniquenessResult r = check_pose_uniqueness(gm.map, pts, n, truth, UniquenessOptions());
    EXPECT_TRUE(r.unique) << truth.x << "," << truth.y << ": cost " << r.cost << " rival " << r.rival_cost << " at "
                          << r.rival.x << "," << r.rival.y;
    EXPECT_LT(r.cost, 0.05f);
    EXPECT_EQ(r.rivals_tried, 2u * 2u * 7u);  // 2 axes × 2 signs × 7 steps of 0.4 m up to 3 m
  }
}

TEST(PoseUniquenessTest, OffsetPoseLosesToTheTruePose) {
  // The candidate is 1.2 m off (a wrong cluster); the rival seeded near the truth fits better.
  static GridWorld g = mcl::testing::unique_room();
  static testing::OwnedGlobalMap gm(g);
  static Point2f pts[1081];
  const Se2f truth(4.5f, 2.8f, 0.0f);
  const std::size_t n = scan_points_at(g, truth, pts);
  const Se2f wrong(truth.x + 1.2f, truth.y, truth.theta);
  const UniquenessResult r = check_pose_uniqueness(gm.map, pts, n, wrong, UniquenessOptions());
  EXPECT_FALSE(r.unique) << "cost " << r.cost << " rival " << r.rival_cost;
  EXPECT_LT(r.rival_cost, r.cost);
  EXPECT_LT(std::hypot(r.rival.x - truth.x, r.rival.y - truth.y), 0.2f) << r.rival.x << "," << r.rival.y;
}

UniquenessOptions with_heading_rivals() {
  UniquenessOptions o;
  o.rotation_step_rad = 0.0524f;  // 3°
  o.max_rotation_rad = 0.21f;     // 12°
  return o;
}

TEST(PoseUniquenessTest, HeadingRivalsLeaveTheTruePoseUnique) {
  static GridWorld g = mcl::testing::unique_room();
  static testing::OwnedGlobalMap gm(g);
  static Point2f pts[1081];
  for (const Se2f truth : {Se2f(2.5f, 6.5f, 0.0f), Se2f(4.5f, 2.8f, -1.57f), Se2f(7.0f, 3.0f, 0.7f)}) {
    const std::size_t n = scan_points_at(g, truth, pts);
    const UniquenessResult r = check_pose_uniqueness(gm.map, pts, n, truth, with_heading_rivals());
    EXPECT_TRUE(r.unique) << truth.x << "," << truth.y << ": cost " << r.cost << " rival " << r.rival_cost;
    EXPECT_EQ(r.rivals_tried, 2u * 2u * 7u + 2u * 4u);  // + 2 signs × 4 turns of 3° up to 12°
  }
}

TEST(PoseUniquenessTest, PoseHeldAtAWrongHeadingLosesToATurnedRival) {
  // The candidate has the right position but is turned 7° (a track held by walls near the robot):
  // translation rivals alone keep its heading; a rival seeded turned back finds the truth.
  static GridWorld g = mcl::testing::unique_room();
  static testing::OwnedGlobalMap gm(g);
  static Point2f pts[1081];
  const Se2f truth(4.5f, 2.8f, 0.3f);
  const std::size_t n = scan_points_at(g, truth, pts);
  const Se2f turned(truth.x, truth.y, truth.theta + 0.122f);
  const UniquenessResult r = check_pose_uniqueness(gm.map, pts, n, turned, with_heading_rivals());
  EXPECT_FALSE(r.unique) << "cost " << r.cost << " rival " << r.rival_cost;
  EXPECT_TRUE(r.rival_turned);
  EXPECT_LT(r.rival_cost, r.cost);
  EXPECT_LT(std::fabs(wrap_angle(r.rival.theta - truth.theta)), 0.02f) << r.rival.theta;
}

TEST(PoseUniquenessTest, PeriodicCorridorIsNotUnique) {
  static GridWorld g = periodic_corridor();
  static testing::OwnedGlobalMap gm(g);
  static Point2f pts[1081];
  for (const Se2f truth : {Se2f(18.1f, 1.5f, 0.0f), Se2f(20.0f, 1.7f, 3.14159f), Se2f(21.0f, 1.4f, 0.3f)}) {
    const std::size_t n = scan_points_at(g, truth, pts);
    const UniquenessResult r = check_pose_uniqueness(gm.map, pts, n, truth, UniquenessOptions());
    EXPECT_FALSE(r.unique) << truth.x << ": cost " << r.cost << " rival " << r.rival_cost << " at " << r.rival.x;
    // The rival is an alias along the corridor (x), one pillar period away, not across it.
    EXPECT_NEAR(std::fabs(r.rival.x - truth.x), 3.0f, 0.2f);
    EXPECT_NEAR(r.rival.y, truth.y, 0.1f);
  }
}

// The periodic corridor's rival one period away is a separate look-alike: between the two, the
// pillars fit nowhere (a barrier). Along a corridor without pillars the walls fit all the way: one
// valley. In the unique room a pose 1 m off is neither (its cost is far above the true pose's).
TEST(PoseUniquenessTest, SameCostValleyOnlyAlongAFeaturelessAxis) {
  static GridWorld periodic = periodic_corridor();
  static testing::OwnedGlobalMap pm(periodic);
  static GridWorld plain = plain_corridor();
  static testing::OwnedGlobalMap fm(plain);
  static GridWorld room = mcl::testing::unique_room();
  static testing::OwnedGlobalMap rm(room);
  static Point2f pts[1081];
  const Se2f at(18.1f, 1.5f, 0.0f);
  std::size_t n = scan_points_at(periodic, at, pts);
  const UniquenessResult r = check_pose_uniqueness(pm.map, pts, n, at, UniquenessOptions());
  ASSERT_FALSE(r.unique);
  EXPECT_FALSE(in_same_cost_valley(pm.map, pts, n, at, r.rival, 0.15f, 0.075f, 0.01f));
  EXPECT_TRUE(in_same_cost_valley(pm.map, pts, n, at, Se2f(at.x + 0.05f, at.y, at.theta), 0.15f, 0.075f, 0.01f))
      << "a neighbour closer than one sample is its own valley";
  n = scan_points_at(plain, at, pts);  // 8 m laser: the ends of the 39 m corridor are out of range
  EXPECT_TRUE(in_same_cost_valley(fm.map, pts, n, at, Se2f(at.x + 2.5f, at.y, at.theta), 0.15f, 0.075f, 0.01f));
  EXPECT_TRUE(in_same_cost_valley(fm.map, pts, n, at, Se2f(at.x - 2.5f, at.y, at.theta), 0.15f, 0.075f, 0.01f));
  EXPECT_FALSE(in_same_cost_valley(fm.map, pts, n, at, Se2f(at.x + 2.5f, at.y + 0.5f, at.theta), 0.15f, 0.075f, 0.01f))
      << "across the corridor the walls do not fit";
  const Se2f room_pose(4.0f, 3.0f, 0.3f);
  n = scan_points_at(room, room_pose, pts);
  EXPECT_FALSE(in_same_cost_valley(rm.map, pts, n, room_pose, Se2f(5.0f, 3.0f, 0.3f), 0.15f, 0.075f, 0.01f));
}

// UniquenessOptions::valley_is_one_mode: along the plain corridor every rival is the scan's own
// weak axis (one valley): not unique when every rival counts, unique when the valley is one mode.
// The periodic corridor's rivals one pillar period away are separate look-alikes: not unique either
// way, and the rival reported is still the look-alike one period away.
TEST(PoseUniquenessTest, ValleyRivalsAreOneModeSeparateLookAlikesAreNot) {
  static GridWorld periodic = periodic_corridor();
  static testing::OwnedGlobalMap pm(periodic);
  static GridWorld plain = plain_corridor();
  static testing::OwnedGlobalMap fm(plain);
  static Point2f pts[1081];
  UniquenessOptions every, one_mode;
  one_mode.valley_is_one_mode = true;
  const Se2f at(18.1f, 1.5f, 0.0f);
  std::size_t n = scan_points_at(plain, at, pts);
  const UniquenessResult all = check_pose_uniqueness(fm.map, pts, n, at, every);
  EXPECT_FALSE(all.unique);
  EXPECT_EQ(all.same_valley_rivals, 0u);
  const UniquenessResult valley = check_pose_uniqueness(fm.map, pts, n, at, one_mode);
  EXPECT_TRUE(valley.unique) << "rival " << valley.rival.x << " cost " << valley.rival_cost << " vs " << valley.cost;
  EXPECT_GE(valley.same_valley_rivals, 10u) << "0.4 m seeds up to 3 m both ways along the corridor";
  n = scan_points_at(periodic, at, pts);
  const UniquenessResult look_alike = check_pose_uniqueness(pm.map, pts, n, at, one_mode);
  EXPECT_FALSE(look_alike.unique);
  EXPECT_NEAR(std::fabs(look_alike.rival.x - at.x), 3.0f, 0.2f);
}

TEST(PoseUniquenessTest, EmptyInputIsHandled) {
  static GridWorld g = mcl::testing::unique_room();
  static testing::OwnedGlobalMap gm(g);
  const UniquenessResult r = check_pose_uniqueness(gm.map, nullptr, 0, Se2f(1.0f, 1.0f, 0.0f), UniquenessOptions());
  EXPECT_TRUE(r.unique);
  EXPECT_EQ(r.rivals_tried, 0u);
  EXPECT_FLOAT_EQ(truncated_scan_cost(gm.map, nullptr, 0, Se2f(), 0.15f), 1.0f);
}


// Issue 58: the paired test against a pose sampled once (PairedFitReference, the confidence extent's)
// gives rival_significantly_better's verdict at every shift and turn; with more end-points than it
// holds it falls back to the same function.
TEST(PairedFitReferenceTest, SameVerdictAsThePairedTest) {
  static GridWorld g = periodic_corridor();
  static testing::OwnedGlobalMap gm(g);
  static Point2f pts[2 * 1081];
  const Se2f fix(10.0f, 1.5f, 0.1f);
  std::size_t n = scan_points_at(g, fix, pts);
  for (std::size_t i = 0; i < n; ++i) pts[n + i] = pts[i];  // the scan twice: more than the reference holds
  n *= 2;
  ASSERT_GT(n, PairedFitReference::kMaxPoints);  // the fallback is exercised below
  int better = 0, not_better = 0;
  for (const std::size_t m : {std::size_t{2}, std::size_t{90}, std::size_t{180}, n}) {
    const PairedFitReference ref(gm.map, pts, m, fix, 0.15f);
    for (float s = -1.0f; s <= 1.0f; s += 0.05f) {
      for (const float dth : {0.0f, 0.02f, -0.05f}) {
        const Se2f r(fix.x + s, fix.y + 0.3f * s, fix.theta + dth);
        for (const float z : {1.645f, 3.09f}) {
          const bool want = rival_significantly_better(gm.map, pts, m, r, fix, 0.15f, 20, z);
          EXPECT_EQ(ref.fixed_better_than(r, 20, z), want) << m << " " << s << " " << dth << " " << z;
          (want ? better : not_better)++;
        }
      }
    }
  }
  EXPECT_GT(better, 0);
  EXPECT_GT(not_better, 0);
}

}  // namespace
}  // namespace mml
}  // namespace fw
