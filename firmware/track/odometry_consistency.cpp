#include "firmware/track/odometry_consistency.h"

#include <Eigen/LU>
#include <cmath>

namespace fw {
namespace track {

void OdometryConsistency::advance(const Se2f& delta, const Eigen::Matrix3f& q) {
  for (std::size_t i = 0; i < count_; ++i) {
    Kept& k = kept_[i];
    // u ⊕ Δ with Q ← F Q Fᵀ + G q Gᵀ (Eq. 3.4 applied to the odometry alone).
    const Eigen::Matrix3f f = k.motion.jacobian_compose_first(delta);
    const Eigen::Matrix3f g = k.motion.jacobian_compose_second();
    k.motion = k.motion.compose(delta);
    k.motion_cov = f * k.motion_cov * f.transpose() + g * q * g.transpose();
    k.path_m += std::hypot(delta.x, delta.y);
    k.turn_rad += std::fabs(delta.theta);
  }
}

void OdometryConsistency::widen(float exy2, float etheta2) {
  for (std::size_t i = 0; i < count_; ++i) {
    kept_[i].motion_cov(0, 0) += exy2;  // isotropic in x, y: the same in every frame
    kept_[i].motion_cov(1, 1) += exy2;
    kept_[i].motion_cov(2, 2) += etheta2;
  }
}

void OdometryConsistency::push(const Se2f& pose, const Eigen::Matrix3f& cov, float bias_xy_m, float bias_theta_rad) {
  if (window_ == 0) return;
  Kept& k = kept_[head_];
  k.pose = pose;
  k.cov = cov;
  k.bias_xy2 = bias_xy_m * bias_xy_m;
  k.bias_theta2 = bias_theta_rad * bias_theta_rad;
  k.motion = Se2f();
  k.motion_cov.setZero();
  k.path_m = 0.0f;
  k.turn_rad = 0.0f;
  head_ = (head_ + 1) % window_;
  if (count_ < window_) ++count_;
}

float OdometryConsistency::max_chi2(const Se2f& pose, const Eigen::Matrix3f& cov, float bias_xy_m,
                                    float bias_theta_rad) const {
  float worst = 0.0f;
  for (std::size_t i = 0; i < count_; ++i) {
    const Kept& k = kept_[i];
    const Se2f expected = k.pose.compose(k.motion);
    const Eigen::Matrix3f j1 = k.pose.jacobian_compose_first(k.motion);
    const Eigen::Matrix3f j2 = k.pose.jacobian_compose_second();
    Eigen::Matrix3d c = (j1 * k.cov * j1.transpose() + j2 * k.motion_cov * j2.transpose() + cov).cast<double>();
    // The wheels' systematic error over this motion (header).
    const double sys_th = static_cast<double>(scale_error_) * k.turn_rad;
    const double sys_xy = static_cast<double>(scale_error_) * k.path_m * (1.0 + k.turn_rad);
    const double bxy = static_cast<double>(k.bias_xy2) + static_cast<double>(bias_xy_m) * bias_xy_m + sys_xy * sys_xy;
    const double bth = static_cast<double>(k.bias_theta2) + static_cast<double>(bias_theta_rad) * bias_theta_rad +
                       sys_th * sys_th;
    c(0, 0) += bxy;
    c(1, 1) += bxy;
    c(2, 2) += bth;
    const Eigen::Vector3d d(static_cast<double>(pose.x) - expected.x, static_cast<double>(pose.y) - expected.y,
                            static_cast<double>(wrap_angle(pose.theta - expected.theta)));
    bool invertible = false;
    Eigen::Matrix3d ci = Eigen::Matrix3d::Zero();  // left unset when not invertible
    c.computeInverseWithCheck(ci, invertible);
    if (!invertible) continue;  // no noise at all on either end: nothing to test against
    const double chi2 = d.dot(ci * d);
    if (std::isfinite(chi2) && chi2 > worst) worst = static_cast<float>(chi2);
  }
  return worst;
}

}  // namespace track
}  // namespace fw
