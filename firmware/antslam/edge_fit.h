// An edge's uncertainty from the data (Ch. 3, Eq. 3.9; SPEC §2): K poses around the matched pose,
// each weighted by the sensor model — how far the scan's end-points land from the other
// fragment's points — and N(μ, Σ) fitted to the weighted poses. Where the scan pins the pose (a
// corner, cross walls) Σ is small; along a corridor it is long. The ants and LM (Eq. 3.13) then put
// a loop's misclosure where the data leaves room for it, instead of spreading it by the distance
// travelled, which is all the motion model's covariance (Eq. 3.4) can say.
//
// The K poses are a regular grid in (x, y, θ) about the matched pose — a deterministic sample, so
// the same edge gets the same Σ — started coarse and halved while fewer than `min_effective_poses`
// carry the weight (effective sample size (Σw)²/Σw²), so a sharp fit is resolved and a flat one is
// not cut off by a grid that is too small. Σ is the weighted second moment about the matched pose
// (not the weighted mean: an offset between the two is uncertainty too) plus the grid's own
// quantisation (step²/12 per axis).
//
// Sensor model: every end-point N(0, σ²) about its nearest map point, clipped at clip_m (an end-point
// the other fragment does not explain costs the same wherever the pose is). End-points of one wall
// are not independent (the same map cells, the same bias), so the log-likelihood is scaled to one
// observation per cell of `correlation_m` holding end-points (as the tracker's information,
// firmware/track/track_options.h); a fragment's keyframes that see one wall again add nothing.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/antslam/sampled_edge.h"
#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/pransam/contact_field.h"
#include "firmware/scan/scan_points.h"

namespace fw::antslam {

struct EdgeFitOptions {
  std::uint32_t grid_half = 3;         // 2·g + 1 poses per axis: K = 343 (at most 4)
  double step_xy_m = 0.10;             // first grid ±0.3 m …
  double step_theta_rad = 0.02;        // … and ±0.06 rad
  std::uint32_t max_refinements = 3;   // halvings of the grid (finest 1.25 cm, 0.14°)
  double min_effective_poses = 8.0;
  double sigma_m = 0.05;               // sensor model σ (one map cell)
  double clip_m = 0.20;
  double correlation_m = 1.0;
  Status validate() const;
};

struct EdgeFit {
  Mat3 cov = Mat3::Zero();
  Se2d weighted_mean;
  double effective_poses = 0.0;       // of the final grid
  double step_xy_m = 0.0, step_theta_rad = 0.0;  // the final grid's spacing
  std::uint32_t independent = 0;      // observations counted (cells holding end-points)
};

// `scene`: points in the frame that `center` places in the field's frame (the robot frame for an
// adjacent edge, fragment a's frame for a loop closure). False (out untouched) when the field keeps
// no distances, fewer than 3 finite points are given, or the options are invalid.
bool fit_edge(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& center,
              const EdgeFitOptions& o, EdgeFit* out);

}  // namespace fw::antslam
