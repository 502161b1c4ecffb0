#include "firmware/track/protection_level.h"

#include <cmath>


namespace fw {
namespace track {

float radial_factor(float risk) { return std::sqrt(-2.0f * std::log(risk)); }

float two_sided_factor(float risk) {
  // P(|z| > k) = erfc(k / √2), decreasing in k.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > risk) lo = mid; else hi = mid;
  }
  return static_cast<float>(0.5 * (lo + hi));
}

ProtectionLevel protection_level(const Eigen::Matrix3f& cov, const ProtectionFactors& k, float bias_xy_m,
                                 float bias_theta_rad) {
  if (!cov.allFinite()) return {INFINITY, INFINITY};  // no bound can be given: never a small one
  // λ_max of the symmetric 2×2 position block (closed form, no Eigen solver: it mallocs).
  const float a = cov(0, 0), b = 0.5f * (cov(0, 1) + cov(1, 0)), d = cov(1, 1);
  const float mean = 0.5f * (a + d);
  const float rad = std::sqrt(0.25f * (a - d) * (a - d) + b * b);
  const float lmax = std::fmax(mean + rad, 0.0f);
  ProtectionLevel pl;
  pl.xy_m = k.k_xy * std::sqrt(lmax) + bias_xy_m;
  pl.theta_rad = k.k_theta * std::sqrt(std::fmax(cov(2, 2), 0.0f)) + bias_theta_rad;
  if (!std::isfinite(pl.xy_m)) pl.xy_m = INFINITY;
  if (!std::isfinite(pl.theta_rad)) pl.theta_rad = INFINITY;
  return pl;
}

}  // namespace track
}  // namespace fw
