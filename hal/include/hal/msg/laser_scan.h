// LaserScan: one planar range scan as the sensor delivered it (polar). Fixed capacity so it can
// live in static rings; 1081 beams covers a 270° scanner at 0.25°.
#pragma once

#include <cstdint>

namespace hal {

struct LaserScan {
  static constexpr std::uint32_t kMaxBeams = 1081;

  std::uint64_t timestamp_ns = 0;  // sample time (first beam), monotonic clock domain
  std::uint32_t scan_id = 0;       // sensor sequence number
  std::uint32_t beam_count = 0;    // valid entries in ranges[]
  float angle_min = 0.0f;          // rad, angle of beam 0 in the sensor frame (x forward, CCW)
  float angle_increment = 0.0f;    // rad between beams
  float range_min = 0.0f;          // m; readings below are invalid
  float range_max = 0.0f;          // m; readings at/above are "no return"
  float ranges[kMaxBeams] = {};    // m
};

}  // namespace hal
