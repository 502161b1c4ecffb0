// Polar scan → Cartesian points in the sensor frame. Invalid readings (NaN, ±inf, below range_min,
// at/above range_max = "no return", or beyond a caller's max_range) are dropped and counted, never
// propagated: every consumer (RBSM, pRANSAM queries, MCL) starts from this.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "hal/msg/laser_scan.h"

namespace fw {

using Point2f = Eigen::Matrix<float, 2, 1>;

struct ScanPointsOptions {
  float max_range = 0.0f;  // 0: use the scan's range_max; else min(range_max, max_range)
  std::uint32_t stride = 1;  // use every k-th beam
};

struct ScanPointsResult {
  std::size_t count = 0;          // points written
  std::size_t invalid = 0;        // NaN/inf/negative readings
  std::size_t out_of_range = 0;   // below min or at/beyond max range
};

// Validates the scan header (beam_count ≤ kMaxBeams, finite angles, positive increment) and
// writes up to `capacity` points. A malformed header is an error naming the problem.
Status scan_to_points(const hal::LaserScan& scan, const ScanPointsOptions& options, Point2f* out,
                      std::size_t capacity, ScanPointsResult* result);

}  // namespace fw
