#include "firmware/rbsm/increment_fusion.h"

#include <Eigen/LU>
#include <cmath>

namespace fw {

namespace {
bool finite(const Se2d& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta); }
}  // namespace

Status IncrementFusionOptions::validate() const {
  if (!(relative_sigma_m > 0 && relative_sigma_per_m >= 0 && relative_sigma_rad > 0 && relative_sigma_per_rad >= 0)) {
    return Status::error(Errc::kInvalidArgument,
                         "increment fusion: relative sigmas must be > 0 (floors) and >= 0 (per metre / radian)");
  }
  if (!(absolute_sigma_m > 0 && absolute_sigma_rad > 0)) {
    return Status::error(Errc::kInvalidArgument, "increment fusion: absolute sigmas must be > 0");
  }
  if (!(gate_chi2 > 0)) return Status::error(Errc::kInvalidArgument, "increment fusion: gate_chi2 must be > 0");
  if (!(unknown_increment_scale >= 1)) {
    return Status::error(Errc::kInvalidArgument, "increment fusion: unknown_increment_scale must be >= 1");
  }
  return Status::ok();
}

Status IncrementFusion::init(const IncrementFusionOptions& options) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  r_.setZero();
  r_(0, 0) = r_(1, 1) = options.absolute_sigma_m * options.absolute_sigma_m;
  r_(2, 2) = options.absolute_sigma_rad * options.absolute_sigma_rad;
  initialized_ = true;
  reset();
  return Status::ok();
}

Eigen::Matrix<double, 3, 3> IncrementFusion::increment_cov(const Se2d& u, double scale) const {
  const double st = options_.relative_sigma_m + options_.relative_sigma_per_m * std::hypot(u.x, u.y);
  const double sr = options_.relative_sigma_rad + options_.relative_sigma_per_rad * std::fabs(u.theta);
  Eigen::Matrix<double, 3, 3> q = Eigen::Matrix<double, 3, 3>::Zero();
  q(0, 0) = q(1, 1) = scale * st * st;
  q(2, 2) = scale * sr * sr;
  return q;
}

Status IncrementFusion::update(const Se2d& absolute, bool has_increment, const Se2d& increment) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "increment fusion: init() first");
  if (!finite(absolute) || (has_increment && !finite(increment))) {
    return Status::error(Errc::kInvalidArgument, "increment fusion: non-finite pose or increment");
  }
  if (!started_) {
    step_.pose = step_.predicted = absolute;
    step_.cov = step_.predicted_cov = r_;
    step_.transition.setIdentity();
    last_absolute_ = absolute;
    started_ = true;
    return Status::ok();
  }
  // Predict (Eq. 3.4): without an increment, RBSM's own motion with a wide Q.
  const Se2d u = has_increment ? increment : last_absolute_.between(absolute);
  const Se2d& pose = step_.pose;
  const Eigen::Matrix<double, 3, 3> transition = pose.jacobian_compose_first(u);
  const PoseWithCovariance<double> predicted =
      propagate(pose.compose(u), transition, step_.cov, pose.jacobian_compose_second(),
                increment_cov(u, has_increment ? 1.0 : options_.unknown_increment_scale));
  last_absolute_ = absolute;
  // Update with RBSM's pose.
  Eigen::Matrix<double, 3, 1> y(absolute.x - predicted.pose.x, absolute.y - predicted.pose.y,
                                wrap_angle(absolute.theta - predicted.pose.theta));
  // Robust update: beyond the χ² gate RBSM's pose is not trusted at face value (its heavy tail:
  // the particle set diffusing along a corridor) nor discarded (the increments may be the ones that
  // slid): R is inflated until the normalised innovation sits on the gate, so one scan pulls by a
  // bounded amount and a lasting disagreement is still resolved towards the drift-free pose.
  Eigen::Matrix<double, 3, 3> r = r_;
  Eigen::Matrix<double, 3, 3> s_inv = (predicted.cov + r).inverse();
  const double m2 = y.dot(s_inv * y);
  if (!(m2 <= options_.gate_chi2)) {
    r *= m2 / options_.gate_chi2;
    s_inv = (predicted.cov + r).inverse();
    ++gated_;
  }
  const Eigen::Matrix<double, 3, 3> k = predicted.cov * s_inv;
  const Eigen::Matrix<double, 3, 1> dx = k * y;
  step_.transition = transition;
  step_.predicted = predicted.pose;
  step_.predicted_cov = predicted.cov;
  step_.pose = Se2d(predicted.pose.x + dx(0), predicted.pose.y + dx(1), wrap_angle(predicted.pose.theta + dx(2)));
  const Eigen::Matrix<double, 3, 3> cov = (Eigen::Matrix<double, 3, 3>::Identity() - k) * predicted.cov;
  step_.cov = 0.5 * (cov + cov.transpose());
  return Status::ok();
}

}  // namespace fw
