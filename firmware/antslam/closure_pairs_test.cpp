// Loop closures confirmed in pairs (closure_pairs.h) and their isolation on the old map
// (closure_isolation.h).
#include "firmware/antslam/closure_isolation.h"
#include "firmware/antslam/closure_pairs.h"
#include "firmware/antslam/field_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace fw::antslam {
namespace closure_pairs_test {  // named: the tests are built as one unity source

using field_test::Field;
using field_test::wall;

ClosureCandidate closure(std::uint32_t a, std::uint32_t c, const Se2d& h, double sigma = 0.05) {
  ClosureCandidate k;
  k.a = a;
  k.c = c;
  k.h = h;
  k.cov_h = Mat3::Identity() * sigma * sigma;
  return k;
}

// Frames of a revisit: old fragments c, c' = c ⊕ cc; new fragments a, a' = a ⊕ aa; the truth puts
// F_a at h in F_c.
struct Revisit {
  Se2d cc{5.0, 0.2, 0.05};
  Se2d aa{4.8, -0.1, 0.04};
  Se2d h{0.4, 0.3, 0.1};
  Se2d h2() const { return cc.inverse().compose(h).compose(aa); }  // F_a' in F_c'
  Mat3 chain_cov = Mat3::Identity() * 1e-4;
};

TEST(ClosurePairsTest, TwoTrueClosuresCloseTheCycle) {
  const Revisit r;
  const double chi2 = pair_cycle_chi2(closure(10, 2, r.h), closure(11, 3, r.h2()), r.cc, r.chain_cov, r.aa, r.chain_cov);
  EXPECT_LT(chi2, 1e-9);
}

TEST(ClosurePairsTest, OneWrongClosureBreaksTheCycle) {
  const Revisit r;
  const Se2d wrong = Se2d(3.0, 0.0, 0.0).compose(r.h2());  // a' matched 3 m along the corridor
  const double chi2 = pair_cycle_chi2(closure(10, 2, r.h), closure(11, 3, wrong), r.cc, r.chain_cov, r.aa, r.chain_cov);
  EXPECT_GT(chi2, 100.0);
  // A turned alias as well.
  const Se2d turned = r.h2().compose(Se2d(0, 0, 3.14159265358979323846));
  EXPECT_GT(pair_cycle_chi2(closure(10, 2, r.h), closure(11, 3, turned), r.cc, r.chain_cov, r.aa, r.chain_cov), 100.0);
}

// The limit of the pair test, and why the isolation test exists: both fragments aliased by the same
// shift of the old map agree with each other.
TEST(ClosurePairsTest, TheSameAliasOfBothFragmentsAlsoClosesTheCycle) {
  const Revisit r;
  const Se2d shift(4.0, 0.0, 0.0);  // in F_c: a corridor's period
  const Se2d h1 = shift.compose(r.h);
  const Se2d h2 = r.cc.inverse().compose(shift).compose(r.cc).compose(r.h2());
  EXPECT_LT(pair_cycle_chi2(closure(10, 2, h1), closure(11, 3, h2), r.cc, r.chain_cov, r.aa, r.chain_cov), 1e-6);
}

TEST(ClosurePairsTest, TheCovariancesWidenTheGate) {
  const Revisit r;
  const Se2d off = Se2d(0.1, 0.0, 0.0).compose(r.h2());
  const double tight = pair_cycle_chi2(closure(10, 2, r.h, 0.01), closure(11, 3, off, 0.01), r.cc, r.chain_cov, r.aa, r.chain_cov);
  const double loose = pair_cycle_chi2(closure(10, 2, r.h, 0.2), closure(11, 3, off, 0.2), r.cc, r.chain_cov, r.aa, r.chain_cov);
  EXPECT_GT(tight, 16.3);
  EXPECT_LT(loose, 1.0);
}

TEST(ClosurePairsTest, RingKeepsTheLastFragmentsOnly) {
  ClosureCandidateRing ring;
  for (std::uint32_t a = 0; a < 100; ++a) ring.push(closure(a, 0, Se2d()));
  EXPECT_EQ(ring.size(), ClosureCandidateRing::kCapacity);
  EXPECT_EQ(ring[0].a, 100 - ClosureCandidateRing::kCapacity);
  ring.expire(100, 2);
  ASSERT_EQ(ring.size(), 2u);
  EXPECT_EQ(ring[0].a, 98u);
  EXPECT_EQ(ring[1].a, 99u);
  ring.clear();
  EXPECT_EQ(ring.size(), 0u);
}

// A corridor 2 m wide from x = 0 to 40 m with 1 m door openings in its walls: every 4 m (periodic),
// or at irregular places.
std::vector<Point2f> corridor(const std::vector<float>& doors) {
  std::vector<Point2f> pts;
  for (const float y : {0.0f, 2.0f}) {
    float x = 0.0f;
    for (const float d : doors) {
      wall(x, y, d, y, &pts);
      x = d + 1.0f;
    }
    wall(x, y, 40.0f, y, &pts);
  }
  // Each door opens into a recess, 1 m deep when the doors are periodic; irregular doors get
  // recesses of different depths (a building's rooms are not all alike).
  const bool periodic = doors.size() > 1 && std::fabs((doors[1] - doors[0]) - 4.0f) < 1e-3f;
  for (std::size_t i = 0; i < doors.size(); ++i) {
    const float d = doors[i], depth = periodic ? 1.0f : 0.6f + 0.45f * static_cast<float>(i % 4);
    wall(d, -depth, d + 1.0f, -depth, &pts);
    wall(d, 2.0f + depth, d + 1.0f, 2.0f + depth, &pts);
  }
  return pts;
}

// The part of the model with x in [x0, x1], moved into a frame at `pose`.
std::vector<Point2f> scene_of(const std::vector<Point2f>& model, float x0, float x1, const Se2d& pose) {
  std::vector<Point2f> s;
  const Se2d inv = pose.inverse();
  for (const Point2f& p : model) {
    if (p(0) < x0 || p(0) > x1) continue;
    s.push_back(inv.transform_point(p.cast<double>()).cast<float>());
  }
  return s;
}

IsolationResult isolation_of(const std::vector<Point2f>& model, const Se2d& pose, const Se2d& h) {
  const Field f(model);
  const std::vector<Point2f> scene = scene_of(model, 14.0f, 24.0f, pose);
  std::vector<CellSample> cells(scene.size());
  return check_closure_isolation(f.field, scene.data(), scene.size(), h, IsolationOptions{}, cells.data());
}

TEST(ClosureIsolationTest, APeriodicCorridorIsNotIsolated) {
  std::vector<float> doors;
  for (float d = 2.0f; d < 38.0f; d += 4.0f) doors.push_back(d);
  const Se2d pose(15.0, 1.0, 0.2);
  const IsolationResult r = isolation_of(corridor(doors), pose, pose);
  EXPECT_FALSE(r.isolated) << "z " << r.rival_z << " rival at " << r.rival.x << ", " << r.rival.y;
  const double along = std::fabs(r.rival.x - r.pose.x);  // whole periods along the corridor
  EXPECT_NEAR(along / 4.0, std::round(along / 4.0), 0.1);
  EXPECT_GE(std::round(along / 4.0), 1.0);
  EXPECT_GT(r.rivals_tried, 0u);
}

// A closure within the drift gate competes only with rivals the gate admits: the periodic corridor's
// aliases 4 m away do not count under a prior of σ 0.5 m, they do under one of σ 3 m.
TEST(ClosureIsolationTest, APriorRulesOutFarAliases) {
  std::vector<float> doors;
  for (float d = 2.0f; d < 38.0f; d += 4.0f) doors.push_back(d);
  const std::vector<Point2f> model = corridor(doors);
  const Se2d pose(15.0, 1.0, 0.2);
  const Field f(model);
  const std::vector<Point2f> scene = scene_of(model, 14.0f, 24.0f, pose);
  std::vector<CellSample> cells(scene.size());
  for (const double sigma : {0.5, 3.0}) {
    IsolationPrior prior;
    prior.mean = pose;
    prior.info = Vec3(1.0 / (sigma * sigma), 1.0 / (sigma * sigma), 1.0 / (0.05 * 0.05)).asDiagonal();
    prior.gate = 16.3;
    const IsolationResult r =
        check_closure_isolation(f.field, scene.data(), scene.size(), pose, IsolationOptions{}, cells.data(), &prior);
    EXPECT_EQ(r.isolated, sigma < 1.0) << "sigma " << sigma << " z " << r.rival_z;
  }
}

TEST(ClosureIsolationTest, IrregularDoorsAreIsolated) {
  const Se2d pose(15.0, 1.0, 0.2);
  const IsolationResult r = isolation_of(corridor({3.0f, 5.5f, 11.0f, 14.5f, 17.0f, 22.5f, 23.8f, 29.0f, 35.0f}), pose, pose);
  EXPECT_TRUE(r.isolated) << "z " << r.rival_z << " rival at " << r.rival.x << ", " << r.rival.y;
  EXPECT_NEAR(r.pose.x, pose.x, 0.02);
  EXPECT_NEAR(r.pose.y, pose.y, 0.02);
  EXPECT_GT(r.quality, r.rival_quality);
}

TEST(ClosureIsolationTest, AWrongClosureHasARivalThatFitsBetter) {
  const std::vector<Point2f> model = corridor({3.0f, 5.5f, 11.0f, 14.5f, 17.0f, 22.5f, 23.8f, 29.0f, 35.0f});
  const Se2d pose(15.0, 1.0, 0.2);
  // The closure 2.5 m off along the corridor: the true place is among its rivals and fits better.
  const IsolationResult r = isolation_of(model, pose, Se2d(17.5, 1.0, 0.2));
  EXPECT_FALSE(r.isolated);
  EXPECT_LT(r.rival_z, 0.0f);
  EXPECT_NEAR(r.rival.x, pose.x, 0.2);  // refined along the corridor's weak axis
}

TEST(ClosureIsolationTest, ACorridorWalkedTheOtherWayFitsBetterUnturned) {
  const std::vector<Point2f> model = corridor({3.0f, 5.5f, 11.0f, 14.5f, 17.0f, 22.5f, 23.8f, 29.0f, 35.0f});
  const Se2d pose(15.0, 1.0, 0.2);
  // The closure turned by 180° about the middle of the scene: the walls fit, the doors do not.
  const Se2d about(19.0, 1.0, 0.0);
  const Se2d turned = about.compose(Se2d(0, 0, 3.14159265358979323846)).compose(about.inverse()).compose(pose);
  const IsolationResult r = isolation_of(model, pose, turned);
  EXPECT_FALSE(r.isolated);
  EXPECT_LT(r.rival_z, 0.0f);
  EXPECT_NEAR(std::fabs(wrap_angle(r.rival.theta - pose.theta)), 0.0, 0.05);
  EXPECT_NEAR(r.rival.y, pose.y, 0.1);
}

TEST(ClosureIsolationTest, RejectsBadOptions) {
  IsolationOptions o;
  EXPECT_TRUE(o.validate().is_ok());
  o.shift_step_m = 0.0f;
  EXPECT_FALSE(o.validate().is_ok());
  o = IsolationOptions{};
  o.z = -1.0f;
  EXPECT_FALSE(o.validate().is_ok());
}

}  // namespace closure_pairs_test
}  // namespace fw::antslam
