#include "firmware/rbsm/scan_matching_odometry.h"

#include <cmath>

namespace fw {

Status ScanMatchingOdometryOptions::validate() const {
  if (!(min_translation_m >= 0.0f) || !(min_rotation_rad >= 0.0f)) {
    return Status::error(Errc::kInvalidArgument, "scan-matching odometry: update thresholds must be >= 0");
  }
  if (!(scan.max_range >= 0.0f)) return Status::error(Errc::kInvalidArgument, "scan-matching odometry: max_range < 0");
  return Status::ok();
}

Status ScanMatchingOdometry::init(const ScanMatchingOdometryOptions& options, ScanMatcher* matcher, LocalMap* local_map) {
  FW_RETURN_IF_ERROR(options.validate());
  if (matcher == nullptr) return Status::error(Errc::kInvalidArgument, "scan-matching odometry: null matcher");
  options_ = options;
  matcher_ = matcher;
  local_map_ = local_map;
  reset();
  return Status::ok();
}

void ScanMatchingOdometry::reset(const Se2f& start) {
  if (matcher_) matcher_->reset();
  if (local_map_) local_map_->reset();
  started_ = false;
  start_ = start;
  pose_ = start;
  last_odom_ = odom_at_match_ = Se2f();
  correction_ = Se2f();
  matches_ = failures_ = 0;
}

Status ScanMatchingOdometry::step(const hal::LaserScan& scan, const hal::Odometry& odom, Se2f* pose,
                                  ScanMatchResult* result) {
  if (matcher_ == nullptr) return Status::error(Errc::kNotInitialized, "scan-matching odometry: step() before init()");
  if (!std::isfinite(odom.x) || !std::isfinite(odom.y) || !std::isfinite(odom.theta)) {
    return Status::error(Errc::kInvalidArgument, "scan %u: non-finite odometry (%g, %g, %g)", scan.scan_id,
                         static_cast<double>(odom.x), static_cast<double>(odom.y), static_cast<double>(odom.theta));
  }
  ScanPointsResult pr;
  FW_RETURN_IF_ERROR(scan_to_points(scan, options_.scan, points_, hal::LaserScan::kMaxBeams, &pr));
  const Se2f o(odom.x, odom.y, odom.theta);
  ScanMatchResult local;
  ScanMatchResult* res = result ? result : &local;
  *res = ScanMatchResult{};
  if (!started_) {
    last_odom_ = odom_at_match_ = o;
    pose_ = start_;
    correction_ = Se2f();
    started_ = true;
  } else {
    pose_ = pose_.compose(last_odom_.between(o));  // prediction: last ⊕ u_t
    last_odom_ = o;
  }
  res->pose = pose_.compose(correction_);
  const Se2f moved = odom_at_match_.between(o);
  const bool first = matches_ == 0;
  if (!first && std::hypot(moved.x, moved.y) < options_.min_translation_m &&
      std::fabs(moved.theta) < options_.min_rotation_rad) {
    if (pose) *pose = pose_.compose(correction_);
    return Status::ok();
  }
  const Status st = matcher_->match(points_, pr.count, pose_, res);
  if (!st.is_ok()) {
    // Keep the odometry prediction; report which scan failed and why.
    ++failures_;
    if (pose) *pose = pose_.compose(correction_);
    return Status::error(st.code(), "scan %u: %s", scan.scan_id, st.message());
  }
  const bool keep_chain = res->refined && !options_.chain_on_refined;
  pose_ = keep_chain ? res->unrefined_pose : res->pose;
  correction_ = keep_chain ? res->unrefined_pose.between(res->pose) : Se2f();
  odom_at_match_ = o;
  ++matches_;
  std::size_t n_new = 0;
  FW_RETURN_IF_ERROR(matcher_->integrate(points_, pr.count, pose_, new_cells_, hal::LaserScan::kMaxBeams, &n_new));
  if (local_map_) {
    FW_RETURN_IF_ERROR(local_map_->update_pose(pose_));
    FW_RETURN_IF_ERROR(local_map_->add_points(new_cells_, n_new));
  }
  if (pose) *pose = res->pose;
  return Status::ok();
}

}  // namespace fw
