#include "firmware/baselines/icp/pl_icp.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "firmware/rbsm/synthetic_world_test_util.h"
#include "firmware/scan/point_to_line.h"
#include "tests/alloc_counter.h"

namespace {

constexpr float kDeg = 0.017453292519943295f;

struct Case {
  const char* name;
  std::vector<rbsm_test::Segment> world;
  fw::Se2f reference, truth, guess;
};

// The worlds of the RBSM tests, with guesses off by 5–10 cm and 2.5–3°.
std::vector<Case> cases() {
  return {
      {"corridor", rbsm_test::corridor_world(), fw::Se2f(-2, 0, 0), fw::Se2f(-1.6f, 0.1f, 4 * kDeg),
       fw::Se2f(-1.55f, 0.04f, 2 * kDeg)},
      {"l_corner", rbsm_test::l_corner_world(), fw::Se2f(0, 0, 0), fw::Se2f(0.5f, -0.1f, 10 * kDeg),
       fw::Se2f(0.44f, -0.04f, 12.5f * kDeg)},
      {"room", rbsm_test::room_world(), fw::Se2f(-1, -1, 0.3f), fw::Se2f(-0.7f, -0.9f, 0.3f - 8 * kDeg),
       fw::Se2f(-0.64f, -0.97f, 0.3f - 5.5f * kDeg)},
  };
}

TEST(PointToLineTest, LineNormalOfAScatterAndOneExactStep) {
  // Points along the direction 30°: the normal is 120° (or −60°), ratio 0.
  float sxx = 0, sxy = 0, syy = 0;
  const float c = std::cos(30 * kDeg), s = std::sin(30 * kDeg);
  for (int k = -5; k <= 5; ++k) {
    sxx += k * c * k * c;
    sxy += k * c * k * s;
    syy += k * s * k * s;
  }
  float nx, ny, ratio;
  fw::line_normal_from_scatter(sxx / 11, sxy / 11, syy / 11, &nx, &ny, &ratio);
  EXPECT_NEAR(std::fabs(nx * c + ny * s), 0.0f, 1e-5f);
  EXPECT_NEAR(nx * nx + ny * ny, 1.0f, 1e-5f);
  EXPECT_NEAR(ratio, 0.0f, 1e-5f);
  // Two walls x = 1 and y = 2 seen from a pose off by a pure translation (0.03, −0.02): the
  // residuals are linear in (x, y), so one Gauss–Newton step lands exactly.
  fw::PointToLineSystem sys;
  for (int k = 0; k < 10; ++k) {
    const float py = -0.5f + 0.1f * k;
    sys.add(1.03f, py, 1.0f, 0.0f, 1.0f, 0.0f, 0.03f, 1.0);  // wall x = 1, point at x = 1.03
    sys.add(py, 1.98f, 1.0f, 0.0f, 0.0f, 1.0f, -0.02f, 1.0);  // wall y = 2, point at y = 1.98
  }
  Eigen::Vector3d dx;
  ASSERT_TRUE(sys.solve(&dx));
  EXPECT_NEAR(dx(0), -0.03, 1e-6);
  EXPECT_NEAR(dx(1), 0.02, 1e-6);
  EXPECT_NEAR(dx(2), 0.0, 1e-6);
  EXPECT_EQ(sys.used, 20u);
}

TEST(PlIcpTest, RecoversKnownDisplacementInSyntheticWorlds) {
  for (const Case& c : cases()) {
    auto icp = std::make_unique<fw::PlIcp>();
    ASSERT_TRUE(icp->init(fw::PlIcpOptions{}).is_ok());
    const auto ref = rbsm_test::cast_scan(c.world, c.reference);
    const auto cur = rbsm_test::cast_scan(c.world, c.truth);
    fw::ScanMatchResult r;
    // No key scan yet: the guess comes back, flagged.
    ASSERT_TRUE(icp->match(ref.data(), ref.size(), c.reference, &r).is_ok());
    EXPECT_TRUE(r.map_was_empty);
    ASSERT_TRUE(icp->integrate(ref.data(), ref.size(), c.reference).is_ok());
    ASSERT_TRUE(icp->has_key());
    ASSERT_TRUE(icp->match(cur.data(), cur.size(), c.guess, &r).is_ok()) << c.name;
    // Exact ray-cast scans: point-to-line converges to the truth up to the polyline's chords.
    EXPECT_NEAR(r.pose.x, c.truth.x, 0.005f) << c.name;
    EXPECT_NEAR(r.pose.y, c.truth.y, 0.005f) << c.name;
    EXPECT_NEAR(fw::wrap_angle(r.pose.theta - c.truth.theta), 0.0f, 0.1f * kDeg) << c.name;
    EXPECT_TRUE(r.converged) << c.name;
    EXPECT_GE(r.iterations, 2u);
    EXPECT_GT(r.matched_points, 100u);
  }
}

TEST(PlIcpTest, KeyScanIsReplacedOnlyAfterEnoughMotion) {
  fw::PlIcpOptions o;
  o.keyframe_translation_m = 0.2f;
  o.keyframe_rotation_rad = 10 * kDeg;
  auto icp = std::make_unique<fw::PlIcp>();
  ASSERT_TRUE(icp->init(o).is_ok());
  const auto world = rbsm_test::room_world();
  const auto a = rbsm_test::cast_scan(world, fw::Se2f(-1, -1, 0));
  ASSERT_TRUE(icp->integrate(a.data(), a.size(), fw::Se2f(-1, -1, 0)).is_ok());
  ASSERT_TRUE(icp->integrate(a.data(), a.size(), fw::Se2f(-0.9f, -1, 5 * kDeg)).is_ok());
  EXPECT_FLOAT_EQ(icp->key_pose().x, -1.0f);  // 0.1 m, 5°: still the old key
  ASSERT_TRUE(icp->integrate(a.data(), a.size(), fw::Se2f(-0.75f, -1, 0)).is_ok());
  EXPECT_FLOAT_EQ(icp->key_pose().x, -0.75f);
  ASSERT_TRUE(icp->integrate(a.data(), a.size(), fw::Se2f(-0.75f, -1, 12 * kDeg)).is_ok());
  EXPECT_FLOAT_EQ(icp->key_pose().theta, 12 * kDeg);
  icp->reset();
  EXPECT_FALSE(icp->has_key());
}

TEST(PlIcpTest, TracksASequenceWithBiasedOdometryAndOutliers) {
  // Laser-to-laser odometry through the room with a biased odometry (+2 cm, +2° per step) and a
  // person (a small box) that is only in every other scan: the outlier rejection must keep the
  // drift below what the bias alone would accumulate (8 steps: 16 cm, 16°).
  auto icp = std::make_unique<fw::PlIcp>();
  ASSERT_TRUE(icp->init(fw::PlIcpOptions{}).is_ok());
  const auto room = rbsm_test::room_world();
  auto with_person = room;
  for (const auto& s : rbsm_test::box(0.2f, -1.0f, 0.5f, -0.7f)) with_person.push_back(s);
  fw::Se2f truth(-1, -1, 0), est = truth;
  const fw::Se2f step(0.15f, 0.02f, 3 * kDeg), bias(0.17f, 0.02f, 5 * kDeg);
  auto pts = rbsm_test::cast_scan(room, truth);
  ASSERT_TRUE(icp->integrate(pts.data(), pts.size(), est).is_ok());
  for (int k = 0; k < 8; ++k) {
    truth = truth.compose(step);
    pts = rbsm_test::cast_scan(k % 2 ? with_person : room, truth);
    fw::ScanMatchResult r;
    ASSERT_TRUE(icp->match(pts.data(), pts.size(), est.compose(bias), &r).is_ok());
    est = r.pose;
    ASSERT_TRUE(icp->integrate(pts.data(), pts.size(), est).is_ok());
  }
  EXPECT_NEAR(est.x, truth.x, 0.01f);
  EXPECT_NEAR(est.y, truth.y, 0.01f);
  EXPECT_NEAR(fw::wrap_angle(est.theta - truth.theta), 0.0f, 0.2f * kDeg);
}

TEST(PlIcpTest, MalformedInputIsAStatusAndMatchAllocatesNothing) {
  fw::PlIcpOptions bad;
  bad.trim_fraction = 0.0f;
  fw::PlIcp icp0;
  EXPECT_FALSE(icp0.init(bad).is_ok());
  fw::ScanMatchResult r;
  EXPECT_EQ(icp0.match(nullptr, 0, fw::Se2f(), &r).code(), fw::Errc::kNotInitialized);
  auto icp = std::make_unique<fw::PlIcp>();
  ASSERT_TRUE(icp->init(fw::PlIcpOptions{}).is_ok());
  EXPECT_FALSE(icp->match(nullptr, 5, fw::Se2f(), &r).is_ok());
  const auto world = rbsm_test::room_world();
  const auto a = rbsm_test::cast_scan(world, fw::Se2f(-1, -1, 0));
  const auto b = rbsm_test::cast_scan(world, fw::Se2f(-0.9f, -1, 0.05f));
  fw::Status st = icp->match(b.data(), 5, fw::Se2f(), &r);
  EXPECT_FALSE(st.is_ok());
  EXPECT_NE(std::string(st.message()).find("valid points"), std::string::npos) << st.message();
  EXPECT_FALSE(icp->match(b.data(), b.size(), fw::Se2f(NAN, 0, 0), &r).is_ok());
  if (!mmlfw_test::AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  mmlfw_test::AllocCounter::begin();
  fw::Status s1 = icp->integrate(a.data(), a.size(), fw::Se2f(-1, -1, 0));
  fw::Status s2 = icp->match(b.data(), b.size(), fw::Se2f(-0.92f, -1, 0.03f), &r);
  const long n = mmlfw_test::AllocCounter::end();
  EXPECT_TRUE(s1.is_ok() && s2.is_ok());
  EXPECT_EQ(n, 0);
}

}  // namespace
