#include "firmware/mml/pose_uniqueness.h"

#include <cmath>

#include "firmware/base/sym2_eigen.h"
#include "firmware/map/distance_batch.h"
#include "firmware/map/distance_sample.h"
#include "firmware/mml/pose_refiner.h"

namespace fw {
namespace mml {

float truncated_scan_cost(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose, float clip_m) {
  if (n == 0) return 1.0f;
  const float c = std::cos(pose.theta), s = std::sin(pose.theta);
  const double clip2 = static_cast<double>(clip_m) * clip_m;
  double sum = 0.0;
  DistanceBatch batch;
  for (std::size_t i0 = 0; i0 < n; i0 += kDistanceBatch) {
    const std::size_t m = n - i0 < kDistanceBatch ? n - i0 : kDistanceBatch;
    sample_distance_batch(map, points + i0, m, pose.x, pose.y, c, s, clip_m, &batch);
    for (std::size_t j = 0; j < m; ++j) {
      const double d = batch.d[j];
      sum += batch.use[j] ? d * d / clip2 : 1.0;  // off the map or beyond the clip: the full cost
    }
  }
  return static_cast<float>(sum / static_cast<double>(n));
}

bool in_same_cost_valley(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose,
                         const Se2f& rival, float clip_m, float step_m, float margin) {
  return in_same_cost_valley(map, points, n, pose, truncated_scan_cost(map, points, n, pose, clip_m), rival,
                             truncated_scan_cost(map, points, n, rival, clip_m), clip_m, step_m, margin);
}

bool in_same_cost_valley(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose,
                         float cost_pose, const Se2f& rival, float cost_rival, float clip_m, float step_m,
                         float margin) {
  if (std::fabs(cost_pose - cost_rival) > margin) return false;  // one end fits worse: not one valley
  const float ceiling = std::fmax(cost_pose, cost_rival) + margin;
  const float dx = rival.x - pose.x, dy = rival.y - pose.y, dth = wrap_angle(rival.theta - pose.theta);
  const float d = std::hypot(dx, dy);
  // At most 1000 samples (75 m at the default step): the rivals of the alias check lie within 3 m.
  const int samples = step_m > 0.0f ? static_cast<int>(std::fmin(std::ceil(d / step_m), 1000.0f)) : 1;
  for (int k = 1; k < samples; ++k) {
    const float f = static_cast<float>(k) / static_cast<float>(samples);
    const Se2f on_path(pose.x + f * dx, pose.y + f * dy, wrap_angle(pose.theta + f * dth));
    if (truncated_scan_cost(map, points, n, on_path, clip_m) > ceiling) return false;
  }
  return true;
}

namespace {

// Principal axes of the translational information Σ ∇D ∇Dᵀ of the inliers at `pose` (columns,
// weak axis first). Falls back to the map axes when too few points are in contact.
Eigen::Matrix2f principal_axes(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose, float clip_m) {
  const DistanceSampler<float> sample(map);
  const float c = std::cos(pose.theta), s = std::sin(pose.theta);
  Eigen::Matrix2f h = Eigen::Matrix2f::Zero();
  std::size_t inl = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float px = points[i].x(), py = points[i].y();
    float d, gx, gy;
    if (!sample(pose.x + c * px - s * py, pose.y + s * px + c * py, &d, &gx, &gy) || d > clip_m) continue;
    const Eigen::Vector2f g(gx, gy);
    h += g * g.transpose();
    ++inl;
  }
  if (inl < 3) return Eigen::Matrix2f::Identity();
  const Sym2Eigen es = sym2_eigen(h(0, 0), h(0, 1), h(1, 1));
  Eigen::Matrix2f axes;
  axes << es.vmin_x, -es.vmin_y, es.vmin_y, es.vmin_x;  // column 0 = weak axis, column 1 its normal
  return axes;
}

}  // namespace

UniquenessResult check_pose_uniqueness(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose,
                                       const UniquenessOptions& o) {
  UniquenessResult r;
  r.cost = truncated_scan_cost(map, points, n, pose, o.clip_m);
  r.rival = pose;
  if (n == 0 || !map.valid() || o.shift_step_m <= 0.0f) return r;
  const Eigen::Matrix2f axes = principal_axes(map, points, n, pose, o.clip_m);
  RefineOptions ro;
  ro.clip_m = o.clip_m;
  ro.max_shift_m = o.shift_step_m;  // a rival stays near its seed: the seeds cover the line
  for (int a = 0; a < 2; ++a) {
    // valley_is_one_mode: per direction, the valley is followed outwards from the candidate through
    // the rivals found in it (each segment an in_same_cost_valley path, each rival within `margin`
    // of the candidate's cost), so a far rival costs one short path, not one from the candidate;
    // after a rival outside it, that direction's further rivals all count.
    Se2f valley_end[2] = {pose, pose};
    float valley_end_cost[2] = {r.cost, r.cost};  // their truncated costs
    bool valley_open[2] = {true, true};
    for (float step = o.shift_step_m; step <= o.max_shift_m + 1e-4f; step += o.shift_step_m) {
      for (int sign = -1; sign <= 1; sign += 2) {
        const Se2f seed(pose.x + sign * step * axes(0, a), pose.y + sign * step * axes(1, a), pose.theta);
        const RefineResult rr = refine_pose(map, points, n, seed, ro);
        ++r.rivals_tried;
        if (std::hypot(rr.pose.x - pose.x, rr.pose.y - pose.y) < o.min_separation_m) continue;
        // The refinement's own pass at rr.pose gives its cost (RefineResult::cost, the same bits).
        const float cost = rr.cost_valid ? rr.cost : truncated_scan_cost(map, points, n, rr.pose, o.clip_m);
        // Only a rival that would break uniqueness is tested for one valley (the path costs a
        // truncated cost per sample); a better one never is (in_same_cost_valley needs alike costs).
        if (o.valley_is_one_mode && cost <= r.cost + o.margin) {
          const int d = sign > 0 ? 1 : 0;
          if (valley_open[d] && std::fabs(wrap_angle(rr.pose.theta - pose.theta)) < o.min_separation_rad &&
              in_same_cost_valley(map, points, n, valley_end[d], valley_end_cost[d], rr.pose, cost, o.clip_m,
                                  o.valley_step_m, o.margin)) {
            valley_end[d] = rr.pose;
            valley_end_cost[d] = cost;
            ++r.same_valley_rivals;
            const float dx = rr.pose.x - pose.x, dy = rr.pose.y - pose.y, dist = std::hypot(dx, dy);
            if (dist > r.valley_extent_m) {
              r.valley_extent_m = dist;
              r.valley_axis_x = dx / dist;
              r.valley_axis_y = dy / dist;
            }
            continue;
          }
          valley_open[d] = false;
        }
        if (cost < r.rival_cost) {
          r.rival_cost = cost;
          r.rival = rr.pose;
          r.rival_turned = false;
        }
      }
    }
  }
  // Rivals in heading, refined from the candidate's position turned both ways.
  if (o.rotation_step_rad > 0.0f) {
    for (float rot = o.rotation_step_rad; rot <= o.max_rotation_rad + 1e-6f; rot += o.rotation_step_rad) {
      for (int sign = -1; sign <= 1; sign += 2) {
        const Se2f seed(pose.x, pose.y, wrap_angle(pose.theta + static_cast<float>(sign) * rot));
        const RefineResult rr = refine_pose(map, points, n, seed, ro);
        ++r.rivals_tried;
        if (std::fabs(wrap_angle(rr.pose.theta - pose.theta)) < o.min_separation_rad &&
            std::hypot(rr.pose.x - pose.x, rr.pose.y - pose.y) < o.min_separation_m)
          continue;
        const float cost = rr.cost_valid ? rr.cost : truncated_scan_cost(map, points, n, rr.pose, o.clip_m);
        if (cost < r.rival_cost) {
          r.rival_cost = cost;
          r.rival = rr.pose;
          r.rival_turned = true;
        }
      }
    }
  }
  r.unique = r.rival_cost > r.cost + o.margin;
  return r;
}

}  // namespace mml
}  // namespace fw
