#include "firmware/mml/mml_options.h"

#include <cmath>

namespace fw {
namespace mml {
namespace {

Status check_range(const char* field, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    return Status::error(Errc::kInvalidArgument, "MmlOptions.%s = %g out of range [%g, %g]", field, v, lo, hi);
  }
  return Status::ok();
}

Status check_positive(const char* field, double v) {
  if (!std::isfinite(v) || !(v > 0.0)) {
    return Status::error(Errc::kInvalidArgument, "MmlOptions.%s = %g must be finite and > 0", field, v);
  }
  return Status::ok();
}

}  // namespace

Status MmlOptions::validate() const {
  FW_RETURN_IF_ERROR(check_range("filter_max_roll_rad", filter_max_roll_rad, 0.0, 3.1416));
  FW_RETURN_IF_ERROR(check_range("filter_max_pitch_rad", filter_max_pitch_rad, 0.0, 3.1416));
  FW_RETURN_IF_ERROR(check_positive("sigma2_trans_max_m2", sigma2_trans_max_m2));
  FW_RETURN_IF_ERROR(check_positive("sigma2_rot_max_deg2", sigma2_rot_max_deg2));
  FW_RETURN_IF_ERROR(check_range("kmeans_iterations", kmeans_iterations, 1, 100));
  double sum = 0.0;
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(alpha[i]) || alpha[i] < 0.0f) {
      return Status::error(Errc::kInvalidArgument, "MmlOptions.alpha[%d] = %g must be ≥ 0", i, alpha[i]);
    }
    sum += alpha[i];
  }
  if (std::fabs(sum - 1.0) > 1e-3) {
    return Status::error(Errc::kInvalidArgument, "MmlOptions.alpha sums to %g, must be 1 (Eq. 5.4)", sum);
  }
  FW_RETURN_IF_ERROR(check_range("delta_r", delta_r, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("unmapped_space_min_area_m2", unmapped_space_min_area_m2, 0.0, 60.0));
  FW_RETURN_IF_ERROR(check_range("min_cluster_hypotheses", min_cluster_hypotheses, 1, kMaxHypotheses));
  FW_RETURN_IF_ERROR(check_positive("xi_r2", xi_r2));
  FW_RETURN_IF_ERROR(check_positive("xi_med", xi_med));
  FW_RETURN_IF_ERROR(check_range("tau_m", tau_m, 1, kMaxMedianWindow));
  FW_RETURN_IF_ERROR(check_range("med_min_samples", med_min_samples, 1, tau_m));
  FW_RETURN_IF_ERROR(check_range("soft_max_blind_steps", soft_max_blind_steps, 0, 1000));
  FW_RETURN_IF_ERROR(check_range("confirm_steps", confirm_steps, 1, 100));
  FW_RETURN_IF_ERROR(check_range("odom_sigma_trans_per_m", odom_sigma_trans_per_m, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("odom_sigma_rot_per_rad", odom_sigma_rot_per_rad, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_range("odom_sigma_rot_per_m", odom_sigma_rot_per_m, 0.0, 10.0));
  FW_RETURN_IF_ERROR(check_positive("odom_sigma_trans_floor_m", odom_sigma_trans_floor_m));
  FW_RETURN_IF_ERROR(check_positive("odom_sigma_rot_floor_rad", odom_sigma_rot_floor_rad));
  FW_RETURN_IF_ERROR(check_positive("hyp_sigma_trans_floor_m", hyp_sigma_trans_floor_m));
  FW_RETURN_IF_ERROR(check_positive("hyp_sigma_rot_floor_rad", hyp_sigma_rot_floor_rad));
  FW_RETURN_IF_ERROR(check_range("refine_points", refine_points, 3, 1081));
  FW_RETURN_IF_ERROR(check_range("tracked_max_rejected_steps", tracked_max_rejected_steps, 1, 100000));
  FW_RETURN_IF_ERROR(check_range("tracked_max_unlocalized_steps", tracked_max_unlocalized_steps, 1, 100000));
  if (!(unique_shift_step_m > 0.0f) || !(unique_max_shift_m >= unique_shift_step_m) || unique_max_shift_m > 20.0f) {
    return Status::error(Errc::kInvalidArgument, "MmlOptions: need 0 < unique_shift_step_m (%g) <= unique_max_shift_m (%g) <= 20",
                         static_cast<double>(unique_shift_step_m), static_cast<double>(unique_max_shift_m));
  }
  if (!(rival_min_rating_ratio > 0.0f && rival_min_rating_ratio <= 1.0f) || !(rival_separation_m > 0.0f) ||
      !(rival_separation_rad > 0.0f) || !(rival_clip_m > 0.0f) || !(rival_z > 0.0f) || !(rival_cell_m > 0.0f) ||
      rival_points < 16 || rival_points > 2048) {
    return Status::error(Errc::kInvalidArgument,
                         "MmlOptions: rival memory needs 0 < rival_min_rating_ratio <= 1, positive separations, clip, z "
                         "and cell, and 16 <= rival_points (%u) <= 2048",
                         rival_points);
  }
  if (!(unique_margin >= 0.0f && unique_margin < 1.0f)) {
    return Status::error(Errc::kInvalidArgument, "MmlOptions: unique_margin %g outside [0, 1)", static_cast<double>(unique_margin));
  }
  FW_RETURN_IF_ERROR(check_range("omega_thres0", omega_thres0, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("tau_tr", tau_tr, 1, kMaxThresholdWindow));
  FW_RETURN_IF_ERROR(check_range("bollinger_k", bollinger_k, 0.0, 100.0));
  FW_RETURN_IF_ERROR(check_range("bollinger_delta_l", bollinger_delta_l, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("bollinger_delta_u", bollinger_delta_u, 0.0, 1.0));
  if (bollinger_delta_l > bollinger_delta_u * omega_thres_max) {
    return Status::error(Errc::kInvalidArgument,
                         "MmlOptions.bollinger_delta_l = %g exceeds bollinger_delta_u·omega_thres_max = %g",
                         bollinger_delta_l, bollinger_delta_u * omega_thres_max);
  }
  FW_RETURN_IF_ERROR(check_range("omega_thres_min", omega_thres_min, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("omega_thres_max", omega_thres_max, omega_thres_min, 0.999));
  if (omega_thres0 < omega_thres_min || omega_thres0 > omega_thres_max) {
    return Status::error(Errc::kInvalidArgument, "MmlOptions.omega_thres0 = %g outside [omega_thres_min, omega_thres_max]",
                         omega_thres0);
  }
  FW_RETURN_IF_ERROR(check_range("tau_up", tau_up, 1, kMaxUnknownWindow));
  FW_RETURN_IF_ERROR(check_range("outside_map_contact", outside_map_contact, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("refine_window", refine_window, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_positive("contact_distance_m", contact_distance_m));
  FW_RETURN_IF_ERROR(check_range("outside_map_no_match_steps", outside_map_no_match_steps, 0, 100000));
  FW_RETURN_IF_ERROR(check_range("reduction_min_jump", reduction_min_jump, 0.0, 1e6));
  FW_RETURN_IF_ERROR(check_range("reduction_delta_max", reduction_delta_max, reduction_min_jump, 1e6));
  FW_RETURN_IF_ERROR(check_range("reduction_clusters_max", reduction_clusters_max, 1, kMaxClusters));
  FW_RETURN_IF_ERROR(check_range("reduction_observation_points", reduction_observation_points, 3, 1081));
  FW_RETURN_IF_ERROR(check_range("reduction_max_observations", reduction_max_observations, 1, kMaxReducedObservations));
  FW_RETURN_IF_ERROR(check_range("correction_iterations", correction_iterations, 0, 10000));
  FW_RETURN_IF_ERROR(check_positive("correction_step", correction_step));
  FW_RETURN_IF_ERROR(check_range("correction_step", correction_step, 0.0, 1.0));
  FW_RETURN_IF_ERROR(check_range("correction_fragments", correction_fragments, 1, kMaxCorrectedFragments));
  FW_RETURN_IF_ERROR(check_range("correction_points", correction_points, 3, kMaxCorrectionPoints));
  FW_RETURN_IF_ERROR(check_range("correction_min_points", correction_min_points, 3, correction_points));
  FW_RETURN_IF_ERROR(check_positive("correction_clip_m", correction_clip_m));
  FW_RETURN_IF_ERROR(check_positive("correction_max_shift_m", correction_max_shift_m));
  FW_RETURN_IF_ERROR(check_range("correction_max_rotation_rad", correction_max_rotation_rad, 1e-6, 3.1416));
  FW_RETURN_IF_ERROR(check_range("min_local_map_points", min_local_map_points, 3, 1000000));
  FW_RETURN_IF_ERROR(check_range("table_triples", static_cast<double>(table_triples), 1, 1e9));
  FW_RETURN_IF_ERROR(check_range("table_extent_m", table_extent_m, 0.5, 1000.0));
  FW_RETURN_IF_ERROR(check_range("matching_iterations", matching_iterations, 1, 100000000));
  FW_RETURN_IF_ERROR(check_range("max_local_map_points", max_local_map_points, 3, 1000000));
  FW_RETURN_IF_ERROR(check_range("max_hypotheses", max_hypotheses, 1, kMaxHypotheses));
  return Status::ok();
}

}  // namespace mml
}  // namespace fw
