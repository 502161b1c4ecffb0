#include "firmware/mml/pose_refiner.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "firmware/map/distance_batch.h"
#include "firmware/scan/point_to_line.h"

namespace fw {
namespace mml {

RefineResult refine_pose(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& initial,
                         const RefineOptions& o) {
  RefineResult r;
  r.pose = initial;
  if (!map.valid() || n == 0) return r;
  Se2f t = initial;
  DistanceBatch batch;  // the samples of one pass, kDistanceBatch end-points at a time
  std::size_t inl = 0;
  double sq = 0.0;
  PointToLineSystem sys;  // the shared 2-D solver (firmware/scan/point_to_line.h)
  for (std::uint32_t it = 0; it <= o.iterations; ++it) {
    sys.clear();
    const float c = std::cos(t.theta), s = std::sin(t.theta);
    inl = 0;
    sq = 0.0;
    const float clip = (it < o.iterations / 2) ? 2.0f * o.clip_m : o.clip_m;
    const double wd = 1.0 / (static_cast<double>(o.sigma_m) * o.sigma_m);
    // The last pass only counts (no step follows it): the alias check refines ~36 rivals per scan.
    const bool last = it == o.iterations;
    for (std::size_t i0 = 0; i0 < n; i0 += kDistanceBatch) {
      const std::size_t m = n - i0 < kDistanceBatch ? n - i0 : kDistanceBatch;
      sample_distance_batch(map, points + i0, m, t.x, t.y, c, s, clip, &batch);
      for (std::size_t j = 0; j < m; ++j) {
        if (!batch.use[j]) continue;
        const float d = batch.d[j];
        ++inl;
        sq += static_cast<double>(d) * d;
        // On the distance field: residual d, normal ∇d.
        if (!last) sys.add_jacobian(batch.gx[j], batch.gy[j], batch.jt[j], d, wd);
      }
    }
    if (it == o.iterations || inl < 3) break;
    // Prior N(initial, diag(σ_xy², σ_xy², σ_θ²)) and a Levenberg damping of 1e-6 of the scale.
    const double pxy = 1.0 / (static_cast<double>(o.prior_sigma_xy_m) * o.prior_sigma_xy_m);
    const double pth = 1.0 / (static_cast<double>(o.prior_sigma_theta_rad) * o.prior_sigma_theta_rad);
    const Eigen::Vector3d offset(t.x - initial.x, t.y - initial.y, wrap_angle(t.theta - initial.theta));
    Eigen::Vector3d dx;
    if (!sys.solve(&dx, pxy, pth, offset, 1e-6)) break;
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
