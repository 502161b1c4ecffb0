#include "firmware/antslam/field_fit.h"

#include <Eigen/LU>
#include <cmath>

namespace fw::antslam {

float field_quality(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& pose) {
  if (n == 0) return 0.0f;
  const float c = static_cast<float>(std::cos(pose.theta)), s = static_cast<float>(std::sin(pose.theta));
  const float tx = static_cast<float>(pose.x), ty = static_cast<float>(pose.y);
  std::uint64_t sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2f q(tx + c * scene[i](0) - s * scene[i](1), ty + s * scene[i](0) + c * scene[i](1));
    sum += field.contact(q);
  }
  return static_cast<float>(static_cast<double>(sum) / (255.0 * static_cast<double>(n)));
}

FieldFit fit_on_field(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& start,
                      std::uint32_t iterations, float cutoff_start, float cutoff_end) {
  FieldFit out;
  out.pose = start;
  if (!field.has_distance() || n < 3) {
    out.quality = field_quality(field, scene, n, start);
    return out;
  }
  Se2d x = start;
  for (std::uint32_t it = 0; it < iterations; ++it) {
    const float a = iterations > 1 ? static_cast<float>(it) / static_cast<float>(iterations - 1) : 1.0f;
    const float cutoff = cutoff_start + (cutoff_end - cutoff_start) * a;
    const double c = std::cos(x.theta), s = std::sin(x.theta);
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    std::uint32_t used = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double px = scene[i](0), py = scene[i](1);
      const Point2f q(static_cast<float>(x.x + c * px - s * py), static_cast<float>(x.y + s * px + c * py));
      float d = 0.0f;
      Point2f g;
      if (!field.distance_gradient(q, &d, &g) || !(d < cutoff)) continue;
      // r = d(R p + t); ∂r/∂(x, y, θ) = gᵀ [I, ∂R/∂θ p]
      const Eigen::Vector3d j(g(0), g(1), g(0) * (-s * px - c * py) + g(1) * (c * px - s * py));
      h += j * j.transpose();
      b += j * static_cast<double>(d);
      ++used;
    }
    out.used = used;
    if (used < 10) break;
    h.diagonal().array() += 1e-6;
    const Eigen::Vector3d delta = -h.inverse() * b;
    if (!delta.allFinite()) break;
    x = Se2d(x.x + delta(0), x.y + delta(1), wrap_angle(x.theta + delta(2)));
    if (delta.head<2>().norm() < 1e-4 && std::fabs(delta(2)) < 1e-5) break;
  }
  out.pose = x;
  out.quality = field_quality(field, scene, n, x);
  return out;
}

}  // namespace fw::antslam
