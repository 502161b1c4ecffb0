#include "firmware/track/scan_alignment.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "firmware/map/distance_batch.h"
#include "firmware/map/distance_sample.h"
#include "firmware/scan/point_to_line.h"

namespace fw {
namespace track {

namespace {

enum class PointClass : std::uint8_t { kInlier, kContradicting, kUnknown };

// Where the map has no say (unknown cell, off the grid) a far end-point is not evidence against
// the pose; on a known free cell it is.
PointClass classify(const GlobalMap& map, float qx, float qy, bool sampled, float d, float outlier) {
  if (sampled && d <= outlier) return PointClass::kInlier;
  std::int32_t cx = 0, cy = 0;
  if (!map.geometry.world_to_cell(qx, qy, &cx, &cy)) return PointClass::kUnknown;
  return map.cell(cx, cy) == kCellUnknown ? PointClass::kUnknown : PointClass::kContradicting;
}

}  // namespace

ScanAlignment align_scan(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& seed,
                         const ScanAlignOptions& o) {
  ScanAlignment r;
  r.pose = seed;
  r.points = static_cast<std::uint32_t>(n);
  if (!map.valid() || n == 0) return r;
  // Levenberg regularisation towards the seed: tiny against what a scan constrains, it keeps the
  // directions a scan does not see (along a corridor) at the seed instead of letting noise move them.
  const double reg_xy = 1.0 / (1.0 * 1.0), reg_th = 1.0 / (0.5 * 0.5);
  Se2f t = seed;
  const DistanceSampler<float> sample(map);
  DistanceBatch batch;  // the Gauss–Newton passes sample kDistanceBatch end-points at a time
  PointToLineSystem sys;  // shared with RBSM's refinement and PL-ICP (firmware/scan/point_to_line.h)
  for (std::uint32_t it = 0; it < o.iterations; ++it) {
    const float outlier = (it < o.iterations / 2) ? 2.0f * o.outlier_m : o.outlier_m;
    const float c = std::cos(t.theta), s = std::sin(t.theta);
    sys.clear();
    for (std::size_t i0 = 0; i0 < n; i0 += kDistanceBatch) {
      const std::size_t m = n - i0 < kDistanceBatch ? n - i0 : kDistanceBatch;
      sample_distance_batch(map, points + i0, m, t.x, t.y, c, s, outlier, &batch);
      for (std::size_t j = 0; j < m; ++j) {
        if (!batch.use[j]) continue;
        // On the distance field the residual is d itself and the line normal its gradient.
        const float d = batch.d[j];
        const double w = d <= o.huber_m ? 1.0 : static_cast<double>(o.huber_m) / d;  // Huber IRLS weight
        sys.add_jacobian(batch.gx[j], batch.gy[j], batch.jt[j], d, w);
      }
    }
    if (sys.used < 3) break;
    Eigen::Vector3d dx;
    const Eigen::Vector3d offset(t.x - seed.x, t.y - seed.y, wrap_angle(t.theta - seed.theta));
    if (!sys.solve(&dx, reg_xy, reg_th, offset)) break;
    t = Se2f(t.x + static_cast<float>(dx(0)), t.y + static_cast<float>(dx(1)),
             wrap_angle(t.theta + static_cast<float>(dx(2))));
    if (it >= o.iterations / 2 && dx.head<2>().norm() < 1e-4 && std::fabs(dx(2)) < 1e-5) break;
  }
  r.pose = t;

  // Statistics and information at the optimum, with the final outlier threshold.
  const float c = std::cos(t.theta), s = std::sin(t.theta);
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  double sq = 0.0, lever = 0.0;
  const float cell = o.correlation_length_m;
  bool have_prev_cell = false;
  std::int32_t prev_cx = 0, prev_cy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float px = points[i].x(), py = points[i].y();
    const float qx = t.x + c * px - s * py, qy = t.y + s * px + c * py;
    float d = 0.0f, gx = 0.0f, gy = 0.0f;
    const bool ok = sample(qx, qy, &d, &gx, &gy);
    const PointClass pc = classify(map, qx, qy, ok, d, o.outlier_m);
    if (pc == PointClass::kUnknown) { ++r.unknown; continue; }
    if (pc == PointClass::kContradicting) { ++r.contradicting; continue; }
    ++r.inliers;
    sq += static_cast<double>(d) * d;
    lever += static_cast<double>(px) * px + static_cast<double>(py) * py;
    const double w = d <= o.huber_m ? 1.0 : static_cast<double>(o.huber_m) / d;
    const Eigen::Vector3d j(gx, gy, gx * (-s * px - c * py) + gy * (c * px - s * py));
    h += w * (j * j.transpose());
    // Beams arrive in angular order: a new correlation cell starts when the end-point leaves the
    // previous one (a wall seen again after a gap counts again, which is conservative enough).
    const std::int32_t cx = static_cast<std::int32_t>(std::floor(qx / cell));
    const std::int32_t cy = static_cast<std::int32_t>(std::floor(qy / cell));
    if (!have_prev_cell || cx != prev_cx || cy != prev_cy) ++r.independent;
    have_prev_cell = true;
    prev_cx = cx;
    prev_cy = cy;
  }
  if (r.inliers > 0) {
    r.rms_m = static_cast<float>(std::sqrt(sq / r.inliers));
    r.lever_m = static_cast<float>(std::sqrt(lever / r.inliers));
    r.sigma_m = r.rms_m > o.min_sigma_m ? r.rms_m : o.min_sigma_m;
    // Σ w JᵀJ / σ² counts every inlier as independent; only `independent` of them are.
    const double scale = static_cast<double>(r.independent) / static_cast<double>(r.inliers) /
                         (static_cast<double>(r.sigma_m) * r.sigma_m);
    r.information = (h * scale).cast<float>();
  }
  return r;
}

}  // namespace track
}  // namespace fw
