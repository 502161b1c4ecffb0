// The windowed odometry-error estimator of the grounding measurement (issue 55, item 6), applied
// identically to a real log (raw odometry vs the corrected reference) and to a simulated run (its
// odometry vs its exact truth).
//
// Input: one pose pair (odometry, reference) per usable instant, in time order, in their own frames
// (odometry frame, map frame). Only instants where the reference is itself a measurement belong in
// the sequence (a corrected pose, a relation scan): a reference chained from the odometry between
// them would agree with the odometry by construction.
//
// Windows: from a start instant, the window ends at the first instant where the driven distance D
// (the reference's path length, Σ|Δref_xy| over consecutive instants) reaches window_m; the next
// window starts stride_m further on (stride_m = window_m: disjoint windows). A window whose D exceeds
// max_overshoot · window_m (a gap in the reference) is dropped. Per window, with ΔO = O_s ⊖ O_e and
// ΔR = R_s ⊖ R_e (each in its start frame) and the turn Σ wrap(Δθ) over the window (unwrapped):
//   trans_err_per_m   = |ΔO_xy − ΔR_xy| / D                         (m per m driven)
//   head_err_per_m    = |turn_O − turn_R| / D                       (rad per m)
//   head_err_per_rad  = |turn_O − turn_R| / |turn_R|   only when |turn_R| > min_turn_rad
//   dist_scale        = (|ΔO_xy| − |ΔR_xy|) / |ΔR_xy|  only when |ΔR_xy| ≥ straight_fraction · D
//   turn_scale        = (turn_O − turn_R) / turn_R      only when |turn_R| > min_turn_rad
// dist_scale and turn_scale are signed: their medians are the systematic parts (wheel radius, track
// width); the absolute errors' p50 and p95 are the spread.
#pragma once

#include <cstddef>
#include <vector>

#include "firmware/base/se2.h"

namespace sim::ground {

struct WindowOptions {
  double window_m = 1.0;
  double stride_m = 0;          // ≤ 0: window_m (disjoint windows)
  double min_turn_rad = 0.3;
  double straight_fraction = 0.8;
  double max_overshoot = 2.0;   // windows longer than this × window_m are dropped
};

struct OdometryWindow {
  double driven_m = 0, chord_m = 0;
  double turn_ref = 0, turn_odom = 0;  // rad, unwrapped
  double trans_err_per_m = 0, head_err_per_m = 0;
  double head_err_per_rad = -1;        // < 0: not a turning window
  double dist_scale = 0;
  bool straight = false;
  bool turning = false;
};

std::vector<OdometryWindow> odometry_windows(const std::vector<fw::Se2d>& odom, const std::vector<fw::Se2d>& ref,
                                             const WindowOptions& opt);

// Quantile q ∈ [0, 1] by linear interpolation; NaN for an empty sample.
double quantile(std::vector<double> v, double q);

struct OdometryErrorSummary {
  std::size_t windows = 0, straight_windows = 0, turning_windows = 0;
  double driven_m = 0;  // Σ driven over the windows
  // Absolute errors: p50, p95 (trans: m/m; head: deg/m and deg/rad → reported in those units).
  double trans_p50 = 0, trans_p95 = 0;
  double head_deg_per_m_p50 = 0, head_deg_per_m_p95 = 0;
  double head_per_rad_p50 = 0, head_per_rad_p95 = 0;  // rad/rad (dimensionless)
  // Systematic parts: medians of the signed scale errors (NaN without such windows).
  double dist_scale_median = 0, turn_scale_median = 0;
  // Interquartile bounds used by the verdicts.
  double trans_p10 = 0, trans_p90 = 0, head_deg_per_m_p10 = 0, head_deg_per_m_p90 = 0;
};

OdometryErrorSummary summarize(const std::vector<OdometryWindow>& w);

}  // namespace sim::ground
