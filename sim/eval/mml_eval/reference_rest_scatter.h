// How much the reference moves while the wheels say the robot stands still (an evaluation figure,
// not a localizer guard).
//
// A protection level of ~0.1 m / ~1.3° can only be judged at the 1e-3 level against a reference
// that is itself much better than that. Where the wheels report no motion between two consecutive
// scans, the robot did not move (odometry over one scan interval is good to millimetres at rest),
// so any motion of the reference between those scans is the reference's own per-scan error. The
// corrected logs that are per-scan SLAM output (fr079: GMapping, a pose for 4791 of 4934 scans)
// jitter like that; references chained from sparse corrected poses with the odometry (intel, aces)
// do not, except at the corrected poses. The figure is reported beside the exceedance rate so that
// a reader sees when the reference is too coarse to judge the bound; it does not clear any step.
#pragma once

#include <cstddef>
#include <vector>

#include "firmware/base/se2.h"

namespace sim::mmleval {

struct RestScatterOptions {
  double rest_m = 0.001;    // odometry increment below which the robot stood still (m)
  double rest_rad = 0.001;  // (rad)
};

struct RestScatter {
  std::size_t pairs = 0;  // consecutive scan pairs at rest (odometry)
  // Reference motion between them (m / rad): median and 99th percentile; NaN when pairs == 0.
  double m_p50 = 0, m_p99 = 0, rad_p50 = 0, rad_p99 = 0;
};

// `reference` and `odometry` hold one pose per scan (same length; a shorter one limits the pairs).
RestScatter reference_rest_scatter(const std::vector<fw::Se2d>& reference, const std::vector<fw::Se2d>& odometry,
                                   const RestScatterOptions& opt = {});

}  // namespace sim::mmleval
