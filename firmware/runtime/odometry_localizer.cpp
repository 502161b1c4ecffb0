#include "firmware/runtime/odometry_localizer.h"

#include <cmath>

#include "firmware/runtime/odometry_interpolation.h"

namespace fw {

Status OdometryLocalizerOptions::validate() const {
  const float v[] = {initial_pose.x, initial_pose.y, initial_pose.theta, sigma_trans_per_m, sigma_rot_per_rad,
                     sigma_rot_per_m};
  for (float f : v) {
    if (!std::isfinite(f)) return Status::error(Errc::kInvalidArgument, "OdometryLocalizerOptions: non-finite value");
  }
  if (sigma_trans_per_m < 0 || sigma_rot_per_rad < 0 || sigma_rot_per_m < 0) {
    return Status::error(Errc::kInvalidArgument, "OdometryLocalizerOptions: negative noise sigma");
  }
  return Status::ok();
}

void OdometryLocalizer::reset() {
  has_first_ = false;
  pose_ = PoseWithCovariance<float>();
}

Status OdometryLocalizer::step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  const hal::CompleteReasonOnExit reason_on_exit{out};  // every estimate says why it is not `localized`
  if (!odometry_is_finite(odom)) {
    return Status::error(Errc::kInvalidArgument, "odom localizer: odometry at t=%llu ns is not finite",
                         static_cast<unsigned long long>(odom.timestamp_ns));
  }
  const Se2f cur(odom.x, odom.y, odom.theta);
  if (!has_first_) {
    has_first_ = true;
    first_odom_ = cur;
    last_odom_ = cur;
    pose_.pose = options_.initial_pose;
    pose_.cov.setZero();
  } else {
    // Eq. 3.4 with the step's own motion as the noise scale.
    PoseWithCovariance<float> u;
    u.pose = last_odom_.between(cur);
    const float d = std::sqrt(u.pose.x * u.pose.x + u.pose.y * u.pose.y);
    const float st = options_.sigma_trans_per_m * d;
    const float sr = options_.sigma_rot_per_rad * std::fabs(u.pose.theta) + options_.sigma_rot_per_m * d;
    u.cov.setZero();
    u.cov(0, 0) = st * st;
    u.cov(1, 1) = st * st;
    u.cov(2, 2) = sr * sr;
    pose_ = compose_with_covariance(pose_, u);
    // Re-anchor on the absolute odometry (no float drift from chaining deltas).
    pose_.pose = options_.initial_pose.compose(first_odom_.between(cur));
    last_odom_ = cur;
  }
  out->timestamp_ns = scan.timestamp_ns;
  out->scan_id = scan.scan_id;
  out->x = pose_.pose.x;
  out->y = pose_.pose.y;
  out->theta = pose_.pose.theta;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out->cov[r * 3 + c] = pose_.cov(r, c);
  }
  out->status = hal::LocalizationStatus::kSearching;
  out->mode = hal::LocalizationMode::kGlobal;
  out->hypothesis_count = 0;
  out->cluster_count = 0;
  out->rating = 0.0f;
  return Status::ok();
}

}  // namespace fw
