// MmlOptions: every knob of MML (dissertation Ch. 5, Tables 5.1–5.4) in one plain struct, validated
// once at start-up (Cartographer style). Defaults are the thesis's values "chosen once for all
// scenarios" (Sec. 5.7): σ²_trans,max = 30 cm², σ²_rot,max = 50 deg², δ_r = 0.8, ξ_r² = 8,
// ξ_med = 10, τ_tr = 10, k = 4, δ_l = 0.01, Δ_u = 0.07, Ω_thres0 = 0.7, τ_up = 10.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {
namespace mml {

// Compile-time capacities (fixed storage; the options may use less).
constexpr std::size_t kMaxHypotheses = 4096;   // hypotheses per step handed to the interpreter
constexpr std::size_t kMaxClusters = 512;      // clusters per step
constexpr std::size_t kMaxMedianWindow = 64;   // τ_m
constexpr std::size_t kMaxThresholdWindow = 64;  // τ_tr
constexpr std::size_t kMaxUnknownWindow = 64;  // τ_up
constexpr std::size_t kMaxReducedObservations = 256;  // reduction_max_observations
constexpr std::size_t kMaxCorrectedFragments = 16;    // correction_fragments
constexpr std::size_t kMaxCorrectionPoints = 2048;    // correction_points

struct MmlOptions {
  // --- Hypothesis filter (Eq. 5.3): max rotation about x (roll) and y (pitch) of a 3-D frame
  // transform; a flipped 2-D triangle frame has roll = π and is discarded.
  float filter_max_roll_rad = 0.5f;
  float filter_max_pitch_rad = 0.5f;

  // --- Hierarchical K-means clustering (Sec. 5.3.1).
  float sigma2_trans_max_m2 = 0.0030f;   // 30 cm²
  float sigma2_rot_max_deg2 = 50.0f;     // 50 deg²
  std::uint32_t kmeans_iterations = 8;   // Lloyd iterations per 2-means split

  // --- Rating (Eq. 5.4–5.6). Σα = 1.
  float alpha[4] = {0.4f, 0.1f, 0.1f, 0.4f};
  bool stretch_quality = true;  // Eq. 5.5: f(w4) = (w4 − Ω_thres)/(1 − Ω_thres)

  // --- Localization constraints (Eq. 5.17) and soft rule (Eq. 5.22).
  float delta_r = 0.8f;         // r(C) > δ_r
  // Extension: a cluster of one or two hypotheses gets r = 1 when it is alone, which says nothing;
  // the rating test also needs this many members.
  std::uint32_t min_cluster_hypotheses = 5;
  // Extension: the members may be pooled over consecutive steps in which the best cluster was alone
  // above δ_r and consistent (d², σ_med) — see interpretation.cpp. Off: one step must hold them all.
  // Off for MML alone, on in mml-track (mml_track_preset): there the tracker confirms the fix on the
  // same scan and guards it from then on, while MML alone publishes its soft-rule continuation
  // (Eq. 5.22) unchecked — with pooling it localized earlier on intel's unknown-area run and then
  // stayed `localized` 1.1 m behind as the robot drove into the erased box (bench mml, trial 1).
  bool pool_cluster_support = false;
  // Extension: a step in which pRANSAM returns no hypothesis above Ω_thres (`searching`) neither
  // supports nor contradicts the best cluster, so it keeps the pool and the consistency streak (x_prev
  // is carried by the odometry through it, so the next d² still spans the gap). Off: such a step
  // starts both again (the adaptive threshold alternates full and empty steps while the robot is
  // still; intel fix trial 3 stayed `ambiguous`/`searching` for 200 steps at 0.0–0.2 m error).
  bool keep_support_across_empty_steps = false;
  // Extension: a step in which the best cluster is consistent (d², σ_med) but not alone above δ_r
  // (a rival cluster holds more than 1 − δ_r of the rating) adds no member and keeps the pool; an
  // inconsistent step still empties it, and `localized` still needs a step in which the cluster is
  // alone. Off: such a step empties the pool.
  bool keep_support_across_contested_steps = false;
  float xi_r2 = 8.0f;           // d²(r_h, R_h) < ξ_r² (χ² quantile, 3 dof)
  float xi_med = 10.0f;         // σ_med < ξ_med
  std::uint32_t tau_m = 10;     // window of d² values for the median test (Eq. 5.15–5.16)
  std::uint32_t med_min_samples = 5;  // d² samples needed before σ_med is trusted
  bool soft_rule = true;        // Eq. 5.22
  std::uint32_t soft_max_blind_steps = 3;  // steps without any hypothesis tolerated in soft mode
  // Extension: consecutive steps meeting d² < ξ_r² and σ_med < ξ_med before the first `localized`
  // (1 = Eq. 5.17 alone).
  std::uint32_t confirm_steps = 2;

