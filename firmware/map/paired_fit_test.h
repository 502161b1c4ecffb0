// Paired test of two poses on the same end-points against the map's distance field (extension of
// the dissertation). Used by the tracker (alias check, heading-fault rule, confidence extent of the
// protection level) and by MML's rival memory (a rival is eliminated only when the local map
// contradicts it, rival_memory.h).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"

namespace fw {

// Paired test of the truncated per-point costs (d²/clip², 1 beyond clip or off the map) of the same
// end-points at `pose` and at `rival`: the rival is better only when the mean difference exceeds z
// standard errors, with the end-points counted as `independent` observations (the correlation cells
// of the alignment) — a few cluttered beams or a map drawn a little off in a corridor prove nothing.
bool rival_significantly_better(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& pose,
                                const Se2f& rival, float clip_m, std::uint32_t independent, float z);

// The same test against one pose tested many times (the confidence extent walks up to 40 poses away
// from one fix): that pose's per-point costs are sampled once. test() gives the bits of
// rival_significantly_better(map, pts, n, pose, fixed, clip_m, independent, z) — the same costs in
// the same order, the batched samples (distance_batch.h) being DistanceSampler's bits. Holds at
// most kMaxPoints end-points; with more, test() calls rival_significantly_better.
class PairedFitReference {
 public:
  static constexpr std::size_t kMaxPoints = 256;
  PairedFitReference(const GlobalMap& map, const Point2f* pts, std::size_t n, const Se2f& fixed, float clip_m);
  // Is `fixed` significantly better than `pose`?
  bool fixed_better_than(const Se2f& pose, std::uint32_t independent, float z) const;

 private:
  const GlobalMap& map_;
  const Point2f* pts_;
  std::size_t n_;
  Se2f fixed_;
  float clip_m_;
  bool cached_;
  double cost_[kMaxPoints];
};

}  // namespace fw
