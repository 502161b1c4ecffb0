// Scan-to-map alignment for tracking: a few Gauss-Newton steps of the scan's end-points on the
// global map's distance field with a Huber loss, seeded by the odometry prediction (as LaMa's
// Loc2D and Cartographer's Ceres scan matcher do). Besides the pose it returns what the integrity
// monitor needs: the information the scan carries (with the correlation of neighbouring
// end-points accounted for), and how the end-points split into explained by the map (inliers),
// contradicting it (on free cells, far from any wall) and unknown (unmapped / off-map space).
// Extension of the dissertation (its Sec. 5.8 names tracking after MML as future work); the
// residual is the distance field of the local map correction (Eq. 5.23–5.27) applied to one scan.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/track/track_options.h"

namespace fw {
namespace track {

struct ScanAlignment {
  Se2f pose;                                          // scan-only optimum (near the seed)
  Eigen::Matrix3f information = Eigen::Matrix3f::Zero();  // of the scan alone, 1/m², 1/rad²
  std::uint32_t points = 0;        // end-points used
  std::uint32_t inliers = 0;       // within outlier_m of a mapped wall at `pose`
  std::uint32_t contradicting = 0; // on a known cell but far from every wall
  std::uint32_t unknown = 0;       // on an unknown cell or off the map, far from every wall
  std::uint32_t independent = 0;   // correlation cells holding inliers (n_eff)
  float sigma_m = 0.0f;            // per-point noise used for the information (residual RMS, floored)
  float rms_m = 0.0f;              // RMS residual of the inliers
  float lever_m = 0.0f;            // RMS distance of the inliers from the sensor
  float inlier_fraction() const {
    const std::uint32_t known = inliers + contradicting;
    return known > 0 ? static_cast<float>(inliers) / static_cast<float>(known) : 0.0f;
  }
  float unknown_fraction() const { return points > 0 ? static_cast<float>(unknown) / static_cast<float>(points) : 0.0f; }
};

// `points` in the robot (sensor) frame, in beam order. Never allocates.
ScanAlignment align_scan(const GlobalMap& map, const Point2f* points, std::size_t n, const Se2f& seed,
                         const ScanAlignOptions& options);

}  // namespace track
}  // namespace fw
