#include "firmware/track/dead_reckoning.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/track/track_test_util.h"

namespace fw {
namespace track {
namespace {

Eigen::Matrix3f dr_cov(float sxy, float sth) {
  Eigen::Matrix3f c = Eigen::Matrix3f::Zero();
  c(0, 0) = c(1, 1) = sxy * sxy;
  c(2, 2) = sth * sth;
  return c;
}

// The wheels carry the pose exactly; the covariance grows by the tracker's model: heading variance
// by Σ σ_r² of the increments (α model: 0.2 rad per metre and per radian), position faster than
// heading alone would make it (the lever of the heading error).
TEST(DeadReckoningTest, CarriesThePoseAndGrowsTheCovarianceByTheOdometryModel) {
  const TrackOptions o;
  DeadReckoning dr;
  EXPECT_FALSE(dr.active());
  const Se2f start(1.0f, 2.0f, 0.5f), wheel0(10.0f, -3.0f, 1.0f);
  dr.start(start, dr_cov(0.05f, 0.01f), wheel0, true, true);
  Se2f wheel = wheel0, truth = start;
  float var_theta = 0.01f * 0.01f;
  for (int i = 0; i < 40; ++i) {
    const Se2f d(0.1f, 0.0f, i < 20 ? 0.0f : 0.05f);
    wheel = wheel.compose(d);
    truth = truth.compose(d);
    const float sr = 0.2f * std::fabs(d.theta) + 0.2f * 0.1f;
    var_theta += sr * sr;
    dr.advance(wheel, o);
  }
  EXPECT_NEAR(dr.pose().x, truth.x, 1e-4f);
  EXPECT_NEAR(dr.pose().y, truth.y, 1e-4f);
  EXPECT_NEAR(dr.pose().theta, truth.theta, 1e-5f);
  EXPECT_NEAR(dr.cov()(2, 2), var_theta, 1e-6f);
  EXPECT_GT(dr.cov()(0, 0) + dr.cov()(1, 1), 2.0f * 0.05f * 0.05f + 40 * 2 * 0.02f * 0.02f);
}

// A binding chain admits a fix inside its protection level plus the alert limits and refuses one
// turned round or far away; a chain that does not bind admits anything.
TEST(DeadReckoningTest, AdmitsOnlyFixesWithinItsProtectionLevel) {
  const TrackOptions o;
  const ProtectionFactors k = ProtectionFactors::for_risk(o.integrity_risk);
  DeadReckoning dr;
  dr.start(Se2f(5.0f, 2.0f, 0.0f), dr_cov(0.1f, 0.02f), Se2f(), true, true);
  const ProtectionLevel pl = dr.bound(k);
  EXPECT_NEAR(pl.xy_m, k.k_xy * 0.1f, 1e-4f);
  EXPECT_TRUE(dr.admits(Se2f(5.0f + pl.xy_m + 0.4f, 2.0f, 0.0f), k, o));
  EXPECT_FALSE(dr.admits(Se2f(5.0f + pl.xy_m + 0.6f, 2.0f, 0.0f), k, o));
  EXPECT_TRUE(dr.admits(Se2f(5.0f, 2.0f, pl.theta_rad + 0.08f), k, o));
  EXPECT_FALSE(dr.admits(Se2f(5.0f, 2.0f, pl.theta_rad + 0.1f), k, o));
  EXPECT_FALSE(dr.admits(Se2f(6.2f, 6.1f, 3.1f), k, o));  // the mapped room turned round
  DeadReckoning loose;
  loose.start(Se2f(5.0f, 2.0f, 0.0f), dr_cov(0.1f, 0.02f), Se2f(), false, true);
  EXPECT_TRUE(loose.admits(Se2f(6.2f, 6.1f, 3.1f), k, o));
  EXPECT_TRUE(loose.trusted());
  loose.start(Se2f(5.0f, 2.0f, 0.0f), dr_cov(0.1f, 0.02f), Se2f(), false, false);  // after a carry
  EXPECT_FALSE(loose.trusted());
  loose.clear();
  EXPECT_FALSE(loose.active());
  EXPECT_FALSE(loose.trusted());
  EXPECT_TRUE(loose.admits(Se2f(6.2f, 6.1f, 3.1f), k, o));
}

// The scan at the carried pose: mostly unknown space → outside; on the map at the right pose, or
// within the alignment's reach of it (0.85 m here), → fits; on the map turned 86° → contradicts, and max_faulty_steps contradictions in a row
// release the chain (the scans refute the wheels). Anything else in between restarts the count.
TEST(DeadReckoningTest, ScansAtTheCarriedPoseJudgeIt) {
  static mml::testing::UnknownWorld uw;  // the map knows x < 6 m; the world goes on beyond
  static testing::OwnedGlobalMap gm(uw.mapped);
  const TrackOptions o;
  RandomStream rng(7, 1);
  const Se2f in_room(2.0f, 4.0f, 0.3f), in_wing(9.5f, 2.5f, 0.0f), wrong(2.0f, 4.0f, -1.2f);
  const auto room_scan = testing::scan_at(uw.world, in_room, &rng);
  const auto wing_scan = testing::scan_at(uw.world, in_wing, &rng);
  DeadReckoning dr;
  EXPECT_EQ(dr.judge(gm.map, room_scan.data(), room_scan.size(), o), DeadReckoningVerdict::kSaysNothing);  // inactive
  dr.start(in_wing, dr_cov(0.1f, 0.02f), Se2f(), true, true);
  EXPECT_EQ(dr.judge(gm.map, wing_scan.data(), wing_scan.size(), o), DeadReckoningVerdict::kOutside);
  dr.start(in_room, dr_cov(0.1f, 0.02f), Se2f(), true, true);
  EXPECT_EQ(dr.judge(gm.map, room_scan.data(), room_scan.size(), o), DeadReckoningVerdict::kFits);
  dr.start(Se2f(2.6f, 3.4f, 0.3f), dr_cov(0.1f, 0.02f), Se2f(), true, true);  // the wheels' drift is no contradiction
  EXPECT_EQ(dr.judge(gm.map, room_scan.data(), room_scan.size(), o), DeadReckoningVerdict::kFits);
  dr.start(wrong, dr_cov(0.1f, 0.02f), Se2f(), true, true);
  for (std::uint32_t i = 1; i < o.max_faulty_steps; ++i) {
    EXPECT_EQ(dr.judge(gm.map, room_scan.data(), room_scan.size(), o), DeadReckoningVerdict::kContradicts);
    EXPECT_TRUE(dr.binding()) << i;
  }
  EXPECT_EQ(dr.judge(gm.map, room_scan.data(), room_scan.size(), o), DeadReckoningVerdict::kContradicts);
  EXPECT_FALSE(dr.binding());
  EXPECT_FALSE(dr.trusted());  // refuted: its pose no longer says where the robot is (outside-map)
  EXPECT_TRUE(dr.active());  // still carried
  EXPECT_EQ(dr.contradicting_steps(), o.max_faulty_steps);
  // One scan that is not a contradiction restarts the count.
  dr.start(wrong, dr_cov(0.1f, 0.02f), Se2f(), true, true);
  for (std::uint32_t i = 1; i < o.max_faulty_steps; ++i) dr.judge(gm.map, room_scan.data(), room_scan.size(), o);
  dr.judge(gm.map, room_scan.data(), 0, o);
  EXPECT_EQ(dr.judge(gm.map, room_scan.data(), room_scan.size(), o), DeadReckoningVerdict::kContradicts);
  EXPECT_TRUE(dr.binding());
}

}  // namespace
}  // namespace track
}  // namespace fw
