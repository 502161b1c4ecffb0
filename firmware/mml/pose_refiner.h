// Pose refinement of the newest observation against the global map's distance image: a few
// Gauss-Newton steps minimising Σ min(D(T·p_i), c)² over T = (x, y, θ) — the idea of the local map
// correction of Sec. 5.4 (Eq. 5.23–5.27: gradient descent of the local map onto the global map)
// applied to the latest scan only. Needed because the scan-matched local map can slip along
// featureless corridors, so H ⊕ x_local lags the robot; refining the published pose (and x_prev of
// Eq. 5.8) against the map keeps the estimate on the robot and lets Eq. 5.14 see the slip.
#pragma once

#include <cstddef>

#include "firmware/base/se2.h"
#include "firmware/map/distance_batch.h"
#include "firmware/map/global_map.h"

namespace fw {
namespace mml {

struct RefineOptions {
  std::uint32_t iterations = 10;
  float clip_m = 0.15f;          // points farther than this from the map are outliers (the first
                                 // half of the iterations uses 2·clip_m to pull in from afar)
  float sigma_m = 0.05f;         // range/map noise of one point
  // Prior on the initial pose: keeps directions the scan does not constrain (along a corridor,
  // or biased by unmapped wall continuations) at the prediction.
  float prior_sigma_xy_m = 0.10f;
  float prior_sigma_theta_rad = 0.05f;
  float min_inlier_ratio = 0.4f; // refinement rejected below this inlier fraction
  float max_shift_m = 1.0f;      // and when it moves the pose farther than this
};

struct RefineResult {
  Se2f pose;
  float inlier_ratio = 0.0f;
  float rms_m = 0.0f;
  bool accepted = false;
  // The truncated cost at `pose` clipped at options.clip_m, as mml::truncated_scan_cost gives it
  // (pose_uniqueness.h; same samples, same order, same bits), taken from the pass that sampled
  // `pose` — so the alias check, which scores every rival it refines, samples each once less.
  // cost_valid false (map invalid, no points): call truncated_scan_cost.
  float cost = 1.0f;
  bool cost_valid = false;
};

// `points` in the robot frame. Never allocates. `build`: which build of the distance samples and of the
// normal equations' sums runs (distance_batch.h; kScalar = point by point, the reference the tests
// compare with) — every build gives the same bits.
RefineResult refine_pose(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& initial,
                         const RefineOptions& options, DistanceBatchBuild build = DistanceBatchBuild::kBest);

}  // namespace mml
}  // namespace fw
