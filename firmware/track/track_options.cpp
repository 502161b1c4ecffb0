#include "firmware/track/track_options.h"

#include <cmath>
#include <cstdint>

namespace fw {
namespace track {

namespace {
Status check_range(const char* name, float v, float lo, float hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    return Status::error(Errc::kInvalidArgument, "TrackOptions.%s = %g out of range [%g, %g]", name,
                         static_cast<double>(v), static_cast<double>(lo), static_cast<double>(hi));
  }
  return Status::ok();
}
Status check_count(const char* name, std::uint32_t v, std::uint32_t lo, std::uint32_t hi) {
  if (v < lo || v > hi) {
    return Status::error(Errc::kInvalidArgument, "TrackOptions.%s = %u out of range [%u, %u]", name, v, lo, hi);
  }
  return Status::ok();
}
}  // namespace

Status ScanAlignOptions::validate() const {
  FW_RETURN_IF_ERROR(check_count("align.max_points", max_points, 10, 1081));
  FW_RETURN_IF_ERROR(check_count("align.iterations", iterations, 1, 100));
  FW_RETURN_IF_ERROR(check_range("align.max_range_m", max_range_m, 0.5f, 1000.0f));
  FW_RETURN_IF_ERROR(check_range("align.outlier_m", outlier_m, 0.01f, 5.0f));
  FW_RETURN_IF_ERROR(check_range("align.huber_m", huber_m, 0.001f, 5.0f));
  FW_RETURN_IF_ERROR(check_range("align.correlation_length_m", correlation_length_m, 0.001f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("align.min_sigma_m", min_sigma_m, 0.0001f, 1.0f));
  return Status::ok();
}

Status CorrelativeSearchOptions::validate() const {
  FW_RETURN_IF_ERROR(check_range("search.trigger_sigma_xy_m", trigger_sigma_xy_m, 0.0f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("search.trigger_sigma_theta_rad", trigger_sigma_theta_rad, 0.0f, 3.2f));
  FW_RETURN_IF_ERROR(check_range("search.window_sigmas", window_sigmas, 0.1f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("search.max_window_xy_m", max_window_xy_m, 0.0f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("search.max_window_theta_rad", max_window_theta_rad, 0.0f, 3.2f));
  FW_RETURN_IF_ERROR(check_range("search.linear_step_m", linear_step_m, 0.005f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("search.angular_step_rad", angular_step_rad, 0.001f, 0.5f));
  FW_RETURN_IF_ERROR(check_range("search.clip_m", clip_m, 0.01f, 2.0f));
  FW_RETURN_IF_ERROR(check_range("search.min_score_gain", min_score_gain, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_count("search.max_points", max_points, 10, 1081));
  FW_RETURN_IF_ERROR(check_count("search.max_candidates", max_candidates, 1, 1000000));
  return Status::ok();
}

Status TrackOptions::validate() const {
  FW_RETURN_IF_ERROR(align.validate());
  FW_RETURN_IF_ERROR(search.validate());
  FW_RETURN_IF_ERROR(check_range("odom_trans_per_m", odom_trans_per_m, 0.0f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("odom_trans_per_rad", odom_trans_per_rad, 0.0f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("odom_rot_per_rad", odom_rot_per_rad, 0.0f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("odom_rot_per_m", odom_rot_per_m, 0.0f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("odom_trans_per_step_m", odom_trans_per_step_m, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("odom_rot_per_step_rad", odom_rot_per_step_rad, 0.0f, 0.5f));
  FW_RETURN_IF_ERROR(check_range("odom_slip_per_100m", odom_slip_per_100m, 0.0f, 1000.0f));
  FW_RETURN_IF_ERROR(check_range("odom_slip_max_m", odom_slip_max_m, 0.0f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("odom_scale_error", odom_scale_error, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("max_odom_step_m", max_odom_step_m, 0.01f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("max_odom_step_rad", max_odom_step_rad, 0.01f, 6.3f));
  FW_RETURN_IF_ERROR(check_range("update_min_d_m", update_min_d_m, 0.0f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("update_min_a_rad", update_min_a_rad, 0.0f, 3.2f));
  FW_RETURN_IF_ERROR(check_count("min_points", min_points, 3, 1081));
  FW_RETURN_IF_ERROR(check_range("min_inlier_fraction", min_inlier_fraction, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("min_explained_fraction", min_explained_fraction, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("fit_drop_z", fit_drop_z, 0.0f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("innovation_chi2", innovation_chi2, 0.1f, 1e6f));
  FW_RETURN_IF_ERROR(check_range("outside_map_fraction", outside_map_fraction, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_count("max_faulty_steps", max_faulty_steps, 1, 10000));
  FW_RETURN_IF_ERROR(check_count("cross_check_steps", cross_check_steps, 0, 1000000));
  FW_RETURN_IF_ERROR(check_count("odometry_window", odometry_window, 0, 32));
  FW_RETURN_IF_ERROR(check_count("recovery_steps", recovery_steps, 0, 10000));
  FW_RETURN_IF_ERROR(check_count("past_scans_per_step", past_scans_per_step, 2, 64));  // 1 never catches up
  FW_RETURN_IF_ERROR(check_range("alias_max_shift_m", alias_max_shift_m, 0.0f, 50.0f));
  FW_RETURN_IF_ERROR(check_range("alias_step_m", alias_step_m, 0.05f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("alias_min_separation_m", alias_min_separation_m, 0.01f, 10.0f));
  FW_RETURN_IF_ERROR(check_range("alias_clip_m", alias_clip_m, 0.01f, 2.0f));
  FW_RETURN_IF_ERROR(check_range("alias_margin", alias_margin, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("alias_z", alias_z, 0.0f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("alias_credible_z", alias_credible_z, 0.0f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("alias_rotation_step_rad", alias_rotation_step_rad, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("alias_max_rotation_rad", alias_max_rotation_rad, 0.0f, 3.1416f));
  FW_RETURN_IF_ERROR(check_range("alias_min_separation_rad", alias_min_separation_rad, 0.0f, 1.0f));
  FW_RETURN_IF_ERROR(check_range("integrity_risk", integrity_risk, 1e-9f, 0.5f));
  FW_RETURN_IF_ERROR(check_range("alert_limit_m", alert_limit_m, 0.001f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("alert_limit_rad", alert_limit_rad, 0.0001f, 3.2f));
  FW_RETURN_IF_ERROR(check_range("lost_limit_m", lost_limit_m, alert_limit_m, 1000.0f));
  FW_RETURN_IF_ERROR(check_range("init_cov_scale", init_cov_scale, 0.01f, 1e4f));
  FW_RETURN_IF_ERROR(check_range("init_sigma_xy_floor_m", init_sigma_xy_floor_m, 0.0f, 100.0f));
  FW_RETURN_IF_ERROR(check_range("init_sigma_theta_floor_rad", init_sigma_theta_floor_rad, 0.0f, 3.2f));
  return Status::ok();
}

}  // namespace track
}  // namespace fw
