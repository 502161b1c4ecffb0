#include "firmware/baselines/mcl/mcl_localizer.h"

#include <cmath>

namespace fw {
namespace mcl {

Status MclLocalizer::init(const MclOptions& options, const MapView& map, WorkerPool* pool) {
  FW_RETURN_IF_ERROR(mcl_.init(options, map, pool));
  reset();
  return Status::ok();
}

void MclLocalizer::reset() {
  mcl_.reset();
  have_odom_ = false;
  tracking_ = false;
  need_uniform_ = true;
  force_update_ = true;
  last_updated_ = false;
  gated_steps_ = 0;
  prev_odom_ = Se2f();
  last_ = MclStepResult();
}

Status MclLocalizer::start_tracking(const Se2f& pose, const Eigen::Matrix3f& cov, const hal::Odometry& odom) {
  FW_RETURN_IF_ERROR(mcl_.init_gaussian(pose, cov));
  need_uniform_ = false;
  tracking_ = true;
  force_update_ = true;
  prev_odom_ = Se2f(odom.x, odom.y, odom.theta);
  have_odom_ = true;
  return Status::ok();
}

void MclLocalizer::publish(const hal::LaserScan& scan, const Se2f& pose, hal::PoseEstimate* out) const {
  *out = hal::PoseEstimate();
  out->timestamp_ns = scan.timestamp_ns;
  out->scan_id = scan.scan_id;
  out->x = pose.x;
  out->y = pose.y;
  out->theta = pose.theta;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out->cov[r * 3 + c] = last_.cov(r, c);
  out->mode = tracking_ ? hal::LocalizationMode::kTracking : hal::LocalizationMode::kGlobal;
  out->status = (last_.localized || tracking_) ? hal::LocalizationStatus::kLocalized : hal::LocalizationStatus::kSearching;
}

Status MclLocalizer::step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  const hal::CompleteReasonOnExit reason_on_exit{out};  // every estimate says why it is not `localized`
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "MclLocalizer: null output");
  if (!std::isfinite(odom.x) || !std::isfinite(odom.y) || !std::isfinite(odom.theta)) {
    return Status::error(Errc::kInvalidArgument, "MclLocalizer: non-finite odometry at scan %u", scan.scan_id);
  }
  if (need_uniform_) {
    FW_RETURN_IF_ERROR(mcl_.init_uniform());
    need_uniform_ = false;
    have_odom_ = false;
    force_update_ = true;
  }
  const Se2f cur(odom.x, odom.y, odom.theta);
  // Motion since the last filter update (gated scans accumulate into it, as AMCL's pf_odom_pose).
  const Se2f delta = have_odom_ ? prev_odom_.between(cur) : Se2f();
  const MclOptions& o = mcl_.options();
  if (!force_update_ && have_odom_ && std::hypot(delta.x, delta.y) < o.update_min_d &&
      std::fabs(delta.theta) < o.update_min_a) {
    // Gated: the filter keeps its particles; publish the last estimate moved by the odometry
    // (its covariance and status as they were).
    last_updated_ = false;
    ++gated_steps_;
    publish(scan, last_.pose.compose(delta), out);
    return Status::ok();
  }
  FW_RETURN_IF_ERROR(mcl_.step(scan, delta, have_odom_, &last_));
  prev_odom_ = cur;
  have_odom_ = true;
  force_update_ = false;
  last_updated_ = true;
  publish(scan, last_.pose, out);
  return Status::ok();
}

}  // namespace mcl
}  // namespace fw
