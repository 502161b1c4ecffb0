// Pose uniqueness test at the moment MML would first report `localized` (extension, not in the
// dissertation). The constraints of Eq. 5.8–5.17 compare the best cluster with the odometry; a
// cluster that is wrong by a constant offset along a corridor moves with the robot and passes them
// (aces, HIL fault run: 1.5 m behind, r = 1 from 5 hypotheses, d² < 1 for 20 steps). Such an
// offset is an alias of the scan along the corridor's weak axis, so before the pose is accepted
// the newest scan is refined from poses shifted along both principal axes of its translational
// information (the weak axis is the corridor), and the pose is unique only when no rival more than
// `min_separation_m` away fits the map as well (truncated quadratic cost, lower is better).
#pragma once

#include <cstddef>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"

namespace fw {
namespace mml {

struct UniquenessOptions {
  float clip_m = 0.15f;            // a point farther than this from the map costs clip² (outlier)
  float max_shift_m = 3.0f;        // rivals are seeded up to this far along each axis
  float shift_step_m = 0.4f;       // spacing of the seeds
  float min_separation_m = 0.4f;   // a refined rival closer than this is the candidate itself
  float margin = 0.01f;            // unique when every rival's cost exceeds the candidate's by more
  // Rivals in heading: seeds turned by ±k·rotation_step_rad up to max_rotation_rad (0 = none). A
  // track held at a wrong heading by clutter near the robot fits the near walls at either heading;
  // the far walls, outliers at the held heading, pull the turned seed to where they fit.
  float rotation_step_rad = 0.0f;
  float max_rotation_rad = 0.0f;
  float min_separation_rad = 0.035f;  // a refined rival turned less than this is the candidate
  // Extension (the tracker's TrackOptions::alias_valley_is_one_mode): a rival at the candidate's
  // heading (within min_separation_rad, cost within `margin` of the candidate's) joined to the
  // candidate through the candidate's own cost valley (in_same_cost_valley paths, sampled every
  // valley_step_m, outwards along each seed direction through the rivals already found in it) is
  // the scan's indeterminacy along its weak axis, not a second mode: it is not counted
  // (same_valley_rivals), and `rival` is the best of the others. false = every rival counts.
  bool valley_is_one_mode = false;
  float valley_step_m = 0.075f;
};

struct UniquenessResult {
  bool unique = true;
  float cost = 0.0f;        // candidate's mean truncated cost ∈ [0, 1] (in units of clip²)
  float rival_cost = 1.0f;  // best rival's
  Se2f rival;
  std::uint32_t rivals_tried = 0;
  bool rival_turned = false;  // the best rival came from a turned seed
  std::uint32_t same_valley_rivals = 0;  // rivals left out as one mode (valley_is_one_mode)
  // The farthest of those rivals from the candidate (valley_extent_m, 0 = none) and the unit
  // direction towards it: the axis along which the scan fits alike, i.e. says nothing.
  float valley_extent_m = 0.0f;
  float valley_axis_x = 0.0f, valley_axis_y = 0.0f;
};

// Mean of min(d, clip)² / clip² over the points (robot frame) placed at `pose`; points off the map
// count as outliers. Never allocates.
float truncated_scan_cost(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose, float clip_m);

// Whether `rival` lies in the same valley of the truncated cost as `pose`: both fit alike (costs
// within `margin`) and on the straight path between them (position and heading interpolated, samples at most step_m apart in position) no pose
// fits worse than the worse of the two ends by more than `margin`. A rival reached along such a path
// is the scan's own indeterminacy along its weak axis (a corridor whose walls fit wherever the robot
// stands along it): one mode with `pose`. One behind a barrier (a pillar, a door frame that only one
// of them explains) is a separate look-alike. Never allocates.
bool in_same_cost_valley(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose,
                         const Se2f& rival, float clip_m, float step_m, float margin);
// The same with the two ends' truncated costs already known (truncated_scan_cost's values at clip_m).
bool in_same_cost_valley(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose,
                         float cost_pose, const Se2f& rival, float cost_rival, float clip_m, float step_m,
                         float margin);

UniquenessResult check_pose_uniqueness(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& pose,
                                       const UniquenessOptions& options);

}  // namespace mml
}  // namespace fw
