// Shared by the ICP baselines: the finite end-points of a scan within max_range (0 = no limit),
// copied into the matcher's structure-of-arrays buffers. Returns how many were kept.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "firmware/rbsm/scan_matcher.h"

namespace fw {

inline std::uint32_t copy_valid_points(const Point2f* points, std::size_t count, float max_range, float* px,
                                       float* py) {
  const float max_r2 = max_range > 0.0f ? max_range * max_range : 0.0f;
  std::uint32_t n = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const float x = points[i](0), y = points[i](1);
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    if (max_r2 > 0.0f && x * x + y * y > max_r2) continue;
    px[n] = x;
    py[n] = y;
    ++n;
  }
  return n;
}

}  // namespace fw
