// Isolation of a loop closure on the map around its candidate (an extension of Alg. 3, the loop
// closing analogue of MML's pose uniqueness, firmware/mml/pose_uniqueness.h).
//
// A closure accepted without the drift gate (closure_pairs.h) has only the map to vouch for it. Two
// successive fragments that both alias a periodic corridor by the same shift agree with each other
// as well as two true closures do (measured on mit-killian's infinite corridor: pairs 4–8 m along
// the corridor, cycle χ² 0.2–12). So the closure must also be *isolated*: the scene (both fragments'
// points) is refined on the field of the old map around the candidate (every fragment within a few
// hops of it) from rival poses shifted along both principal axes of the scene's extent, and turned
// by 180°, up to max_shift_m; the closure is isolated only when it fits significantly better than
// every rival that settles more than min_separation_m (or more than min_separation_rad in heading)
// away: a paired test on the points' contact values (Eq. 4.33), one observation per correlation
// cell, z one-sided. A rival that fits as well is another place the scene could be: no closure.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/antslam/field_fit.h"
#include "firmware/antslam/sampled_edge.h"

namespace fw::antslam {

struct IsolationOptions {
  std::uint32_t hops = 3;           // old fragments within this many edges of the candidate form the model
  float max_shift_m = 10.0f;        // rivals seeded up to this far along each principal axis …
  float shift_step_m = 0.5f;        // … every shift_step_m
  bool turned_rivals = true;        // and every seed also turned by 180°
  float min_separation_m = 1.0f;    // a refined rival nearer than this (and min_separation_rad) is the closure
  float min_separation_rad = 0.35f;
  float cell_m = 0.5f;              // correlation cell of the paired test
  float z = 3.09f;                  // one-sided 0.1 %
  std::uint32_t refine_iterations = 10;
  float cutoff_start_m = 0.5f, cutoff_end_m = 0.15f;
  Status validate() const;
};

struct IsolationResult {
  bool isolated = true;
  float quality = 0.0f;        // the closure's (mean contact / 255) after refinement
  float rival_quality = 0.0f;  // the best rival's
  float rival_z = 0.0f;        // the paired test's z of (closure − best rival); isolated when > z for every rival
  Se2d pose, rival;
  std::uint32_t rivals_tried = 0;
};

struct CellSample {
  std::uint32_t key;  // correlation cell
  float d;            // contact difference of one point
};

// A prior on the closure: rivals it rules out (Mahalanobis² beyond `gate` from `mean`) do not compete.
struct IsolationPrior {
  Se2d mean;
  Mat3 info = Mat3::Zero();
  double gate = 0.0;
};

// `scene` (n points) placed at `h` in the field's frame; `cells` scratch of at least n entries;
// `prior` optional (nullptr: every rival competes). Never allocates.
IsolationResult check_closure_isolation(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n,
                                        const Se2d& h, const IsolationOptions& options, CellSample* cells,
                                        const IsolationPrior* prior = nullptr);

}  // namespace fw::antslam
