// ScanMatcher: the seam every experiment swaps (RBSM, trimmed ICP). A matcher owns its map of
// previously accepted scan points; match() aligns sensor-frame points against it starting from an
// initial guess (world frame), integrate() adds accepted points. Same contract for all matchers
// so the evaluation tool, the scan-matching odometry and MML's local map never see which one runs.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/base/status.h"
#include "firmware/scan/scan_points.h"

namespace fw {

struct ScanMatchResult {
  Se2f pose;                     // matched sensor/robot pose in the world frame
  std::uint32_t iterations = 0;  // RBSM: resampling rounds; ICP: alignment iterations
  std::uint32_t used_points = 0;   // valid points taken into account
  std::uint32_t matched_points = 0;  // points with a correspondence within the bound at `pose`
  float score = 0.0f;            // matcher-specific quality in [0, 1] (RBSM: best weight / max)
  float effective_ratio = 0.0f;  // RBSM: M_eff / M at termination; ICP: trimmed rms error (m)
  bool converged = false;        // stop rule met before the iteration cap
  bool map_was_empty = false;    // nothing to match against: pose = initial guess
  bool refined = false;          // RBSM: the continuous refinement (extension) moved the pose
  Se2f unrefined_pose;           // RBSM: x̂_t of Alg. 1 before the refinement (= pose when not refined)
};

class ScanMatcher {
 public:
  virtual ~ScanMatcher() = default;
  virtual const char* name() const = 0;
  // Forget the map and any tracking state (particles).
  virtual void reset() = 0;
  // Aligns `count` sensor-frame points with the map, starting from `initial_guess` (world).
  // Errors (status) for a null pointer with count > 0, non-finite points or guess, or too few
  // valid points; an empty map is not an error (result.map_was_empty, pose = initial_guess).
  virtual Status match(const Point2f* points, std::size_t count, const Se2f& initial_guess,
                       ScanMatchResult* out) = 0;
  // Adds the points seen from `pose` to the map. If `new_cells` is given, the world positions of
  // newly occupied map cells are written there (at most `capacity`, count in *num_new).
  virtual Status integrate(const Point2f* points, std::size_t count, const Se2f& pose,
                           Point2f* new_cells = nullptr, std::size_t capacity = 0,
                           std::size_t* num_new = nullptr) = 0;
};

}  // namespace fw
