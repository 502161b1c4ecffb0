#include "firmware/map/paired_fit_test.h"

#include <cmath>

#include "firmware/map/distance_batch.h"
#include "firmware/map/distance_sample.h"

namespace fw {

namespace {
// The paired test's verdict from the sums of the per-point differences and their squares.
bool paired_verdict(double sum, double sq, std::size_t n, std::uint32_t independent, float z) {
  const double mean = sum / static_cast<double>(n);
  const double var = std::fmax(sq / static_cast<double>(n) - mean * mean, 0.0);
  const double se = std::sqrt(var / static_cast<double>(independent));
  return mean > static_cast<double>(z) * se;
}
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
  return paired_verdict(sum, sq, n, independent, z);
}

namespace {
// The per-point truncated costs at `pose` (as truncated_cost above: use = on the grid and d ≤ clip).
void batch_costs(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& pose, float clip_m,
                 double clip2, double* out) {
  const float c = std::cos(pose.theta), s = std::sin(pose.theta);
  DistanceBatch batch;
  for (std::size_t i0 = 0; i0 < n; i0 += kDistanceBatch) {
    const std::size_t m = n - i0 < kDistanceBatch ? n - i0 : kDistanceBatch;
    sample_distance_batch(map, pts + i0, m, pose.x, pose.y, c, s, clip_m, &batch);
    for (std::size_t j = 0; j < m; ++j) {
      const double d = batch.d[j];
      out[i0 + j] = batch.use[j] ? d * d / clip2 : 1.0;
    }
  }
}
}  // namespace

PairedFitReference::PairedFitReference(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& fixed,
                                       float clip_m)
    : map_(map), pts_(pts), n_(n), fixed_(fixed), clip_m_(clip_m), cached_(n <= kMaxPoints) {
  if (cached_) batch_costs(map, pts, n, fixed, clip_m, static_cast<double>(clip_m) * clip_m, cost_);
}

bool PairedFitReference::fixed_better_than(const Se2f& pose, std::uint32_t independent, float z) const {
  if (!cached_) return rival_significantly_better(map_, pts_, n_, pose, fixed_, clip_m_, independent, z);
  if (n_ < 2 || independent < 2) return false;
  double cost[kMaxPoints];
  batch_costs(map_, pts_, n_, pose, clip_m_, static_cast<double>(clip_m_) * clip_m_, cost);
  double sum = 0.0, sq = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    const double diff = cost[i] - cost_[i];
    sum += diff;
    sq += diff * diff;
  }
  return paired_verdict(sum, sq, n_, independent, z);
}

}  // namespace fw
