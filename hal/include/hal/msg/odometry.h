// Odometry: the wheel-odometry pose in the odometry frame (x, y, θ) at a sample time. Deltas are
// formed by the firmware as (⊖prev) ⊕ cur, which is what the motion models consume.
#pragma once

#include <cstdint>

namespace hal {

struct Odometry {
  std::uint64_t timestamp_ns = 0;
  float x = 0.0f;      // m
  float y = 0.0f;      // m
  float theta = 0.0f;  // rad
  float v = 0.0f;      // m/s (0 if unknown)
  float omega = 0.0f;  // rad/s (0 if unknown)
};

}  // namespace hal
