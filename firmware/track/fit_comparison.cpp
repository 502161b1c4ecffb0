#include "firmware/track/fit_comparison.h"

#include <cmath>

#include "firmware/base/sym2_eigen.h"
#include "firmware/map/distance_sample.h"

namespace fw {
namespace track {

namespace {
double truncated_cost(const GlobalMap& map, float x, float y, float clip_m, double clip2) {
  float d = 0.0f, gx = 0.0f, gy = 0.0f;
  if (!sample_distance<float>(map, x, y, &d, &gx, &gy) || d > clip_m) return 1.0;
  return static_cast<double>(d) * d / clip2;
}
}  // namespace

bool rival_significantly_better(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& pose,
                                const Se2f& rival, float clip_m, std::uint32_t independent, float z) {
  if (n < 2 || independent < 2) return false;
  const float c0 = std::cos(pose.theta), s0 = std::sin(pose.theta);
  const float c1 = std::cos(rival.theta), s1 = std::sin(rival.theta);
  const double clip2 = static_cast<double>(clip_m) * clip_m;
  double sum = 0.0, sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const float px = pts[i].x(), py = pts[i].y();
    const double diff = truncated_cost(map, pose.x + c0 * px - s0 * py, pose.y + s0 * px + c0 * py, clip_m, clip2) -
                        truncated_cost(map, rival.x + c1 * px - s1 * py, rival.y + s1 * px + c1 * py, clip_m, clip2);
    sum += diff;
    sq += diff * diff;
  }
  const double mean = sum / static_cast<double>(n);
  const double var = std::fmax(sq / static_cast<double>(n) - mean * mean, 0.0);
  const double se = std::sqrt(var / static_cast<double>(independent));
  return mean > static_cast<double>(z) * se;
}

ConfidenceExtent confidence_extent(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& fix,
                                   float info_xx, float info_xy, float info_yy, std::uint32_t independent,
                                   const ConfidenceExtentOptions& o) {
  ConfidenceExtent e;
  if (n < 2 || independent < 2 || !(o.step_m > 0.0f) || !(o.step_rad > 0.0f)) return e;
  // max_xy_m / max_rad of 0 skip that part (each test costs 2n distance samples).
  const Sym2Eigen ev = sym2_eigen(info_xx, info_xy, info_yy);
  // The weak axis (least information) and its normal; both directions of each.
  const float ax[2][2] = {{ev.vmin_x, ev.vmin_y}, {-ev.vmin_y, ev.vmin_x}};
  for (const auto& a : ax) {
    for (const float sign : {1.0f, -1.0f}) {
      float open = 0.0f;
      for (float s = o.step_m; s <= o.max_xy_m + 1e-6f; s += o.step_m) {
        const Se2f r(fix.x + sign * s * a[0], fix.y + sign * s * a[1], fix.theta);
        if (rival_significantly_better(map, pts, n, r, fix, o.clip_m, independent, o.z)) break;
        open = s;
      }
      e.xy_m = std::fmax(e.xy_m, open);
    }
  }
  for (const float sign : {1.0f, -1.0f}) {
    float open = 0.0f;
    for (float t = o.step_rad; t <= o.max_rad + 1e-7f; t += o.step_rad) {
      const Se2f r(fix.x, fix.y, wrap_angle(fix.theta + sign * t));
      if (rival_significantly_better(map, pts, n, r, fix, o.clip_m, independent, o.z)) break;
      open = t;
    }
    e.theta_rad = std::fmax(e.theta_rad, open);
  }
  return e;
}

}  // namespace track
}  // namespace fw
