#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <limits>

#include "firmware/map/global_map.h"
#include "sim/world/builtin_worlds.h"
#include "sim/world/laser_model.h"
#include "sim/world/odometry_model.h"
#include "sim/world/raster.h"
#include "sim/world/ray_cast.h"
#include "sim/world/route.h"
#include "sim/world/synthetic_run.h"

namespace sim {
namespace {

World square_room() {
  World w;
  w.name = "square";
  w.bounds = {Vec2(0, 0), Vec2(10, 10)};
  add_rect(&w, 0, 0, 10, 10);
  return w;
}

TEST(RayCast, KnownGeometry) {
  const World w = square_room();
  const Vec2 o(5, 5);
  EXPECT_NEAR(cast_ray(w, o, 0.0, 20, 0).range, 5.0, 1e-12);
  EXPECT_NEAR(cast_ray(w, o, M_PI / 2, 20, 0).range, 5.0, 1e-12);
  EXPECT_NEAR(cast_ray(w, o, M_PI / 4, 20, 0).range, 5.0 * std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(cast_ray(w, Vec2(2, 5), M_PI, 20, 0).range, 2.0, 1e-12);
  // Out of range: no hit, reported at max range.
  const RayHit far = cast_ray(w, o, 0.0, 4.0, 0);
  EXPECT_FALSE(far.hit);
  EXPECT_DOUBLE_EQ(far.range, 4.0);
  // Segment behind the ray and parallel segments are misses.
  const Segment s{Vec2(-1, -1), Vec2(-1, 1)};
  EXPECT_TRUE(std::isinf(ray_segment_distance(Vec2(0, 0), Vec2(1, 0), s)));
  EXPECT_TRUE(std::isinf(ray_segment_distance(Vec2(0, 0), Vec2(0, 1), {Vec2(1, 0), Vec2(1, 5)})));
  EXPECT_NEAR(ray_segment_distance(Vec2(0, 0), Vec2(0, 1), {Vec2(-1, 3), Vec2(1, 3)}), 3.0, 1e-12);
  // Circles: from outside, from inside (ignored), missing.
  EXPECT_NEAR(ray_circle_distance(Vec2(0, 0), Vec2(1, 0), Vec2(3, 0), 0.5), 2.5, 1e-12);
  EXPECT_TRUE(std::isinf(ray_circle_distance(Vec2(3, 0), Vec2(1, 0), Vec2(3, 0), 0.5)));
  EXPECT_TRUE(std::isinf(ray_circle_distance(Vec2(0, 0), Vec2(1, 0), Vec2(3, 1), 0.5)));
}

TEST(RayCast, PeopleMoveAndOccludeWalls) {
  World w = square_room();
  Person p;
  p.path = {Vec2(8, 5), Vec2(8, 9)};
  p.radius = 0.25;
  p.speed = 1.0;
  w.people.push_back(p);
  const RayHit at0 = cast_ray(w, Vec2(5, 5), 0.0, 20, 0.0);
  EXPECT_TRUE(at0.person);
  EXPECT_NEAR(at0.range, 2.75, 1e-9);
  EXPECT_NEAR(cast_ray(w, Vec2(5, 5), 0.0, 20, 0.0, false).range, 5.0, 1e-12);
  // After 2 s the person is at (8, 7): the ray along y = 5 sees the wall again.
  EXPECT_NEAR(cast_ray(w, Vec2(5, 5), 0.0, 20, 2.0).range, 5.0, 1e-12);
  // Ping-pong: at t = 6 s the person walked 4 m up and 2 m back.
  const Vec2 q = person_position(p, 6.0);
  EXPECT_NEAR(q.y(), 7.0, 1e-12);
}

TEST(LaserModel, NoiseStatisticsAndDropouts) {
  const World w = square_room();
  LaserModelOptions opt;
  opt.beams = 361;
  opt.fov_deg = 180;
  opt.max_range = 80;
  opt.sigma_range = 0.005;
  opt.dropout_rate = 0.02;
  ASSERT_EQ(opt.validate(), "");
  fw::RandomStream rng(7, 3);
  hal::LaserScan scan;
  double sum = 0, sum2 = 0;
  std::size_t n = 0, dropped = 0, total = 0;
  const fw::Se2d pose(5, 5, 0.3);
  for (int k = 0; k < 60; ++k) {
    simulate_scan(w, pose, 0, opt, &rng, &scan);
    ASSERT_EQ(scan.beam_count, 361u);
    EXPECT_NEAR(scan.angle_min, -M_PI / 2, 1e-6);
    EXPECT_NEAR(scan.angle_increment, M_PI / 360, 1e-7);
    for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
      ++total;
      if (scan.ranges[i] >= scan.range_max) {
        ++dropped;
        continue;
      }
      const double a = pose.theta + scan.angle_min + i * static_cast<double>(scan.angle_increment);
      const double truth = cast_ray(w, Vec2(5, 5), a, 80, 0).range;
      const double e = scan.ranges[i] - truth;
      sum += e;
      sum2 += e * e;
      ++n;
    }
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.0003);
  EXPECT_NEAR(sd, 0.005, 0.0003);
  const double rate = static_cast<double>(dropped) / total;
  EXPECT_NEAR(rate, 0.02, 0.005);  // binomial sd ≈ 0.0010 over 21660 beams
}

TEST(LaserModel, NoEchoIsMaxRangeAndOptionsAreValidated) {
  const World w = square_room();
  LaserModelOptions opt;
  opt.max_range = 8;
  opt.sigma_range = 0;
  opt.dropout_rate = 0;
  fw::RandomStream rng(1, 3);
  hal::LaserScan scan;
  // Corner at (0.5, 0.5) facing +x: the far wall is 9.5 m away (> 8 m) straight ahead.
  simulate_scan(w, fw::Se2d(0.5, 5, 0), 0, opt, &rng, &scan);
  EXPECT_FLOAT_EQ(scan.ranges[180], 8.0f);
  EXPECT_NEAR(scan.ranges[0], 5.0f, 1e-5f);    // −90°: wall y = 0
  EXPECT_NEAR(scan.ranges[360], 5.0f, 1e-5f);  // +90°: wall y = 10
  LaserModelOptions bad = opt;
  bad.beams = 5000;
  EXPECT_NE(bad.validate().find("beams"), std::string::npos);
  bad = opt;
  bad.dropout_rate = 1.5;
  EXPECT_NE(bad.validate().find("dropout"), std::string::npos);
}

TEST(OdometryModel, NoiseHasTheConfiguredSigmaPerScanStep) {
  OdometryNoiseOptions opt;  // 4 cm, 4° per scan step
  for (double fraction : {1.0, 0.25}) {
    OdometrySimulator sim(opt, 11);
    const fw::Se2d still(3, 4, 0.5);  // robot standing still: every odometry delta is pure noise
    hal::Odometry prev = sim.start(still, 0);
    double sx = 0, sx2 = 0, sy2 = 0, st = 0, st2 = 0;
    const int n = 20000;
    for (int i = 1; i <= n; ++i) {
      const hal::Odometry o = sim.next(still, static_cast<std::uint64_t>(i) * 1000, fraction);
      const fw::Se2d d = fw::Se2d(prev.x, prev.y, prev.theta).between(fw::Se2d(o.x, o.y, o.theta));
      sx += d.x;
      sx2 += d.x * d.x;
      sy2 += d.y * d.y;
      st += d.theta;
      st2 += d.theta * d.theta;
      // Rebase to keep float precision (the odometry frame drifts as a random walk).
      prev = o;
    }
    const double k = std::sqrt(fraction);
    EXPECT_NEAR(sx / n, 0.0, 0.002 * k);
    EXPECT_NEAR(std::sqrt(sx2 / n), 0.04 * k, 0.002 * k) << fraction;
    EXPECT_NEAR(std::sqrt(sy2 / n), 0.04 * k, 0.002 * k) << fraction;
    EXPECT_NEAR(st / n, 0.0, 0.002 * k);
    EXPECT_NEAR(std::sqrt(st2 / n) * 180 / M_PI, 4.0 * k, 0.15 * k) << fraction;
  }
}

TEST(OdometryModel, NoiselessOdometryFollowsTheTruthInItsOwnFrame) {
  OdometryNoiseOptions opt;
  opt.sigma_trans = 0;
  opt.sigma_rot_deg = 0;
  opt.odom_origin = fw::Se2d(100, -50, 1.0);
  OdometrySimulator sim(opt, 1);
  const fw::Se2d a(2, 3, 0.2), b(2.5, 3.4, 0.9);
  const hal::Odometry oa = sim.start(a, 0);
  const hal::Odometry ob = sim.next(b, 100000000, 1.0);
  const fw::Se2d true_delta = a.between(b);
  const fw::Se2d odom_delta = fw::Se2d(oa.x, oa.y, oa.theta).between(fw::Se2d(ob.x, ob.y, ob.theta));
  EXPECT_NEAR(odom_delta.x, true_delta.x, 1e-4);
  EXPECT_NEAR(odom_delta.y, true_delta.y, 1e-4);
  EXPECT_NEAR(odom_delta.theta, true_delta.theta, 1e-6);
  EXPECT_FLOAT_EQ(oa.x, 100.0f);
}

TEST(Raster, WallsOccupiedInteriorFreeUnknownErased) {
  World w = square_room();
  w.unknown_areas.push_back({Vec2(6, 6), Vec2(9, 9)});
  RasterOptions ro;
  ro.resolution = 0.1;
  ro.margin = 0.5;
  OccupancyGrid g;
  std::string err;
  ASSERT_TRUE(rasterize_world(w, ro, &g, &err)) << err;
  EXPECT_EQ(g.geometry.width, 110u);
  EXPECT_EQ(g.geometry.height, 110u);
  auto cell = [&](double x, double y) {
    std::int32_t cx, cy;
    EXPECT_TRUE(g.geometry.world_to_cell(static_cast<float>(x), static_cast<float>(y), &cx, &cy));
    return g.cells[g.geometry.index(cx, cy)];
  };
  EXPECT_EQ(cell(0.01, 5), fw::kCellOccupied);
  EXPECT_EQ(cell(5, 10.02), fw::kCellOccupied);  // wall y = 10 lies in the cell [10.0, 10.1)
  EXPECT_EQ(cell(5, 5), fw::kCellFree);
  EXPECT_EQ(cell(7.5, 7.5), fw::kCellUnknown);  // erased unknown area
  EXPECT_EQ(cell(-0.3, 5), fw::kCellUnknown);   // outside the building
  ro.erase_unknown_areas = false;
  ASSERT_TRUE(rasterize_world(w, ro, &g, &err));
  EXPECT_EQ(cell(7.5, 7.5), fw::kCellFree);
  ro.resolution = -1;
  EXPECT_FALSE(rasterize_world(w, ro, &g, &err));
  EXPECT_NE(err.find("resolution"), std::string::npos);
}

TEST(BuiltinWorlds, GeometryAndRouteGraphAreConsistent) {
  for (const std::string& name : builtin_world_names()) {
    World w;
    std::string err;
    ASSERT_TRUE(make_builtin_world(name, &w, &err)) << err;
    EXPECT_EQ(w.name, name);
    const RouteGraph& g = w.route;
    ASSERT_GE(g.nodes.size(), 2u) << name;
    ASSERT_EQ(g.kinds.size(), g.nodes.size());
    // Connected: every node reachable from node 0.
    std::vector<bool> seen(g.nodes.size(), false);
    std::deque<int> q = {0};
    seen[0] = true;
    while (!q.empty()) {
      const int n = q.front();
      q.pop_front();
      for (int m : g.adjacent[n]) {
        if (!seen[m]) { seen[m] = true; q.push_back(m); }
      }
    }
    for (size_t i = 0; i < seen.size(); ++i) EXPECT_TRUE(seen[i]) << name << " node " << i << " unreachable";
    // Every route edge is free of walls (the robot drives it), nodes lie inside the building.
    for (size_t a = 0; a < g.nodes.size(); ++a) {
      EXPECT_TRUE(w.bounds.contains(g.nodes[a])) << name << " node " << a;
      for (int b : g.adjacent[a]) {
        const Vec2 d = g.nodes[b] - g.nodes[a];
        const RayHit h = cast_ray(w, g.nodes[a], std::atan2(d.y(), d.x()), d.norm(), 0, false);
        EXPECT_FALSE(h.hit) << name << ": edge " << a << "→" << b << " crosses a wall at " << h.range << " m";
      }
    }
  }
  World w;
  std::string err;
  ASSERT_TRUE(make_builtin_world("large-office", &w, &err));
  EXPECT_DOUBLE_EQ(w.bounds.max.x() - w.bounds.min.x(), 81.0);
  EXPECT_DOUBLE_EQ(w.bounds.max.y() - w.bounds.min.y(), 47.0);
  EXPECT_EQ(w.unknown_areas.size(), 1u);
  EXPECT_FALSE(make_builtin_world("huge-office", &w, &err));
  EXPECT_NE(err.find("huge-office"), std::string::npos);
  EXPECT_NE(err.find("large-office"), std::string::npos);
}

TEST(Route, LengthSeedAndUnknownAreaAreRespected) {
  World w;
  std::string err;
  ASSERT_TRUE(make_builtin_world("large-office", &w, &err));
  RouteOptions opt;
  opt.length_m = 120;
  RouteTrajectory a, b, c;
  fw::RandomStream r1(5, 1), r2(5, 1), r3(6, 1);
  ASSERT_TRUE(generate_route(w, opt, &r1, &a, nullptr, &err)) << err;
  ASSERT_TRUE(generate_route(w, opt, &r2, &b, nullptr, &err));
  ASSERT_TRUE(generate_route(w, opt, &r3, &c, nullptr, &err));
  EXPECT_NEAR(a.length(), 120.0, 1e-6);
  ASSERT_EQ(a.pieces().size(), b.pieces().size());
  for (size_t i = 0; i < a.pieces().size(); ++i) EXPECT_EQ(a.pieces()[i].t1, b.pieces()[i].t1);
  EXPECT_NE(a.pose_at(60).x, c.pose_at(60).x);
  // Continuous in time, inside the building, never in the unknown area, speed respected.
  fw::Se2d prev = a.pose_at(0);
  for (double t = 0.05; t <= a.duration(); t += 0.05) {
    const fw::Se2d p = a.pose_at(t);
    EXPECT_LE(std::hypot(p.x - prev.x, p.y - prev.y), opt.speed * 0.05 + 1e-9);
    EXPECT_TRUE(w.bounds.contains(Vec2(p.x, p.y)));
    EXPECT_FALSE(w.unknown_areas[0].contains(Vec2(p.x, p.y))) << t;
    prev = p;
  }
  opt.start_node = 100000;
  EXPECT_FALSE(generate_route(w, opt, &r1, &a, nullptr, &err));
  EXPECT_NE(err.find("start node"), std::string::npos);
}

TEST(SyntheticRun, DeterministicAndEveryScanIsBracketedByOdometry) {
  World w;
  std::string err;
  ASSERT_TRUE(make_builtin_world("small-office", &w, &err));
  SyntheticRunOptions opt;
  opt.seed = 3;
  opt.max_scans = 80;
  SyntheticRun r1, r2;
  ASSERT_TRUE(r1.init(w, opt, &err)) << err;
  ASSERT_TRUE(r2.init(w, opt, &err));
  EXPECT_EQ(r1.num_scans(), 80u);
  EXPECT_EQ(r1.world().people.size(), 1u);  // 240 m² / 150
  SyntheticFrame f1, f2;
  std::uint64_t last_odom = 0;
  bool first = true;
  while (r1.next(&f1)) {
    ASSERT_TRUE(r2.next(&f2));
    ASSERT_EQ(f1.scan.beam_count, f2.scan.beam_count);
    for (std::uint32_t i = 0; i < f1.scan.beam_count; ++i) ASSERT_EQ(f1.scan.ranges[i], f2.scan.ranges[i]);
    ASSERT_EQ(f1.odometry.size(), f2.odometry.size());
    ASSERT_FALSE(f1.odometry.empty());
    for (size_t i = 0; i < f1.odometry.size(); ++i) {
      EXPECT_EQ(f1.odometry[i].x, f2.odometry[i].x);
      if (!first) EXPECT_GT(f1.odometry[i].timestamp_ns, last_odom);
      last_odom = f1.odometry[i].timestamp_ns;
      first = false;
    }
    EXPECT_GE(f1.odometry.back().timestamp_ns, f1.scan.timestamp_ns);  // bracketed from above
    if (f1.odometry.size() >= 2) EXPECT_LT(f1.odometry[f1.odometry.size() - 2].timestamp_ns, f1.scan.timestamp_ns);
  }
  EXPECT_FALSE(r2.next(&f2));
  SyntheticRunOptions bad = opt;
  bad.odometry_per_scan = 0;
  EXPECT_FALSE(r1.init(w, bad, &err));
  EXPECT_NE(err.find("odometry samples"), std::string::npos);
}

TEST(Route, ViaUnknownDrivesIntoTheUnknownArea) {
  World w;
  std::string err;
  ASSERT_TRUE(make_builtin_world("large-office", &w, &err));
  RouteOptions opt;
  opt.via_unknown = true;
  opt.length_m = 200;
  for (std::uint64_t seed : {1, 2, 3}) {
    fw::RandomStream rng(seed, 1);
    RouteTrajectory t;
    ASSERT_TRUE(generate_route(w, opt, &rng, &t, nullptr, &err)) << err;
    EXPECT_FALSE(w.unknown_areas[0].contains(Vec2(t.pose_at(0).x, t.pose_at(0).y)));
    bool inside = false;
    for (double s = 0; s <= t.duration(); s += 0.2) {
      const fw::Se2d p = t.pose_at(s);
      inside |= w.unknown_areas[0].contains(Vec2(p.x, p.y));
    }
    EXPECT_TRUE(inside) << "seed " << seed;
  }
  World corridor;
  ASSERT_TRUE(make_builtin_world("corridor", &corridor, &err));
  fw::RandomStream rng(1, 1);
  RouteTrajectory t;
  EXPECT_FALSE(generate_route(corridor, opt, &rng, &t, nullptr, &err));
  EXPECT_NE(err.find("no unknown area"), std::string::npos);
}

TEST(SyntheticRun, KidnappingJumpsTheTruthButNotTheOdometry) {
  World w;
  std::string err;
  ASSERT_TRUE(make_builtin_world("large-office", &w, &err));
  SyntheticRunOptions opt;
  opt.seed = 9;
  opt.kidnap_at_scan = 50;
  opt.max_scans = 80;
  SyntheticRun run;
  ASSERT_TRUE(run.init(w, opt, &err)) << err;
  SyntheticFrame f;
  fw::Se2d prev_truth;
  hal::Odometry prev_odom;
  int kidnaps = 0;
  while (run.next(&f)) {
    if (f.index > 0) {
      const double jump = std::hypot(f.truth.x - prev_truth.x, f.truth.y - prev_truth.y);
      const hal::Odometry& o = f.odometry.back();
      const double odom_step = std::hypot(o.x - prev_odom.x, o.y - prev_odom.y);
      EXPECT_LT(odom_step, 1.0) << f.index;  // wheels: at most one scan period of driving + noise
      if (f.kidnapped) {
        ++kidnaps;
        EXPECT_EQ(f.index, 50u);
        EXPECT_GT(jump, 9.0);
      } else {
        EXPECT_LT(jump, 0.75 * opt.scan_period_s + 1e-6) << f.index;
      }
    }
    prev_truth = f.truth;
    prev_odom = f.odometry.back();
  }
  EXPECT_EQ(kidnaps, 1);
  opt.kidnap_at_scan = 1000000;
  EXPECT_FALSE(run.init(w, opt, &err));
  EXPECT_NE(err.find("kidnap"), std::string::npos);
}

}  // namespace
}  // namespace sim
