// Test helpers of the evaluation's map checks (reference_map_check_test, unmapped_scan_test): a
// featureless corridor and the scan a simulated laser takes in it, as the checks read scans.
#pragma once

#include <cstdint>

#include "firmware/baselines/mcl/mcl_test_world.h"
#include "firmware/map/global_map.h"
#include "sim/eval/mml_eval/reference_map_check.h"

namespace sim::mmleval::testing {

using fw::mcl::testing::GridWorld;

// 20 × 4 m: a 2 m wide corridor with no feature along it, closed far beyond the laser's 8 m. With
// `known_to_m` < 20 the map's cells east of it are unknown (no wall, no free space), as a map built
// from part of a log.
inline GridWorld corridor(float known_to_m = 20.0f) {
  GridWorld g;
  g.w = 400;
  g.h = 80;
  g.occ.assign(g.w * g.h, 0);
  g.box(0.2f, 1.0f, 19.8f, 3.0f);
  for (std::uint32_t y = 0; y < g.h; ++y)
    for (std::uint32_t x = 0; x < g.w; ++x)
      if ((static_cast<float>(x) + 0.5f) * g.res > known_to_m) g.occ[y * g.w + x] = fw::kCellUnknown;
  g.finish();
  return g;
}

// The scan of the simulated 8 m laser at (x, y, th) in `world`.
inline CarmenScan scan_at(const GridWorld& world, double x, double y, double th) {
  static hal::LaserScan s;
  fw::mcl::testing::simulate_scan(world.view(), static_cast<float>(x), static_cast<float>(y), static_cast<float>(th), &s);
  return carmen_scan_of(s);
}

}  // namespace sim::mmleval::testing
