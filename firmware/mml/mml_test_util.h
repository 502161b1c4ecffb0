// Synthetic-world harness for the MML / hand-off tests: a true world (GridWorld), a global map
// built from a (possibly edited) copy, simulated scans and noisy odometry along a path.
#pragma once

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "firmware/base/rng.h"
#include "firmware/map/global_map.h"
#include "firmware/baselines/mcl/mcl_test_world.h"
#include "firmware/runtime/localizer.h"

namespace fw {
namespace mml {
namespace testing {

using mcl::testing::GridWorld;

struct OwnedGlobalMap {
  std::vector<Point2f> points;
  GlobalMap map;
  explicit OwnedGlobalMap(const GridWorld& g) {
    for (std::uint32_t y = 0; y < g.h; ++y)
      for (std::uint32_t x = 0; x < g.w; ++x)
        if (g.occ[y * g.w + x] == 100) points.emplace_back((x + 0.5f) * g.res, (y + 0.5f) * g.res);
    map.geometry.resolution = g.res;
    map.geometry.width = g.w;
    map.geometry.height = g.h;
    map.occupancy = g.occupancy_tiles();
    map.distance = g.distance_field();
    map.points = points.data();
    map.num_points = static_cast<std::uint32_t>(points.size());
  }
};

struct StepRecord {
  Se2f truth;
  hal::PoseEstimate est;
  std::string error;
  std::string note;  // filled by the caller's hook (e.g. interpreter internals)
};

// Drives `loc` along `path` (true poses) in `world`, feeding odometry with small multiplicative
// noise (seeded). Returns one record per scan. `wheels`, if given, may change the odometry of scan
// i before it is fed (a slip: the change stays in every later odometry).
inline std::vector<StepRecord> drive(Localizer* loc, const GridWorld& world, const std::vector<Se2f>& path,
                                     std::uint64_t seed, std::function<void(StepRecord*)> hook = nullptr,
                                     std::function<void(std::size_t, Se2f*)> wheels = nullptr) {
  static hal::LaserScan scan;
  RandomStream rng(seed, 42);
  std::vector<StepRecord> out;
  Se2f odom(0, 0, 0);
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0) {
      Se2f d = path[i - 1].between(path[i]);
      d.x *= 1.0f + 0.02f * static_cast<float>(rng.gaussian());
      d.y *= 1.0f + 0.02f * static_cast<float>(rng.gaussian());
      const float scale = 1.0f + 0.02f * static_cast<float>(rng.gaussian());  // one draw per statement
      d.theta = d.theta * scale + 0.002f * static_cast<float>(rng.gaussian());
      odom = odom.compose(d);
    }
    if (wheels) wheels(i, &odom);
    mcl::testing::simulate_scan(world.view(), path[i].x, path[i].y, path[i].theta, &scan);
    for (std::uint32_t b = 0; b < scan.beam_count; ++b) {
      if (scan.ranges[b] < scan.range_max) scan.ranges[b] += 0.005f * static_cast<float>(rng.gaussian());
    }
    scan.scan_id = static_cast<std::uint32_t>(i);
    scan.timestamp_ns = i * 100000000ull;
    hal::Odometry od;
    od.timestamp_ns = scan.timestamp_ns;
    od.x = odom.x;
    od.y = odom.y;
    od.theta = odom.theta;
    StepRecord r;
    r.truth = path[i];
    const Status s = loc->step(scan, od, &r.est);
    if (!s.is_ok()) {
      r.est.status = hal::LocalizationStatus::kFault;
      r.error = s.message();
    }
    if (hook) hook(&r);
    out.push_back(r);
  }
  return out;
}

// One "trace" line per step of what it published (floats as exact hex): scripts/check_cross_target.py
// compares the host's run with the robot CPU's (aarch64 under qemu) — statuses and counts exactly,
// values to within its tolerance (glibc's atan2f differs in the last bit between x86-64 and aarch64).
inline void print_trace(const char* name, const std::vector<StepRecord>& rec) {
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const hal::PoseEstimate& e = rec[i].est;
    std::printf("trace %s %zu %d %d %u %u %u %d %a %a %a %a %a %a\n", name, i, static_cast<int>(e.status),
                static_cast<int>(e.mode), e.hypothesis_count, e.cluster_count, e.unsupported_steps,
                static_cast<int>(e.reason), e.x, e.y, e.theta, e.protection_xy_m, e.protection_theta_rad, e.cov[0]);
  }
}

// Straight segments through waypoints at `step` metres per scan, turning in place at corners.
inline std::vector<Se2f> waypoint_path(const std::vector<std::pair<float, float>>& wps, float step) {
  std::vector<Se2f> path;
  for (std::size_t k = 0; k + 1 < wps.size(); ++k) {
    const float x0 = wps[k].first, y0 = wps[k].second, x1 = wps[k + 1].first, y1 = wps[k + 1].second;
    const float th = std::atan2(y1 - y0, x1 - x0);
    if (!path.empty()) {  // turn in place
      const float th0 = path.back().theta;
      const float dth = wrap_angle(th - th0);
      const int n = static_cast<int>(std::fabs(dth) / 0.3f);
      for (int i = 1; i <= n; ++i) path.emplace_back(x0, y0, wrap_angle(th0 + dth * i / (n + 1)));
    }
    const float len = std::hypot(x1 - x0, y1 - y0);
    const int n = static_cast<int>(len / step);
    for (int i = 0; i < n; ++i) path.emplace_back(x0 + (x1 - x0) * i / n, y0 + (y1 - y0) * i / n, th);
  }
  return path;
}

// The right part of the building (x > 6 m) is missing from the global map, and it is a different
// layout from anything mapped.
struct UnknownWorld {
  GridWorld world = mcl::testing::unique_room();
  GridWorld mapped;
  UnknownWorld() {
    mapped = world;
    for (std::uint32_t y = 0; y < mapped.h; ++y)
      for (std::uint32_t x = 0; x < mapped.w; ++x)
        if (x * mapped.res > 6.0f) mapped.occ[y * mapped.w + x] = 255;
    mapped.finish();
    for (std::uint32_t y = 0; y < world.h; ++y)
      for (std::uint32_t x = 0; x < world.w; ++x)
        if (x * world.res > 6.5f && world.occ[y * world.w + x] == 100) world.occ[y * world.w + x] = 0;
    world.wall(6.6f, 0.2f, 11.8f, 0.2f);
    world.wall(11.8f, 0.2f, 11.8f, 7.8f);
    world.wall(11.8f, 7.8f, 6.6f, 7.8f);
    world.wall(6.6f, 7.8f, 6.6f, 4.5f);  // doorway 1.2 m < y < 4.5 m into the unmapped part
    world.wall(8.0f, 5.5f, 10.5f, 3.5f);
    world.wall(9.0f, 7.8f, 9.0f, 6.0f);
    world.box(10.0f, 1.0f, 11.0f, 1.6f);
    world.finish();
  }
};

}  // namespace testing
}  // namespace mml
}  // namespace fw
