// The confidence extent of the protection level (extension of the dissertation), built on the paired
// test of two poses on the same scan (firmware/map/paired_fit_test.h).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/map/paired_fit_test.h"  // rival_significantly_better

namespace fw {
namespace track {

// How far the scan leaves the pose open: from `fix`, shifts of step_m, 2·step_m, … along both
// directions of both principal axes of the position information, and turns of step_rad, … in
// heading, until the fix is significantly better than the shifted pose (the paired test above at z).
// The farthest shift the scan cannot reject is a lower bound on what a protection level must cover:
// a corridor that fits as well 0.25 m further on (aces scan 5120: 152 against 151 end-points on the
// map) is not known to 1.4 cm whatever its information matrix says. Capped at max_xy_m/max_rad
// (the alert limits: beyond them the status is not `localized` anyway).
struct ConfidenceExtentOptions {
  float step_m = 0.05f;
  float max_xy_m = 0.5f;
  float step_rad = 0.00873f;  // 0.5°
  float max_rad = 0.0873f;    // 5°
  float clip_m = 0.15f;
  float z = 3.09f;
};
struct ConfidenceExtent {
  float xy_m = 0.0f;       // farthest shift not rejected (0: even the first step is rejected)
  float theta_rad = 0.0f;  // farthest turn not rejected
  float axis_m[2] = {0.0f, 0.0f};  // the same along the weak axis [0] and across it [1]
};
ConfidenceExtent confidence_extent(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& fix,
                                   float info_xx, float info_xy, float info_yy, std::uint32_t independent,
                                   const ConfidenceExtentOptions& o);

}  // namespace track
}  // namespace fw
