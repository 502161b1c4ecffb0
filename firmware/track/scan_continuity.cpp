#include "firmware/track/scan_continuity.h"

#include <cmath>

namespace fw {
namespace track {

namespace {
std::size_t bin_of(float x, float y) {
  constexpr float kTwoPi = 6.28318531f;
  float a = std::atan2(y, x);
  if (a < 0.0f) a += kTwoPi;
  const std::size_t b = static_cast<std::size_t>(a / kTwoPi * static_cast<float>(ScanContinuity::kBins));
  return b < ScanContinuity::kBins ? b : ScanContinuity::kBins - 1;
}
}  // namespace

float ScanContinuity::explained_fraction(const Point2f* prev, std::size_t n_prev, const Point2f* cur,
                                         std::size_t n_cur, const Se2f& motion, float tolerance_m) {
  if (n_cur == 0) return 1.0f;
  for (float& r : nearest_) r = INFINITY;
  const Se2f to_cur = motion.inverse();  // previous sensor frame → this one
  for (std::size_t i = 0; i < n_prev; ++i) {
    const Point2f q = to_cur.transform_point(prev[i]);
    const std::size_t b = bin_of(q.x(), q.y());
    nearest_[b] = std::fmin(nearest_[b], std::hypot(q.x(), q.y()));
  }
  std::size_t explained = 0;
  for (std::size_t i = 0; i < n_cur; ++i) {
    const float r = std::hypot(cur[i].x(), cur[i].y());
    const std::size_t b = bin_of(cur[i].x(), cur[i].y());
    for (std::size_t d = 0; d < 3; ++d) {
      const std::size_t k = (b + kBins - 1 + d) % kBins;
      if (std::fabs(nearest_[k] - r) <= tolerance_m) {
        ++explained;
        break;
      }
    }
  }
  return static_cast<float>(explained) / static_cast<float>(n_cur);
}

}  // namespace track
}  // namespace fw
