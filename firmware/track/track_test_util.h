// Shared by the tracking tests: a synthetic room, its global map and scans at known poses.
#pragma once

#include <vector>

#include "firmware/baselines/mcl/mcl_test_world.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/mml/mml_test_util.h"
#include "firmware/scan/scan_points.h"
#include "firmware/track/pose_tracker.h"

namespace fw {
namespace track {
namespace testing {

using mcl::testing::GridWorld;
using mml::testing::OwnedGlobalMap;

// MML sized for the small synthetic worlds of the tracking tests (fast start-up, small table).
inline mml::MmlLocalizerConfig small_mml_config() {
  mml::MmlLocalizerConfig c = mml::default_mml_config();
  c.mml.matching_iterations = 20000;
  c.mml.table_triples = 400000;
  c.mml.min_local_map_points = 100;
  return c;
}

// The 12 × 8 m room with a unique layout and its global map.
inline const GridWorld& room() {
  static GridWorld g = mcl::testing::unique_room();
  return g;
}
inline const OwnedGlobalMap& room_map() {
  static OwnedGlobalMap m(room());
  return m;
}

// A plain corridor 2 m wide and 30 m long: with a 4 m laser its ends are never seen. `stub` adds a
// 10 cm stub on one wall at x = 12 m (a door frame): a few end-points that constrain the axis.
inline GridWorld plain_corridor(bool stub = false) {
  GridWorld g;
  g.w = 600; g.h = 80;
  g.occ.assign(g.w * g.h, 0);
  g.box(0.5f, 1.0f, 29.5f, 3.0f);
  if (stub) g.wall(12.0f, 1.0f, 12.0f, 1.1f);
  g.finish();
  return g;
}

// Scan end-points (sensor frame) of a simulated scan at `pose` in `world`, with range noise.
inline std::vector<Point2f> scan_at(const GridWorld& world, const Se2f& pose, RandomStream* rng, float noise = 0.01f,
                                    float maxr = 8.0f) {
  static hal::LaserScan scan;
  mcl::testing::simulate_scan(world.view(), pose.x, pose.y, pose.theta, &scan, maxr);
  for (std::uint32_t b = 0; b < scan.beam_count; ++b)
    if (scan.ranges[b] < scan.range_max) scan.ranges[b] += noise * static_cast<float>(rng->gaussian());
  std::vector<Point2f> pts(hal::LaserScan::kMaxBeams);
  ScanPointsResult r;
  ScanPointsOptions so;
  if (!scan_to_points(scan, so, pts.data(), pts.size(), &r).is_ok()) r.count = 0;
  pts.resize(r.count);
  return pts;
}

// A tour through every part of the room (0.1 m steps), shared by the tracked-localizer tests.
inline std::vector<Se2f> room_tour() {
  return mml::testing::waypoint_path({{1.5f, 1.5f}, {1.5f, 6.5f}, {4.5f, 6.5f}, {4.5f, 2.0f}, {10.5f, 3.5f},
                                      {10.5f, 6.5f}, {8.0f, 6.5f}},
                                     0.1f);
}

}  // namespace testing
}  // namespace track
}  // namespace fw
