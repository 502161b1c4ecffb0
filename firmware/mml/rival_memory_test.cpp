// RivalMemory: a rival leaves the memory only when the local map contradicts it.
#include "firmware/mml/rival_memory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "firmware/base/rng.h"
#include "firmware/map/paired_fit_test.h"
#include "firmware/mml/mml_test_util.h"
#include "firmware/scan/scan_points.h"

namespace fw {
namespace mml {
namespace {

using mcl::testing::GridWorld;
using testing::OwnedGlobalMap;

// Two 12 × 8 m rooms side by side, the second a copy of the first shifted by 12 m (a twin), and
// optionally a 4.3 m partition only in the second, in view of the test pose (a single small box is
// not enough: a couple of correlation cells could be a person standing there).
GridWorld twin_rooms(bool mark_second) {
  GridWorld g;
  g.w = 480;
  g.h = 160;
  g.occ.assign(g.w * g.h, 0);
  for (const float ox : {0.0f, 12.0f}) {
    g.box(ox + 0.2f, 0.2f, ox + 11.8f, 7.8f);
    g.wall(ox + 3.0f, 0.2f, ox + 3.0f, 3.0f);
    g.wall(ox + 7.0f, 7.8f, ox + 7.0f, 5.0f);
    g.wall(ox + 5.0f, 4.0f, ox + 6.5f, 4.0f);
  }
  if (mark_second) g.wall(12.0f + 9.0f, 0.2f, 12.0f + 9.0f, 4.5f);
  g.finish();
  return g;
}

// End-points of a scan at `pose` in the local frame (here the local frame is the robot's).
std::vector<Point2f> scan_points_at(const GridWorld& w, const Se2f& pose) {
  static hal::LaserScan scan;
  mcl::testing::simulate_scan(w.view(), pose.x, pose.y, pose.theta, &scan, 8.0f);
  RandomStream rng(7, 1);
  for (std::uint32_t b = 0; b < scan.beam_count; ++b)
    if (scan.ranges[b] < scan.range_max) scan.ranges[b] += 0.01f * static_cast<float>(rng.gaussian());
  std::vector<Point2f> pts(hal::LaserScan::kMaxBeams);
  ScanPointsResult r;
  ScanPointsOptions so;
  EXPECT_TRUE(scan_to_points(scan, so, pts.data(), pts.size(), &r).is_ok());
  pts.resize(r.count);
  return pts;
}

Cluster cluster_at(const Se2f& p, float rating) {
  Cluster c;
  c.x = p.x;
  c.y = p.y;
  c.theta = p.theta;
  c.rating = rating;
  return c;
}

const Se2f kPose(7.5f, 2.0f, 0.3f);  // in the first room, facing the partition's place in the second

TEST(RivalMemoryTest, ATwinThatLeftTheClustersStaysOpen) {
  const GridWorld world = twin_rooms(false);
  const OwnedGlobalMap map(world);
  const std::vector<Point2f> pts = scan_points_at(world, kPose);
  MmlOptions o;
  RivalMemory mem;
  // Step 1: both places are clusters; step 2: only the true one is returned.
  const Se2f twin(kPose.x + 12.0f, kPose.y, kPose.theta);
  const Cluster both[2] = {cluster_at(kPose, 0.5f), cluster_at(twin, 0.5f)};
  mem.observe(both, 2, Se2f(), o, 1);
  const Cluster one[1] = {cluster_at(kPose, 1.0f)};
  mem.observe(one, 1, Se2f(), o, 2);
  ASSERT_EQ(mem.size(), 2u);
  const RivalCheck r = mem.check(map.map, pts.data(), pts.size(), kPose, Se2f(), o);
  EXPECT_FALSE(r.resolved);
  EXPECT_EQ(r.checked, 1u);
  EXPECT_EQ(r.contradicted, 0u);
  EXPECT_NEAR(r.open_rival.x, twin.x, 0.1f);
  EXPECT_EQ(mem.size(), 2u);  // still remembered
}

TEST(RivalMemoryTest, ARivalRememberedAFewCentimetresOffIsRefinedBeforeItIsJudged) {
  const GridWorld world = twin_rooms(false);
  const OwnedGlobalMap map(world);
  const std::vector<Point2f> pts = scan_points_at(world, kPose);
  MmlOptions o;
  RivalMemory mem;
  // A cluster mean is a few hypotheses' average, not an aligned pose.
  const Se2f twin_off(kPose.x + 12.0f + 0.15f, kPose.y - 0.12f, kPose.theta + 0.04f);
  const Cluster c[1] = {cluster_at(twin_off, 1.0f)};
  mem.observe(c, 1, Se2f(), o, 1);
  const RivalCheck r = mem.check(map.map, pts.data(), pts.size(), kPose, Se2f(), o);
  EXPECT_FALSE(r.resolved);
  // Unrefined, the same rival is contradicted: the refinement is what makes the test fair.
  EXPECT_TRUE(rival_significantly_better(map.map, pts.data(), pts.size(), twin_off, kPose, o.rival_clip_m,
                                         r.independent, o.rival_z));
}

TEST(RivalMemoryTest, TheLocalMapContradictsTheTwinOnceItSeesWhatDiffers) {
  const GridWorld world = twin_rooms(true);  // a partition only in the second room
  const OwnedGlobalMap map(world);
  MmlOptions o;
  RivalMemory mem;
  const Se2f twin(kPose.x + 12.0f, kPose.y, kPose.theta);
  // The robot is in the second room and sees the partition; the first room has nothing where its
  // end-points fall, so the rival there is rejected and forgotten.
  const std::vector<Point2f> pts = scan_points_at(world, twin);
  const Cluster c[1] = {cluster_at(kPose, 1.0f)};
  mem.observe(c, 1, Se2f(), o, 1);
  const RivalCheck r = mem.check(map.map, pts.data(), pts.size(), twin, Se2f(), o);
  EXPECT_TRUE(r.resolved);
  EXPECT_EQ(r.contradicted, 1u);
  EXPECT_EQ(mem.size(), 0u);  // forgotten for good
  // The other way round the end-points prove nothing: in the first room the scan passes where the
  // second room's partition stands and ends on walls both rooms have. The test judges end-points only,
  // so that rival stays open (the status stays `ambiguous`: the safe side).
  const std::vector<Point2f> pts1 = scan_points_at(world, kPose);
  const Cluster c2[1] = {cluster_at(twin, 1.0f)};
  mem.observe(c2, 1, Se2f(), o, 2);
  EXPECT_FALSE(mem.check(map.map, pts1.data(), pts1.size(), kPose, Se2f(), o).resolved);
}

TEST(RivalMemoryTest, ACandidateTheLocalMapRejectsInFavourOfARivalIsFlagged) {
  // The robot stands in the second room (it sees the partition) and MML's candidate is the first
  // room: the remembered rival (the true room) fits significantly better, so the candidate is not
  // only held back but rejected (mml_localizer.cpp drops it instead of keeping it pending).
  const GridWorld world = twin_rooms(true);
  const OwnedGlobalMap map(world);
  MmlOptions o;
  RivalMemory mem;
  const Se2f twin(kPose.x + 12.0f, kPose.y, kPose.theta);
  const std::vector<Point2f> pts = scan_points_at(world, twin);
  const Cluster c[1] = {cluster_at(twin, 1.0f)};
  mem.observe(c, 1, Se2f(), o, 1);
  const RivalCheck r = mem.check(map.map, pts.data(), pts.size(), kPose, Se2f(), o);
  EXPECT_FALSE(r.resolved);
  EXPECT_TRUE(r.candidate_rejected);
  // In the twin world without the partition neither is better: held back, not rejected.
  const GridWorld same = twin_rooms(false);
  const OwnedGlobalMap same_map(same);
  const std::vector<Point2f> pts2 = scan_points_at(same, twin);
  const RivalCheck r2 = mem.check(same_map.map, pts2.data(), pts2.size(), kPose, Se2f(), o);
  EXPECT_FALSE(r2.resolved);
  EXPECT_FALSE(r2.candidate_rejected);
}

TEST(RivalMemoryTest, TheCandidateItselfAndWeakClustersAreNoRivals) {
  const GridWorld world = twin_rooms(false);
  const OwnedGlobalMap map(world);
  const std::vector<Point2f> pts = scan_points_at(world, kPose);
  MmlOptions o;
  RivalMemory mem;
  const Se2f near(kPose.x + 0.3f, kPose.y, kPose.theta + 0.05f);           // within the separation
  const Se2f twin(kPose.x + 12.0f, kPose.y, kPose.theta);                  // rated far below the best
  const Cluster c[3] = {cluster_at(kPose, 1.0f), cluster_at(near, 0.9f), cluster_at(twin, 0.2f)};
  mem.observe(c, 3, Se2f(), o, 1);
  EXPECT_EQ(mem.size(), 1u);  // `near` merged into the best's entry, the twin too weak
  const RivalCheck r = mem.check(map.map, pts.data(), pts.size(), kPose, Se2f(), o);
  EXPECT_TRUE(r.resolved);
  EXPECT_EQ(r.checked, 0u);
}

TEST(RivalMemoryTest, RivalsAreRememberedInTheLocalFrameAndFollowTheRobot) {
  // The rival is seen while the robot is at local pose A and judged when it is at B: H = robot ⊖
  // local pose is fixed, so the rival robot pose moves with the local map, not with stale odometry.
  const GridWorld world = twin_rooms(false);
  const OwnedGlobalMap map(world);
  MmlOptions o;
  RivalMemory mem;
  const Se2f h_true(2.0f, 1.0f, 0.2f);  // map ← local
  const Se2f local_a(1.0f, 0.5f, 0.1f);
  const Se2f robot_a = h_true.compose(local_a);
  const Se2f twin_a(robot_a.x + 12.0f, robot_a.y, robot_a.theta);
  const Cluster c[1] = {cluster_at(twin_a, 1.0f)};
  mem.observe(c, 1, local_a, o, 1);
  const Se2f robot_b = kPose;
  const Se2f local_b = h_true.inverse().compose(robot_b);
  const std::vector<Point2f> robot_pts = scan_points_at(world, robot_b);
  std::vector<Point2f> local_pts;
  for (const Point2f& p : robot_pts) local_pts.push_back(local_b.transform_point(p));
  const RivalCheck r = mem.check(map.map, local_pts.data(), local_pts.size(), h_true, local_b, o);
  EXPECT_FALSE(r.resolved);
  EXPECT_NEAR(r.open_rival.x, robot_b.x + 12.0f, 0.1f);
  EXPECT_NEAR(r.open_rival.y, robot_b.y, 0.1f);
}

TEST(RivalMemoryTest, AFullMemoryKeepsItsStrongestEntries) {
  MmlOptions o;
  RivalMemory mem;
  for (std::size_t i = 0; i < kMaxRivals; ++i) {
    const Cluster c[2] = {cluster_at(Se2f(100.0f, 0.0f, 0.0f), 1.0f),
                          cluster_at(Se2f(5.0f * static_cast<float>(i), 50.0f, 0.0f), 0.6f)};
    mem.observe(c, 2, Se2f(), o, i);
  }
  EXPECT_EQ(mem.size(), kMaxRivals);
  // A weaker newcomer does not displace anything; a best cluster does (displacing a 0.6 entry).
  const Cluster weak[2] = {cluster_at(Se2f(100.0f, 0.0f, 0.0f), 1.0f), cluster_at(Se2f(0.0f, -40.0f, 0.0f), 0.55f)};
  mem.observe(weak, 2, Se2f(), o, 100);
  EXPECT_EQ(mem.size(), kMaxRivals);
  const Cluster strong[1] = {cluster_at(Se2f(0.0f, -80.0f, 0.0f), 1.0f)};
  mem.observe(strong, 1, Se2f(), o, 101);
  EXPECT_EQ(mem.size(), kMaxRivals);
}

}  // namespace
}  // namespace mml
}  // namespace fw
