// CorrelativeSearch: a brute-force search of the scan's best fit on the global map's distance field
// over a window around the odometry prediction, used by the tracker when the prediction is too
// uncertain for Gauss-Newton alone (the real-time correlative scan matcher Cartographer runs before
// its Ceres refinement; LaMa's Loc2D relies on a tight prediction instead). Gauss-Newton from a
// prediction 0.4 m / 10° off converges into whichever wall is nearest (fr079: a track slid 1.2 m
// after one odometry fault widened its covariance); the search scores every pose of the window and
// hands the best one to Gauss-Newton. The window follows from the data the robot has now: a
// multiple of the prediction's standard deviations, capped. Extension of the dissertation.
// Never allocates; deterministic (fixed candidate order, first best wins).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/track/track_options.h"

namespace fw {
namespace track {


struct CorrelativeWindow {
  float xy_m = 0.0f;      // half-width in x and y
  float theta_rad = 0.0f; // half-width in heading
};

struct CorrelativeResult {
  Se2f pose;                  // best candidate (the seed when nothing beats it)
  float score = 0.0f;         // mean truncated score of the best candidate, 0..1
  float seed_score = 0.0f;    // the same at the seed
  std::uint32_t candidates = 0;
};

// Mean over `points` of max(0, 1 − d²/clip²) with d the distance-field value at the end-point
// (0 off the map). `points` in the sensor frame.
float fit_score(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose, float clip_m);

// `points` in the sensor frame (at most options.max_points, and half the scratch, are used, evenly
// subsampled). `scratch`: caller-owned storage of `scratch_len` points (2 × max_points suffice).
CorrelativeResult correlative_search(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& seed,
                                     const CorrelativeWindow& window, const CorrelativeSearchOptions& options,
                                     Point2f* scratch, std::size_t scratch_len);

}  // namespace track
}  // namespace fw
