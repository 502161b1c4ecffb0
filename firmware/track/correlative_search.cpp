#include "firmware/track/correlative_search.h"

#include <cmath>

#include "firmware/map/nearest_distance_batch.h"

namespace fw {
namespace track {

namespace {
// Truncated score of an end-point at distance d from the nearest wall: 1 on it, 0 beyond clip.
inline float truncated_score(float d, float inv_clip2) {
  const float s = 1.0f - d * d * inv_clip2;
  return s > 0.0f ? s : 0.0f;
}
// The same at an end-point in world coordinates (0 off the map).
inline float point_score(const GlobalMap& map, float x, float y, float inv_clip2) {
  return truncated_score(map.distance_at(x, y, 1e9f), inv_clip2);
}
// Σ point_score over `points` translated by (x, y), in point order: the cell look-ups in batches
// (nearest_distance_batch.h, distance_at's bits), the sum as the scalar loop adds it.
inline double translated_score_sum(const GlobalMap& map, const Point2f* points, std::size_t m, float x, float y,
                                   float inv_clip2) {
  alignas(32) float d[kDistanceBatch];
  double sum = 0.0;
  for (std::size_t k = 0; k < m; k += kDistanceBatch) {
    const std::size_t len = m - k < kDistanceBatch ? m - k : kDistanceBatch;
    nearest_distance_batch(map, points + k, len, x, y, 1e9f, d);
    for (std::size_t i = 0; i < len; ++i) sum += truncated_score(d[i], inv_clip2);
  }
  return sum;
}
}  // namespace

float fit_score(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose, float clip_m) {
  if (!map.valid() || n == 0 || !(clip_m > 0.0f)) return 0.0f;
  const float inv = 1.0f / (clip_m * clip_m);
  const float c = std::cos(pose.theta), s = std::sin(pose.theta);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const float px = points[i].x(), py = points[i].y();
    sum += point_score(map, pose.x + c * px - s * py, pose.y + s * px + c * py, inv);
  }
  return static_cast<float>(sum / static_cast<double>(n));
}

CorrelativeResult correlative_search(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& seed,
                                     const CorrelativeWindow& window, const CorrelativeSearchOptions& o,
                                     Point2f* scratch, std::size_t scratch_len) {
  CorrelativeResult r;
  r.pose = seed;
  if (!map.valid() || n == 0 || scratch == nullptr || scratch_len < 2) return r;
  // Evenly subsampled end-points (first half of the scratch), rotated once per heading (second half).
  Point2f* const sub = scratch;
  Point2f* const rot = scratch + scratch_len / 2;
  const std::size_t cap = o.max_points < scratch_len / 2 ? o.max_points : scratch_len / 2;
  const std::size_t stride = (n + cap - 1) / cap;
  std::size_t m = 0;
  for (std::size_t i = 0; i < n && m < cap; i += stride) sub[m++] = points[i];
  r.seed_score = fit_score(map, sub, m, seed, o.clip_m);
  r.score = r.seed_score;

  // Grid sizes; the steps are coarsened together until the candidate count fits the budget.
  float lin = o.linear_step_m, ang = o.angular_step_rad;
  std::int32_t nx = 0, nt = 0;
  for (int k = 0; k < 32; ++k) {
    nx = static_cast<std::int32_t>(std::floor(window.xy_m / lin));
    nt = static_cast<std::int32_t>(std::floor(window.theta_rad / ang));
    const double count = static_cast<double>(2 * nx + 1) * (2 * nx + 1) * (2 * nt + 1);
    if (count <= o.max_candidates) break;
    lin *= 1.25f;
    ang *= 1.25f;
  }
  const float inv = 1.0f / (o.clip_m * o.clip_m);
  for (std::int32_t it = -nt; it <= nt; ++it) {
    const float th = wrap_angle(seed.theta + static_cast<float>(it) * ang);
    const float c = std::cos(th), s = std::sin(th);
    for (std::size_t i = 0; i < m; ++i) {
      rot[i] = Point2f(c * sub[i].x() - s * sub[i].y(), s * sub[i].x() + c * sub[i].y());
    }
    for (std::int32_t ix = -nx; ix <= nx; ++ix) {
      const float x = seed.x + static_cast<float>(ix) * lin;
      for (std::int32_t iy = -nx; iy <= nx; ++iy) {
        const float y = seed.y + static_cast<float>(iy) * lin;
        ++r.candidates;
        const double sum = translated_score_sum(map, rot, m, x, y, inv);
        const float sc = static_cast<float>(sum / static_cast<double>(m));
        if (sc > r.score) {  // strict: the seed (and the first of equals) wins ties
          r.score = sc;
          r.pose = Se2f(x, y, th);
        }
      }
    }
  }
  return r;
}

}  // namespace track
}  // namespace fw
