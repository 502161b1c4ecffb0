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

float ScanContinuity::explained_fraction_within(const Point2f* prev, std::size_t n_prev, const Point2f* cur,
                                                std::size_t n_cur, const Se2f& motion, float sigma_xy_m,
                                                float sigma_theta_rad, float tolerance_m) {
  constexpr float kTurns[7] = {0.0f, -0.67f, 0.67f, -1.33f, 1.33f, -2.0f, 2.0f};  // × σθ
  constexpr float kShifts[5][2] = {{0, 0}, {2, 0}, {-2, 0}, {0, 2}, {0, -2}};    // × σxy
  float best = 0.0f;
  for (const float t : kTurns) {
    for (const auto& s : kShifts) {
      // The offset applies in the frame of this scan's sensor: motion ⊕ δ.
      const Se2f m = motion.compose(Se2f(s[0] * sigma_xy_m, s[1] * sigma_xy_m, t * sigma_theta_rad));
      best = std::fmax(best, explained_fraction(prev, n_prev, cur, n_cur, m, tolerance_m));
      if (best >= 1.0f) return best;
      if (sigma_xy_m <= 0.0f) break;  // no translation noise: the shifts are all the same
    }
    if (sigma_theta_rad <= 0.0f) break;
  }
  return best;
}

}  // namespace track
}  // namespace fw
