#include "firmware/mml/pose_refiner.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "firmware/map/distance_sample.h"

namespace fw {
namespace mml {

RefineResult refine_pose(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& initial,
                         const RefineOptions& o) {
  RefineResult r;
  r.pose = initial;
  if (!map.valid() || n == 0) return r;
  Se2f t = initial;
  std::size_t inl = 0;
  double sq = 0.0;
  for (std::uint32_t it = 0; it <= o.iterations; ++it) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    const float c = std::cos(t.theta), s = std::sin(t.theta);
    inl = 0;
    sq = 0.0;
    const float clip = (it < o.iterations / 2) ? 2.0f * o.clip_m : o.clip_m;
    const double wd = 1.0 / (static_cast<double>(o.sigma_m) * o.sigma_m);
    for (std::size_t i = 0; i < n; ++i) {
      const float px = points[i].x(), py = points[i].y();
      const float qx = t.x + c * px - s * py, qy = t.y + s * px + c * py;
      float d, gx, gy;
      if (!sample_distance<float>(map, qx, qy, &d, &gx, &gy) || d > clip) continue;
      ++inl;
      sq += static_cast<double>(d) * d;
      const Eigen::Vector3d j(gx, gy, gx * (-s * px - c * py) + gy * (c * px - s * py));
      h += wd * (j * j.transpose());
      b += wd * static_cast<double>(d) * j;
    }
    if (it == o.iterations || inl < 3) break;
    // Prior N(initial, diag(σ_xy², σ_xy², σ_θ²)).
    const double pxy = 1.0 / (static_cast<double>(o.prior_sigma_xy_m) * o.prior_sigma_xy_m);
    const double pth = 1.0 / (static_cast<double>(o.prior_sigma_theta_rad) * o.prior_sigma_theta_rad);
    h(0, 0) += pxy;
    h(1, 1) += pxy;
    h(2, 2) += pth;
    b(0) += pxy * (t.x - initial.x);
    b(1) += pxy * (t.y - initial.y);
    b(2) += pth * wrap_angle(t.theta - initial.theta);
    h.diagonal() += Eigen::Vector3d(1e-6, 1e-6, 1e-6) * (1.0 + h.trace());  // Levenberg damping
    const Eigen::Vector3d dx = -h.ldlt().solve(b);
    if (!dx.allFinite()) break;
    t = Se2f(t.x + static_cast<float>(dx(0)), t.y + static_cast<float>(dx(1)), wrap_angle(t.theta + static_cast<float>(dx(2))));
    if (dx.head<2>().norm() < 1e-4 && std::fabs(dx(2)) < 1e-4) {
      // Converged: one more pass computes the final statistics.
      it = o.iterations - 1;
    }
  }
  r.inlier_ratio = static_cast<float>(inl) / static_cast<float>(n);
  r.rms_m = inl ? static_cast<float>(std::sqrt(sq / inl)) : 0.0f;
  const float shift = std::hypot(t.x - initial.x, t.y - initial.y);
  r.accepted = r.inlier_ratio >= o.min_inlier_ratio && shift <= o.max_shift_m;
  r.pose = r.accepted ? t : initial;
  return r;
}

}  // namespace mml
}  // namespace fw
