#include "firmware/track/fit_comparison.h"

#include <cmath>

#include "firmware/base/sym2_eigen.h"

namespace fw {
namespace track {

ConfidenceExtent confidence_extent(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& fix,
                                   float info_xx, float info_xy, float info_yy, std::uint32_t independent,
                                   const ConfidenceExtentOptions& o) {
  ConfidenceExtent e;
  if (n < 2 || independent < 2 || !(o.step_m > 0.0f) || !(o.step_rad > 0.0f)) return e;
  // max_xy_m / max_rad of 0 skip that part (each test costs 2n distance samples).
  const Sym2Eigen ev = sym2_eigen(info_xx, info_xy, info_yy);
  // The weak axis (least information) and its normal; both directions of each.
  const float ax[2][2] = {{ev.vmin_x, ev.vmin_y}, {-ev.vmin_y, ev.vmin_x}};
  const PairedFitReference at_fix(map, pts, n, fix, o.clip_m);  // the fix's costs, sampled once
  for (int axis = 0; axis < 2; ++axis) {
    const auto& a = ax[axis];
    for (const float sign : {1.0f, -1.0f}) {
      float open = 0.0f;
      for (float s = o.step_m; s <= o.max_xy_m + 1e-6f; s += o.step_m) {
        const Se2f r(fix.x + sign * s * a[0], fix.y + sign * s * a[1], fix.theta);
        if (at_fix.fixed_better_than(r, independent, o.z)) break;
        open = s;
      }
      e.xy_m = std::fmax(e.xy_m, open);
      e.axis_m[axis] = std::fmax(e.axis_m[axis], open);
    }
  }
  for (const float sign : {1.0f, -1.0f}) {
    float open = 0.0f;
    for (float t = o.step_rad; t <= o.max_rad + 1e-7f; t += o.step_rad) {
      const Se2f r(fix.x, fix.y, wrap_angle(fix.theta + sign * t));
      if (at_fix.fixed_better_than(r, independent, o.z)) break;
      open = t;
    }
    e.theta_rad = std::fmax(e.theta_rad, open);
  }
  return e;
}

}  // namespace track
}  // namespace fw
