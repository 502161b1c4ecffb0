// MclLocalizer: the AMCL-style update gate (update_min_d / update_min_a) and reset() giving a
// fresh start (same inputs after reset() ⇒ bit-identical outputs to a freshly initialised object).
#include "firmware/baselines/mcl/mcl_localizer.h"
#include "firmware/baselines/mcl/mcl_presets.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "firmware/baselines/mcl/mcl_test_world.h"

namespace fw {
namespace mcl {
namespace {

using testing::GridWorld;

// The hand-off tracking configuration the product ships (mcl_presets.h).
MclOptions tracking_options() { return mcl_tracking_options(1); }

hal::Odometry odometry(const Se2f& p) {
  hal::Odometry o;
  o.x = p.x;
  o.y = p.y;
  o.theta = p.theta;
  return o;
}

Eigen::Matrix3f start_cov() {
  Eigen::Matrix3f c = Eigen::Matrix3f::Zero();
  c(0, 0) = c(1, 1) = 0.05f * 0.05f;
  c(2, 2) = 0.03f * 0.03f;
  return c;
}

// Standing still: 200 scans of the same place with the same odometry. Before the gate every scan
// re-weighted and (every few scans) resampled the cloud, with the motion model's noise floor
// diffusing it in between: the estimate random-walked although nothing moved.
TEST(MclLocalizerTest, StandingStillNeitherUpdatesNorDrifts) {
  static GridWorld g = testing::unique_room();
  static MclLocalizer loc;
  ASSERT_TRUE(loc.init(tracking_options(), g.view(), nullptr).is_ok());
  const Se2f truth(2.0f, 5.0f, 0.4f);
  const hal::Odometry odom = odometry(Se2f(10.0f, -3.0f, 1.0f));  // odometry frame ≠ map frame
  ASSERT_TRUE(loc.start_tracking(truth, start_cov(), odom).is_ok());
  static hal::LaserScan scan;
  testing::simulate_scan(g.view(), truth.x, truth.y, truth.theta, &scan);
  hal::PoseEstimate first, est;
  ASSERT_TRUE(loc.step(scan, odom, &first).is_ok());  // the first scan after start_tracking is used
  ASSERT_EQ(first.status, hal::LocalizationStatus::kLocalized);
  EXPECT_LT(std::hypot(first.x - truth.x, first.y - truth.y), 0.1f);
  const std::uint64_t updates = loc.filter().updates(), resamples = loc.filter().resamples();
  EXPECT_EQ(updates, 1u);
  EXPECT_TRUE(loc.last_step_updated());
  float max_dev = 0.0f, max_dth = 0.0f;
  for (int i = 0; i < 200; ++i) {
    ASSERT_TRUE(loc.step(scan, odom, &est).is_ok());
    EXPECT_FALSE(loc.last_step_updated()) << i;
    max_dev = std::fmax(max_dev, std::hypot(est.x - first.x, est.y - first.y));
    max_dth = std::fmax(max_dth, std::fabs(wrap_angle(est.theta - first.theta)));
    ASSERT_EQ(est.status, first.status) << i;
    ASSERT_EQ(est.mode, first.mode) << i;
    for (int k = 0; k < 9; ++k) ASSERT_EQ(est.cov[k], first.cov[k]) << i;
  }
  EXPECT_LT(max_dev, 1e-5f) << "estimate drifted while the robot stood still";
  EXPECT_LT(max_dth, 1e-5f);
  EXPECT_EQ(loc.filter().updates(), updates) << "sensor updates while standing still";
  EXPECT_EQ(loc.filter().resamples(), resamples) << "resampling while standing still";
  EXPECT_EQ(loc.gated_steps(), 200u);
}

// Creeping: small odometry increments accumulate until the gate opens (0.03 m steps: every 4th
// scan; 0.04 rad turns: every 3rd); in between the published pose follows the odometry.
TEST(MclLocalizerTest, GateOpensOnAccumulatedMotion) {
  static GridWorld g = testing::unique_room();
  static MclLocalizer loc;
  const MclOptions o = tracking_options();
  ASSERT_EQ(o.update_min_d, 0.10f);
  ASSERT_EQ(o.update_min_a, 0.10f);
  ASSERT_TRUE(loc.init(o, g.view(), nullptr).is_ok());
  Se2f truth(2.0f, 5.0f, 0.0f), odom(-1.0f, 2.0f, -0.5f);
  ASSERT_TRUE(loc.start_tracking(truth, start_cov(), odometry(odom)).is_ok());
  static hal::LaserScan scan;
  hal::PoseEstimate est;
  std::vector<int> updated_at;
  for (int i = 0; i <= 70; ++i) {
    if (i > 0) {
      const Se2f u = i <= 40 ? Se2f(0.03f, 0.0f, 0.0f) : Se2f(0.0f, 0.0f, 0.04f);
      truth = truth.compose(u);
      odom = odom.compose(u);
    }
    testing::simulate_scan(g.view(), truth.x, truth.y, truth.theta, &scan);
    ASSERT_TRUE(loc.step(scan, odometry(odom), &est).is_ok());
    if (loc.last_step_updated()) updated_at.push_back(i);
    EXPECT_LT(std::hypot(est.x - truth.x, est.y - truth.y), 0.05f) << i;
    EXPECT_LT(std::fabs(wrap_angle(est.theta - truth.theta)), 0.03f) << i;
    EXPECT_EQ(est.status, hal::LocalizationStatus::kLocalized) << i;
  }
  const std::vector<int> expected = {0,  4,  8,  12, 16, 20, 24, 28, 32, 36, 40,
                                     43, 46, 49, 52, 55, 58, 61, 64, 67, 70};
  EXPECT_EQ(updated_at, expected);
  EXPECT_EQ(loc.filter().updates(), expected.size());
  EXPECT_EQ(loc.gated_steps(), 71u - expected.size());
}

TEST(MclLocalizerTest, UpdateGateOptionsValidated) {
  MclOptions o;
  o.update_min_d = -0.1f;
  Status s = o.validate();
  EXPECT_NE(std::string(s.message()).find("update_min_d"), std::string::npos) << s.message();
  o = MclOptions();
  o.update_min_a = std::nanf("");
  s = o.validate();
  EXPECT_NE(std::string(s.message()).find("update_min_a"), std::string::npos) << s.message();
  o.update_min_a = 4.0f;  // more than half a turn can never be reached by a wrapped angle
  EXPECT_FALSE(o.validate().is_ok());
  o.update_min_a = 0.0f;
  o.update_min_d = 0.0f;  // 0, 0: every scan
  EXPECT_TRUE(o.validate().is_ok());
}

struct Step {
  Se2f truth;
  Se2f odom;
};

// Path in the unique room with odometry starting at `odom0` (exact odometry).
std::vector<Step> make_steps(const Se2f& start, const Se2f& odom0, int n, const Se2f& u) {
  std::vector<Step> s;
  Se2f truth = start, odom = odom0;
  for (int i = 0; i < n; ++i) {
    s.push_back({truth, odom});
    truth = truth.compose(u);
    odom = odom.compose(u);
  }
  return s;
}

std::vector<hal::PoseEstimate> run(MclLocalizer* loc, const GridWorld& g, const std::vector<Step>& steps) {
  static hal::LaserScan scan;
  std::vector<hal::PoseEstimate> out;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    testing::simulate_scan(g.view(), steps[i].truth.x, steps[i].truth.y, steps[i].truth.theta, &scan);
    scan.scan_id = static_cast<std::uint32_t>(i);
    hal::PoseEstimate e;
    EXPECT_TRUE(loc->step(scan, odometry(steps[i].odom), &e).is_ok());
    out.push_back(e);
  }
  return out;
}

void expect_identical(const std::vector<hal::PoseEstimate>& a, const std::vector<hal::PoseEstimate>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].x, b[i].x) << i;
    EXPECT_EQ(a[i].y, b[i].y) << i;
    EXPECT_EQ(a[i].theta, b[i].theta) << i;
    for (int k = 0; k < 9; ++k) EXPECT_EQ(a[i].cov[k], b[i].cov[k]) << i << " cov " << k;
    EXPECT_EQ(a[i].status, b[i].status) << i;
    EXPECT_EQ(a[i].mode, b[i].mode) << i;
  }
}