  // Covariances for Eq. 5.9–5.13: odometry noise per step (P_r) and a floor added to cluster
  // covariances (P_prev, P_h) — a one-hypothesis cluster has zero spread but is not exact.
  float odom_sigma_trans_per_m = 0.10f;    // σ_t = a·|Δt| + floor
  float odom_sigma_rot_per_rad = 0.10f;    // σ_θ = b·|Δθ| + c·|Δt| + floor
  float odom_sigma_rot_per_m = 0.05f;
  float odom_sigma_trans_floor_m = 0.02f;
  float odom_sigma_rot_floor_rad = 0.02f;
  float hyp_sigma_trans_floor_m = 0.10f;
  float hyp_sigma_rot_floor_rad = 0.035f;  // ≈ 2°

  // --- Published pose (extension, see pose_refiner.h): refine the newest scan against the global
  // map; while localized, propagate the previous published pose with the wheel odometry and refine
  // that (the clusters keep validating it through Eq. 5.14 and the soft rule).
  bool refine_pose = true;
  bool track_when_localized = true;
  std::uint32_t refine_points = 180;   // scan points used
  // The tracked pose is dropped (and the soft rule with it) after this many consecutive scans the
  // refinement rejects, or this many consecutive steps the interpretation is not `localized`.
  std::uint32_t tracked_max_rejected_steps = 5;
  std::uint32_t tracked_max_unlocalized_steps = 30;
  // Extension (pose_uniqueness.h): entering `localized` also needs the refined pose to be the best
  // fit of the newest scan among rivals seeded along its principal axes (corridor aliases).
  bool unique_check = true;
  float unique_max_shift_m = 3.0f;
  float unique_shift_step_m = 0.4f;
  float unique_margin = 0.01f;       // in units of clip² of the truncated scan cost: a near-tie is no proof

  // Extension (rival_memory.h): a cluster that stops appearing is not eliminated. Clusters rated
  // ≥ rival_min_rating_ratio × the step's best are remembered (as map ← local map transforms);
  // entering `localized` needs every remembered rival farther than the separation to be explained
  // significantly worse by the local map (paired test at rival_z over its rival_cell_m cells).
  bool rival_memory = true;
  float rival_min_rating_ratio = 0.5f;
  float rival_separation_m = 1.0f;
  float rival_separation_rad = 0.35f;  // 20°
  float rival_clip_m = 0.15f;
  float rival_z = 3.09f;               // one-sided 1e-3
  float rival_cell_m = 1.0f;
  std::uint32_t rival_points = 1024;   // local map points used by the test (≤ kMaxRivalPoints)

  // --- Matching threshold adaptation (Sec. 5.3.3, Eq. 5.18–5.21).
  bool bollinger = true;
  float omega_thres0 = 0.7f;
  std::uint32_t tau_tr = 10;
  float bollinger_k = 4.0f;
  float bollinger_delta_l = 0.01f;
  float bollinger_delta_u = 0.07f;
  float omega_thres_min = 0.60f;   // never ask pRANSAM for less than this (weak matches fool
                                   // the constraints when only one cluster survives)
  float omega_thres_max = 0.95f;
  // pRANSAM refinement (MatchParams::refine_iterations, on in mml_track_preset): hypotheses rated
  // at least Ω_thres − refine_window (and MatchParams::refine_min_quality) are refined.
  float refine_window = 0.2f;

