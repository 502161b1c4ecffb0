#include "firmware/baselines/mcl/mcl.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "firmware/baselines/mcl/mcl_test_world.h"

namespace fw {
namespace mcl {
namespace {

using testing::GridWorld;

// Drives a robot along a loop in the unique room; returns the final pose error.
float run_global(Mcl* mcl, const MapView& map, int steps, bool* localized_at_end, int* first_localized,
                 Se2f* final_pose = nullptr) {
  static hal::LaserScan scan;
  Se2f truth(1.5f, 1.5f, 0.3f);
  Se2f prev = truth;
  *first_localized = -1;
  MclStepResult r;
  for (int t = 0; t < steps; ++t) {
    const Se2f u = (t % 40 < 30) ? Se2f(0.15f, 0.0f, 0.0f) : Se2f(0.05f, 0.0f, 0.2f);
    Se2f next = truth.compose(u);
    if (map.distance_at(next.x, next.y, 0) < 0.5f) next = truth.compose(Se2f(0, 0, 0.4f));  // turn at walls
    truth = next;
    testing::simulate_scan(map, truth.x, truth.y, truth.theta, &scan);
    const Se2f delta = prev.between(truth);
    prev = truth;
    EXPECT_TRUE(mcl->step(scan, delta, t > 0, &r).is_ok());
    if (r.localized && *first_localized < 0) *first_localized = t;
  }
  *localized_at_end = r.localized;
  if (final_pose) *final_pose = r.pose;
  return std::hypot(r.pose.x - truth.x, r.pose.y - truth.y);
}

TEST(MclOptionsTest, MalformedRejectedNamingField) {
  MclOptions o;
  EXPECT_TRUE(o.validate().is_ok());
  o.num_particles = 200000;
  Status s = o.validate();
  EXPECT_NE(std::string(s.message()).find("num_particles"), std::string::npos) << s.message();
  o = MclOptions();
  o.z_hit = 0.9f;
  s = o.validate();
  EXPECT_NE(std::string(s.message()).find("z_hit"), std::string::npos) << s.message();
  o = MclOptions();
  o.sigma_hit_m = std::nanf("");
  s = o.validate();
  EXPECT_NE(std::string(s.message()).find("sigma_hit_m"), std::string::npos) << s.message();
  static Mcl mcl;
  EXPECT_FALSE(mcl.init(o, MapView(), nullptr).is_ok());
}

TEST(MclTest, RaycastMatchesGeometry) {
  static GridWorld g = testing::unique_room();
  const MapView m = g.view();
  // From (1.5, 5) looking −x: wall at x = 0.2 → ≈ 1.3 m (within a cell).
  EXPECT_NEAR(m.raycast(1.5f, 5.0f, 3.14159f, 8.0f), 1.3f, 0.06f);
  EXPECT_NEAR(m.raycast(1.5f, 5.0f, 1.5708f, 8.0f), 2.8f, 0.06f);
}

TEST(MclTest, GlobalLocalizationBeamModel) {
  static GridWorld g = testing::unique_room();
  static Mcl mcl;
  MclOptions o;
  o.num_particles = 20000;
  ASSERT_TRUE(mcl.init(o, g.view(), nullptr).is_ok());
  ASSERT_TRUE(mcl.init_uniform().is_ok());
  bool loc = false;
  int first = -1;
  const float err = run_global(&mcl, g.view(), 60, &loc, &first);
  EXPECT_TRUE(loc);
  EXPECT_LT(err, 0.3f);
  EXPECT_GE(first, 10);  // needs τ = 10 steps of best-particle distances
}

TEST(MclTest, LikelihoodFieldKldInjection) {
  static GridWorld g = testing::unique_room();
  static Mcl mcl;
  MclOptions o;
  o.num_particles = 20000;
  o.model = SensorModel::kLikelihoodField;
  o.kld_sampling = true;
  o.random_injection = true;
  ASSERT_TRUE(mcl.init(o, g.view(), nullptr).is_ok());
  ASSERT_TRUE(mcl.init_uniform().is_ok());
  bool loc = false;
  int first = -1;
  const float err = run_global(&mcl, g.view(), 60, &loc, &first);
  EXPECT_LT(err, 0.3f);
  EXPECT_LT(mcl.size(), 20000u);  // KLD shrank the set after convergence
}

TEST(MclTest, DeterministicAcrossWorkerCounts) {
  static GridWorld g = testing::unique_room();
  static Mcl a, b;
  static WorkerPool pool;
  WorkerPoolOptions po;
  po.num_workers = 2;
  po.pin = false;
  ASSERT_TRUE(pool.start(po).is_ok());
  MclOptions o;
  o.num_particles = 4000;
  ASSERT_TRUE(a.init(o, g.view(), nullptr).is_ok());
  ASSERT_TRUE(b.init(o, g.view(), &pool).is_ok());
  ASSERT_TRUE(a.init_uniform().is_ok());
  ASSERT_TRUE(b.init_uniform().is_ok());
  bool la, lb;
  int fa, fb;
  Se2f pa, pb;
  run_global(&a, g.view(), 15, &la, &fa, &pa);
  run_global(&b, g.view(), 15, &lb, &fb, &pb);
  pool.stop();
  EXPECT_EQ(pa.x, pb.x);
  EXPECT_EQ(pa.y, pb.y);
  EXPECT_EQ(pa.theta, pb.theta);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.particles()[i].x, b.particles()[i].x) << i;
}

TEST(MclTest, MalformedScanRejected) {
  static GridWorld g = testing::unique_room();
  static Mcl mcl;
  MclOptions o;
  o.num_particles = 100;
  ASSERT_TRUE(mcl.init(o, g.view(), nullptr).is_ok());
  static hal::LaserScan s;
  MclStepResult r;
  EXPECT_FALSE(mcl.step(s, Se2f(), false, &r).is_ok());  // before init_uniform
  ASSERT_TRUE(mcl.init_uniform().is_ok());
  EXPECT_FALSE(mcl.step(s, Se2f(), false, &r).is_ok());  // zero beams
  testing::simulate_scan(g.view(), 2, 2, 0, &s);
  s.ranges[5] = std::nanf("");
  EXPECT_TRUE(mcl.step(s, Se2f(), false, &r).is_ok());  // NaN reading skipped
  EXPECT_FALSE(mcl.step(s, Se2f(std::nanf(""), 0, 0), true, &r).is_ok());
}

}  // namespace
}  // namespace mcl
}  // namespace fw
