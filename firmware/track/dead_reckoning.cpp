#include "firmware/track/dead_reckoning.h"

#include <cmath>

#include "firmware/track/scan_alignment.h"

namespace fw {
namespace track {

Eigen::Matrix3f odometry_increment_noise(const Se2f& delta, const TrackOptions& o) {
  const float ds = std::hypot(delta.x, delta.y), da = std::fabs(delta.theta);
  const float at = o.odom_trans_per_m * ds + o.odom_trans_per_rad * da;
  const float ar = o.odom_rot_per_rad * da + o.odom_rot_per_m * ds;
  const float ft = o.odom_trans_per_step_m, fr = o.odom_rot_per_step_rad;
  // The per-step part in quadrature (track_options.h); without one, the AMCL model exactly.
  const float st = ft > 0.0f ? std::sqrt(at * at + ft * ft) : at;
  const float sr = fr > 0.0f ? std::sqrt(ar * ar + fr * fr) : ar;
  Eigen::Matrix3f q = Eigen::Matrix3f::Zero();
  q(0, 0) = q(1, 1) = st * st;
  q(2, 2) = sr * sr;
  return q;
}

void DeadReckoning::clear() {
  active_ = binding_ = trusted_ = false;
  pose_ = wheel_ = Se2f();
  cov_.setZero();
  contradicting_ = 0;
  outside_ = reentered_ = false;
}

void DeadReckoning::start(const Se2f& pose, const Eigen::Matrix3f& cov, const Se2f& wheel, bool binding,
                          bool trusted) {
  active_ = true;
  binding_ = binding;
  trusted_ = trusted;
  pose_ = pose;
  wheel_ = wheel;
  cov_ = cov;
  contradicting_ = 0;
  outside_ = reentered_ = false;
}

void DeadReckoning::advance(const Se2f& wheel, const TrackOptions& o) {
  if (!active_) return;
  const Se2f delta = wheel_.between(wheel);
  wheel_ = wheel;
  const Eigen::Matrix3f q = odometry_increment_noise(delta, o);
  const Eigen::Matrix3f f = pose_.jacobian_compose_first(delta);
  const Eigen::Matrix3f g = pose_.jacobian_compose_second();
  pose_ = pose_.compose(delta);
  cov_ = f * cov_ * f.transpose() + g * q * g.transpose();
  cov_ = 0.5f * (cov_ + cov_.transpose()).eval();
}

DeadReckoningVerdict DeadReckoning::judge(const GlobalMap& map, const Point2f* pts, std::size_t n,
                                          const TrackOptions& o) {
  reentered_ = false;
  if (!active_) return DeadReckoningVerdict::kSaysNothing;
  if (n == 0) {  // says nothing, and so breaks a run of contradictions (as the tracker counts them)
    contradicting_ = 0;
    return DeadReckoningVerdict::kSaysNothing;
  }
  ScanAlignOptions at_pose = o.align;
  at_pose.iterations = 0;  // the statistics at the pose itself, no fit
  const ScanAlignment here = align_scan(map, pts, n, pose_, at_pose);
  const bool outside = here.unknown_fraction() > o.outside_map_fraction;
  if (!binding_) return outside ? DeadReckoningVerdict::kOutside : DeadReckoningVerdict::kSaysNothing;
  // The part of the scan on the map, fitted from the carried pose (the wheels' drift is no
  // contradiction), by the tracker's fit tests (pose_tracker.cpp, judge_scan). Off the map too: a
  // robot where the wheels say sees the mapped walls where the map has them, so a scan mostly off
  // the map whose end-points on it contradict the carried pose refutes the wheels as well.
  const ScanAlignment a = align_scan(map, pts, n, pose_, o.align);
  const bool informative = a.inliers + a.contradicting >= o.min_points;
  const bool contradicts =
      informative && (a.inlier_fraction() < o.min_inlier_fraction ||
                      (!outside && static_cast<float>(a.inliers) < o.min_explained_fraction * static_cast<float>(a.points)));
  contradicting_ = contradicts ? contradicting_ + 1 : 0;
  if (contradicting_ >= o.max_faulty_steps) binding_ = trusted_ = false;  // the scans refute the wheels
  if (outside) {
    outside_ = true;
    return DeadReckoningVerdict::kOutside;
  }
  if (contradicts) return DeadReckoningVerdict::kContradicts;
  if (!informative) return DeadReckoningVerdict::kSaysNothing;
  reentered_ = outside_;
  outside_ = false;
  return DeadReckoningVerdict::kFits;
}

bool DeadReckoning::admits(const Se2f& fix, const ProtectionFactors& k, const TrackOptions& o) const {
  if (!active_ || !binding_) return true;
  const ProtectionLevel pl = bound(k);
  const float d = std::hypot(fix.x - pose_.x, fix.y - pose_.y);
  const float dth = std::fabs(wrap_angle(fix.theta - pose_.theta));
  return d <= pl.xy_m + o.alert_limit_m && dth <= pl.theta_rad + o.alert_limit_rad;
}

}  // namespace track
}  // namespace fw