  // --- Unknown regions (Sec. 5.6, Eq. 5.37).
  bool detect_unknown = true;
  // Unmapped space = inner unknown regions of at least this area (m², map/unmapped_space.h): while
  // MmlLocalizer::set_unmapped_hypothesis(true), a point there counts as contact in pRANSAM's
  // quality (the robot may stand in a room the map lacks). 0 = none (the dissertation: unknown
  // cells are misses). 1 m²: smaller unknown pockets (pillars, thick walls) cannot hold the robot.
  float unmapped_space_min_area_m2 = 1.0f;
  std::uint32_t tau_up = 10;
  float outside_map_contact = 0.35f;   // Ω' below ⇒ outside-map
  float contact_distance_m = 0.15f;    // "contact" = a map point within this distance
  // Extension: no hypothesis at all for this many consecutive steps although the threshold sits
  // at omega_thres_min and the local map is ≥ 2·min_local_map_points ⇒ outside-map too (covers a
  // start inside the unknown region, where no H_best exists for Eq. 5.37). 0 = off.
  std::uint32_t outside_map_no_match_steps = 10;

  // --- Local map (Sec. 5.4–5.5; the last m fragments kept: LocalMapOptions::keep_last, local_map/local_map.h).
  // Local map reduction (Sec. 5.5.1, Eq. 5.28–5.30, observation_reduction.h): match only the
  // observations (scans) at which the number of clusters f(t) collapsed, plus the two newest.
  bool reduce_observations = false;
  float reduction_min_jump = 2.0f;         // Δ(|C(t)|) for |C(t)| → 0: the constant 2 of Eq. 5.30
  float reduction_delta_max = 4.0f;        // Δ_max of Eq. 5.30 (≥ reduction_min_jump)
  std::uint32_t reduction_clusters_max = 20;  // |C|_max of Eq. 5.30
  std::uint32_t reduction_observation_points = 180;  // scan points kept per accepted observation
  std::uint32_t reduction_max_observations = 64;     // accepted observations kept (oldest evicted)
  // Local map correction (Sec. 5.4, Eq. 5.23–5.27, App. D, local_map_correction.h): gradient
  // descent of the newest fragments onto the global map under H_best, only in steps that end
  // `localized` with the best cluster passing the rating test (r > δ_r, ≥ min_cluster_hypotheses).
  bool correct_local_map = false;
  std::uint32_t correction_iterations = 20;  // gradient steps per fragment and MML step
  float correction_step = 0.05f;             // α(0) of Eq. 5.27 (adapted: ×2 on success, ½ on failure)
  std::uint32_t correction_fragments = 2;    // newest fragments corrected per step
  std::uint32_t correction_points = 300;     // fragment points used (subsampled)
  std::uint32_t correction_min_points = 30;  // fewer fragment points: not corrected
  float correction_clip_m = 0.30f;           // points farther from the map do not pull (outliers)
  float correction_max_shift_m = 0.30f;      // a per-step correction beyond these is rejected
  float correction_max_rotation_rad = 0.10f;
  std::uint32_t min_local_map_points = 150;  // no matching below (status searching)

  // --- Matching (pRANSAM collect-all).
  bool precomputed_table = true;
  std::uint64_t table_triples = 2000000;  // h of Sec. 5.5.2 when the table is filled at start-up
  float table_extent_m = 12.0f;           // relation table extent (longest triangle side)
  std::uint32_t matching_iterations = 30000;
  std::uint32_t max_local_map_points = 1500;  // subsampled for matching
  std::uint32_t max_hypotheses = 2048;        // ≤ kMaxHypotheses
  std::uint64_t seed = 1;

  Status validate() const;
};

}  // namespace mml
}  // namespace fw
