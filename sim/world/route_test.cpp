// Route additions of issue 55 (speeds per leg, stops at nodes) and synthetic runs with every
// issue-55 option on: the path is the one of the default route, the timing changes; kidnapping and
// driving through unknown space still work.
#include "sim/world/route.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/world/builtin_worlds.h"
#include "sim/world/odometry_profiles.h"
#include "sim/world/sensor_profiles.h"
#include "sim/world/synthetic_run.h"

namespace sim {
namespace {

World office(const char* name = "large-office") {
  World w;
  std::string err;
  EXPECT_TRUE(make_builtin_world(name, &w, &err)) << err;
  return w;
}

TEST(RouteMotion, ValidateNamesTheNewFields) {
  RouteOptions o;
  EXPECT_EQ(o.validate(), "");
  EXPECT_FALSE(o.varied_motion());
  o.speed_min = 0.3;  // max 0
  EXPECT_NE(o.validate().find("speed_min"), std::string::npos);
  o.speed_max = 0.2;
  EXPECT_NE(o.validate().find("speed_max"), std::string::npos);
  o = RouteOptions();
  o.stop_probability = 1.5;
  EXPECT_NE(o.validate().find("stop_probability"), std::string::npos);
  o = RouteOptions();
  o.stop_min_s = 5;
  o.stop_max_s = 1;
  EXPECT_NE(o.validate().find("stop_min_s"), std::string::npos);
}

// Speeds per leg in [speed_min, speed_max] and stops at nodes: the same path (nodes, geometry) as
// the default route of the same seed, the same length; legs at their own speeds; stops stand still.
TEST(RouteMotion, SpeedsAndStopsKeepThePathAndChangeTheTiming) {
  const World w = office();
  RouteOptions plain;
  plain.length_m = 300;
  RouteOptions varied = plain;
  varied.speed_min = 0.3;
  varied.speed_max = 1.5;
  varied.stop_probability = 0.3;
  varied.stop_min_s = 2;
  varied.stop_max_s = 10;
  ASSERT_EQ(varied.validate(), "");
  std::string err;
  for (std::uint64_t seed : {1, 2, 3}) {
    fw::RandomStream r1(seed, 1), r2(seed, 1);
    RouteTrajectory a, b;
    std::vector<int> na, nb;
    ASSERT_TRUE(generate_route(w, plain, &r1, &a, &na, &err)) << err;
    ASSERT_TRUE(generate_route(w, varied, &r2, &b, &nb, &err)) << err;
    EXPECT_EQ(na, nb);
    EXPECT_EQ(r1.next_u32(), r2.next_u32());  // the route's stream advanced alike
    EXPECT_NEAR(a.length(), b.length(), 1e-9);
    EXPECT_EQ(a.end_pose().x, b.end_pose().x);
    std::vector<double> speeds;
    int stops = 0, drives = 0;
    double stop_time = 0;
    for (const RouteTrajectory::Piece& p : b.pieces()) {
      if (p.v > 0) {
        ++drives;
        speeds.push_back(p.v);
        EXPECT_TRUE(p.v >= 0.3 && p.v <= 1.5) << p.v;
      } else if (p.omega == 0) {
        ++stops;
        stop_time += p.t1 - p.t0;
        EXPECT_TRUE(p.t1 - p.t0 >= 2 && p.t1 - p.t0 <= 10);
        // Standing still through the stop.
        const fw::Se2d s0 = b.pose_at(p.t0 + 1e-9), s1 = b.pose_at(0.5 * (p.t0 + p.t1)), s2 = b.pose_at(p.t1 - 1e-9);
        EXPECT_EQ(s0.x, s1.x);
        EXPECT_EQ(s1.y, s2.y);
        EXPECT_EQ(s0.theta, s2.theta);
      }
    }
    ASSERT_GT(drives, 20);
    double mean = 0;
    for (double v : speeds) mean += v / speeds.size();
    EXPECT_NEAR(mean, 0.9, 0.15) << seed;  // uniform in [0.3, 1.5]: sd of the mean ≈ 0.35/√drives
    EXPECT_NEAR(static_cast<double>(stops) / drives, 0.3, 0.15) << seed;
    // Drive pieces: the same segments as the default route's, in order.
    std::vector<RouteTrajectory::Piece> da, db;
    for (const auto& p : a.pieces()) {
      if (p.v > 0) da.push_back(p);
    }
    for (const auto& p : b.pieces()) {
      if (p.v > 0) db.push_back(p);
    }
    ASSERT_EQ(da.size(), db.size());
    for (size_t i = 0; i < da.size(); ++i) EXPECT_EQ(da[i].start.x, db[i].start.x);
    // Continuous in time at each leg's speed.
    fw::Se2d prev = b.pose_at(0);
    for (double t = 0.05; t <= b.duration(); t += 0.05) {
      const fw::Se2d p = b.pose_at(t);
      EXPECT_LE(std::hypot(p.x - prev.x, p.y - prev.y), 1.5 * 0.05 + 1e-9);
      prev = p;
    }
    EXPECT_GT(stop_time, 0);
  }
}

// Everything of issue 55 on at once: a generated-run setting with a sensor and an odometry profile,
// varied speeds and stops, a kidnapping; same seed ⇒ same frames; the kidnap still jumps.
TEST(RouteMotion, SyntheticRunWithProfilesKidnapsAndIsDeterministic) {
  const World w = office();
  SyntheticRunOptions opt;
  opt.seed = 4;
  opt.laser = find_sensor_profile("rplidar-a1")->laser;
  opt.odometry = find_odometry_profile("skid-steer")->wheels;
  opt.route.speed_min = 0.3;
  opt.route.speed_max = 1.5;
  opt.route.stop_probability = 0.3;
  opt.scan_period_s = 1.0 / find_sensor_profile("rplidar-a1")->rate_hz;
  opt.kidnap_at_scan = 60;
  opt.max_scans = 120;
  std::string err;
  SyntheticRun r1, r2;
  ASSERT_TRUE(r1.init(w, opt, &err)) << err;
  ASSERT_TRUE(r2.init(w, opt, &err)) << err;
  SyntheticFrame f1, f2;
  int kidnaps = 0;
  fw::Se2d prev;
  while (r1.next(&f1)) {
    ASSERT_TRUE(r2.next(&f2));
    ASSERT_EQ(f1.odometry.size(), f2.odometry.size());
    for (size_t i = 0; i < f1.odometry.size(); ++i) ASSERT_EQ(f1.odometry[i].theta, f2.odometry[i].theta);
    for (std::uint32_t i = 0; i < f1.scan.beam_count; ++i) ASSERT_EQ(f1.scan.ranges[i], f2.scan.ranges[i]);
    if (f1.kidnapped) {
      ++kidnaps;
      EXPECT_GT(std::hypot(f1.truth.x - prev.x, f1.truth.y - prev.y), 9.0);
    } else if (f1.index > 0) {
      EXPECT_LT(std::hypot(f1.truth.x - prev.x, f1.truth.y - prev.y), 1.5 * opt.scan_period_s + 1e-6);
    }
    prev = f1.truth;
  }
  EXPECT_EQ(kidnaps, 1);
}

TEST(RouteMotion, ViaUnknownStillDrivesIntoTheUnknownArea) {
  const World w = office();
  RouteOptions opt;
  opt.via_unknown = true;
  opt.length_m = 200;
  opt.speed_min = 0.3;
  opt.speed_max = 1.5;
  opt.stop_probability = 0.5;
  std::string err;
  for (std::uint64_t seed : {1, 2, 3}) {
    fw::RandomStream rng(seed, 1);
    RouteTrajectory t;
    ASSERT_TRUE(generate_route(w, opt, &rng, &t, nullptr, &err)) << err;
    bool inside = false;
    for (double s = 0; s <= t.duration(); s += 0.2) {
      const fw::Se2d p = t.pose_at(s);
      inside |= w.unknown_areas[0].contains(Vec2(p.x, p.y));
    }
    EXPECT_TRUE(inside) << "seed " << seed;
  }
}

}  // namespace
}  // namespace sim
