#include "firmware/mml/handoff_localizer.h"

#include <cmath>

namespace fw {
namespace mml {

Status HandoffOptions::validate() const {
  if (!std::isfinite(collapse_log_likelihood) || collapse_log_likelihood > 0.0f) {
    return Status::error(Errc::kInvalidArgument, "HandoffOptions.collapse_log_likelihood = %g must be finite and ≤ 0",
                         collapse_log_likelihood);
  }
  if (collapse_steps < 1 || collapse_steps > 10000) {
    return Status::error(Errc::kInvalidArgument, "HandoffOptions.collapse_steps = %u out of range [1, 10000]",
                         collapse_steps);
  }
  if (!std::isfinite(init_cov_scale) || init_cov_scale <= 0.0f) {
    return Status::error(Errc::kInvalidArgument, "HandoffOptions.init_cov_scale = %g must be > 0", init_cov_scale);
  }
  if (!std::isfinite(init_sigma_xy_floor_m) || init_sigma_xy_floor_m < 0.0f) {
    return Status::error(Errc::kInvalidArgument, "HandoffOptions.init_sigma_xy_floor_m = %g must be ≥ 0",
                         init_sigma_xy_floor_m);
  }
  if (!std::isfinite(init_sigma_theta_floor_rad) || init_sigma_theta_floor_rad < 0.0f) {
    return Status::error(Errc::kInvalidArgument, "HandoffOptions.init_sigma_theta_floor_rad = %g must be ≥ 0",
                         init_sigma_theta_floor_rad);
  }
  return Status::ok();
}

Status HandoffLocalizer::init(const HandoffOptions& options, MmlLocalizer* mml, mcl::MclLocalizer* mcl) {
  FW_RETURN_IF_ERROR(options.validate());
  if (mml == nullptr || mcl == nullptr) return Status::error(Errc::kInvalidArgument, "HandoffLocalizer: null localizer");
  options_ = options;
  mml_ = mml;
  mcl_ = mcl;
  reset();
  return Status::ok();
}

void HandoffLocalizer::reset() {
  tracking_ = false;
  low_steps_ = 0;
  if (mml_) mml_->reset();
  if (mcl_) mcl_->reset();
}

Status HandoffLocalizer::step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  const hal::CompleteReasonOnExit reason_on_exit{out};  // every estimate says why it is not `localized`
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "HandoffLocalizer: step() before init()");
  if (!tracking_) {
    FW_RETURN_IF_ERROR(mml_->step(scan, odom, out));
    out->mode = hal::LocalizationMode::kGlobal;
    if (out->status == hal::LocalizationStatus::kLocalized) {
      Eigen::Matrix3f cov;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) cov(r, c) = out->cov[r * 3 + c] * options_.init_cov_scale;
      const float fxy = options_.init_sigma_xy_floor_m * options_.init_sigma_xy_floor_m;
      const float ft = options_.init_sigma_theta_floor_rad * options_.init_sigma_theta_floor_rad;
      if (cov(0, 0) < fxy) cov(0, 0) = fxy;
      if (cov(1, 1) < fxy) cov(1, 1) = fxy;
      if (cov(2, 2) < ft) cov(2, 2) = ft;
      FW_RETURN_IF_ERROR(mcl_->start_tracking(Se2f(out->x, out->y, out->theta), cov, odom));
      tracking_ = true;
      low_steps_ = 0;
      ++handoffs_;
    }
    return Status::ok();
  }
  FW_RETURN_IF_ERROR(mcl_->step(scan, odom, out));
  out->mode = hal::LocalizationMode::kTracking;
  out->status = hal::LocalizationStatus::kLocalized;
  if (mcl_->last().mean_beam_log_likelihood < options_.collapse_log_likelihood) {
    ++low_steps_;
  } else {
    low_steps_ = 0;
  }
  if (low_steps_ >= options_.collapse_steps) {
    // Tracking lost or kidnapped: back to global localization with a fresh local map.
    tracking_ = false;
    low_steps_ = 0;
    ++fallbacks_;
    mml_->reset();
    mcl_->reset();
    out->status = hal::LocalizationStatus::kSearching;
    out->mode = hal::LocalizationMode::kGlobal;
  }
  return Status::ok();
}

}  // namespace mml
}  // namespace fw
