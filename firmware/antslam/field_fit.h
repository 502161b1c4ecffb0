// Local refinement of a loop-closing transform (an addition to Ch. 3, not in the dissertation):
// Gauss–Newton on the distance from the scene's points to the model's points, read from pRANSAM's
// ContactField of the model (interpolated distance and gradient), with a cutoff that shrinks over
// the iterations. A pRANSAM hypothesis is as precise as its triangle's points; and in a corridor
// the best triangle match may slide along it. AntSLAM therefore refines both pRANSAM's hypothesis
// and the prediction x of the loop and keeps the better fit (quality = mean fuzzy contact, Eq. 4.33).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/pransam/contact_field.h"
#include "firmware/scan/scan_points.h"

namespace fw::antslam {

struct FieldFit {
  Se2d pose;
  float quality = 0.0f;     // mean contact / 255 of all scene points at `pose`
  std::uint32_t used = 0;   // points within the cutoff at the last step
};

// Quality (mean contact / 255) of `scene` moved by `pose` into the field's frame.
float field_quality(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& pose);

// Gauss–Newton from `start`: `iterations` steps, cutoff from `cutoff_start` to `cutoff_end` (m).
FieldFit fit_on_field(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& start,
                      std::uint32_t iterations, float cutoff_start, float cutoff_end);

}  // namespace fw::antslam