// A trial's result must not depend on the trials before it: A, then B, then reset() and A again
// gives bit-identically what A gives on a freshly initialised localizer.
TEST(MclLocalizerTest, ResetGivesAFreshStart) {
  static GridWorld g = testing::unique_room();
  static MclLocalizer fresh, used;
  MclOptions o;
  o.num_particles = 3000;
  ASSERT_TRUE(fresh.init(o, g.view(), nullptr).is_ok());
  ASSERT_TRUE(used.init(o, g.view(), nullptr).is_ok());
  // A: global localization (uniform start) driving along the room.
  const auto a = make_steps(Se2f(1.5f, 1.5f, 0.3f), Se2f(0, 0, 0), 14, Se2f(0.15f, 0.0f, 0.05f));
  // B: a global run elsewhere, then a tracking start, standing still and moving on.
  const auto b1 = make_steps(Se2f(9.0f, 6.0f, -2.0f), Se2f(3, 4, 1), 6, Se2f(0.15f, 0.0f, -0.05f));
  const auto b2 = make_steps(Se2f(4.0f, 6.0f, 0.0f), Se2f(-2, 1, 0.5f), 9, Se2f(0.04f, 0.0f, 0.0f));
  const auto ref = run(&fresh, g, a);
  const auto first = run(&used, g, a);
  expect_identical(ref, first);  // same seed, same inputs
  run(&used, g, b1);
  ASSERT_TRUE(used.start_tracking(b2[0].truth, start_cov(), odometry(b2[0].odom)).is_ok());
  run(&used, g, b2);
  used.reset();
  const auto again = run(&used, g, a);
  expect_identical(ref, again);
}

}  // namespace
}  // namespace mcl
}  // namespace fw
