#include "firmware/antslam/edge_fit.h"

#include <cmath>

namespace fw::antslam {

Status EdgeFitOptions::validate() const {
  if (grid_half == 0 || grid_half > 4) {
    return Status::error(Errc::kInvalidArgument, "antslam edge fit: grid_half %u not in 1..4", grid_half);
  }
  if (!(step_xy_m > 0.0 && step_theta_rad > 0.0 && sigma_m > 0.0 && clip_m > 0.0 && correlation_m > 0.0)) {
    return Status::error(Errc::kInvalidArgument, "antslam edge fit: steps, sigma, clip and correlation must be > 0");
  }
  if (!(min_effective_poses >= 1.0) || max_refinements > 16) {
    return Status::error(Errc::kInvalidArgument, "antslam edge fit: min_effective_poses >= 1, max_refinements <= 16");
  }
  return Status::ok();
}

namespace {

// Σ min(d, clip)² of the scene placed by `pose` (points off the field count as clipped).
double clipped_cost(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& pose,
                    double clip) {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double px = scene[i](0), py = scene[i](1);
    if (!std::isfinite(px) || !std::isfinite(py)) continue;
    const Point2f q(static_cast<float>(pose.x + c * px - s * py), static_cast<float>(pose.y + s * px + c * py));
    float d = 0.0f;
    Point2f g;
    const double dd = field.distance_gradient(q, &d, &g) && d < clip ? static_cast<double>(d) : clip;
    sum += dd * dd;
  }
  return sum;
}

// Observations: distinct cells of `side` (scene frame) holding finite end-points, counted on a
// fixed 64 × 64 bitmap over the points' bounding box (the cell grows when the box is wider than
// 64 cells: an outdoor scan), and the number of finite points. A fragment's points are the union of
// its keyframes, which see the same walls again and again: the same cells, one observation.
void count_observations(const Point2f* scene, std::size_t n, double side, std::uint32_t* cells,
                        std::uint32_t* finite) {
  *cells = *finite = 0;
  double lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(scene[i](0)) || !std::isfinite(scene[i](1))) continue;
    ++*finite;
    lo_x = std::fmin(lo_x, scene[i](0));
    hi_x = std::fmax(hi_x, scene[i](0));
    lo_y = std::fmin(lo_y, scene[i](1));
    hi_y = std::fmax(hi_y, scene[i](1));
  }
  if (*finite == 0) return;
  constexpr int kSide = 64;
  const double cell = std::fmax(side, std::fmax(hi_x - lo_x, hi_y - lo_y) / (kSide - 1));
  std::uint64_t bits[kSide] = {};
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(scene[i](0)) || !std::isfinite(scene[i](1))) continue;
    const int cx = static_cast<int>((scene[i](0) - lo_x) / cell), cy = static_cast<int>((scene[i](1) - lo_y) / cell);
    const int x = cx < 0 ? 0 : (cx >= kSide ? kSide - 1 : cx), y = cy < 0 ? 0 : (cy >= kSide ? kSide - 1 : cy);
    const std::uint64_t b = std::uint64_t{1} << x;
    if (!(bits[y] & b)) ++*cells;
    bits[y] |= b;
  }
}

}  // namespace

bool fit_edge(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& center,
              const EdgeFitOptions& o, EdgeFit* out) {
  if (!field.has_distance() || scene == nullptr || out == nullptr || !o.validate().is_ok()) return false;
  std::uint32_t cells = 0, finite = 0;
  count_observations(scene, n, o.correlation_m, &cells, &finite);
  if (finite < 3) return false;
  // Eq. 3.9 weights: exp(log-likelihood), the likelihood counted once per observation.
  const double scale = static_cast<double>(cells) / static_cast<double>(finite) / (2.0 * o.sigma_m * o.sigma_m);
  const int g = static_cast<int>(o.grid_half);
  constexpr int kMaxPoses = 9 * 9 * 9;  // grid_half ≤ 4 (validate)
  double ll[kMaxPoses];
  double sx = o.step_xy_m, st = o.step_theta_rad;
  for (std::uint32_t level = 0;; ++level) {
    double best = -INFINITY;
    int k = 0;
    for (int i = -g; i <= g; ++i)
      for (int j = -g; j <= g; ++j)
        for (int t = -g; t <= g; ++t, ++k) {
          const Se2d p(center.x + i * sx, center.y + j * sx, wrap_angle(center.theta + t * st));
          ll[k] = -scale * clipped_cost(field, scene, n, p, o.clip_m);
          if (ll[k] > best) best = ll[k];
        }
    double sw = 0.0, sw2 = 0.0;
    Vec3 m = Vec3::Zero();
    Mat3 second = Mat3::Zero();
    k = 0;
    for (int i = -g; i <= g; ++i)
      for (int j = -g; j <= g; ++j)
        for (int t = -g; t <= g; ++t, ++k) {
          const double w = std::exp(ll[k] - best);
          const Vec3 d(i * sx, j * sx, t * st);
          sw += w;
          sw2 += w * w;
          m += w * d;
          second += w * d * d.transpose();
        }
    const double ess = sw * sw / sw2;
    if (ess >= o.min_effective_poses || level >= o.max_refinements) {
      m /= sw;
      out->cov = second / sw;
      out->cov(0, 0) += sx * sx / 12.0;
      out->cov(1, 1) += sx * sx / 12.0;
      out->cov(2, 2) += st * st / 12.0;
      out->cov = 0.5 * (out->cov + out->cov.transpose());
      out->weighted_mean = Se2d(center.x + m(0), center.y + m(1), wrap_angle(center.theta + m(2)));
      out->effective_poses = ess;
      out->step_xy_m = sx;
      out->step_theta_rad = st;
      out->independent = cells;
      return true;
    }
    sx *= 0.5;
    st *= 0.5;
  }
}

}  // namespace fw::antslam
