#include "firmware/map/paired_fit_test.h"

#include <cmath>

#include "firmware/map/distance_sample.h"

namespace fw {

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

}  // namespace fw
