#include "firmware/scan/scan_points.h"

#include <cmath>

namespace fw {

Status scan_to_points(const hal::LaserScan& scan, const ScanPointsOptions& options, Point2f* out,
                      std::size_t capacity, ScanPointsResult* result) {
  *result = ScanPointsResult{};
  if (scan.beam_count > hal::LaserScan::kMaxBeams) {
    return Status::error(Errc::kInvalidArgument, "scan %u: beam_count %u exceeds %u", scan.scan_id, scan.beam_count,
                         hal::LaserScan::kMaxBeams);
  }
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment) || scan.angle_increment == 0.0f) {
    return Status::error(Errc::kInvalidArgument, "scan %u: bad angle_min/angle_increment (%g, %g)", scan.scan_id,
                         static_cast<double>(scan.angle_min), static_cast<double>(scan.angle_increment));
  }
  if (!(scan.range_max > 0.0f) || !std::isfinite(scan.range_max)) {
    return Status::error(Errc::kInvalidArgument, "scan %u: bad range_max %g", scan.scan_id,
                         static_cast<double>(scan.range_max));
  }
  const float max_r = options.max_range > 0.0f && options.max_range < scan.range_max ? options.max_range : scan.range_max;
  const std::uint32_t stride = options.stride == 0 ? 1 : options.stride;
  for (std::uint32_t i = 0; i < scan.beam_count; i += stride) {
    const float r = scan.ranges[i];
    if (!std::isfinite(r) || r < 0.0f) { ++result->invalid; continue; }
    if (r < scan.range_min || r >= max_r) { ++result->out_of_range; continue; }
    if (result->count == capacity) {
      return Status::error(Errc::kCapacityExceeded, "scan %u: more than %zu valid points", scan.scan_id, capacity);
    }
    const float a = scan.angle_min + static_cast<float>(i) * scan.angle_increment;
    out[result->count++] = Point2f(r * std::cos(a), r * std::sin(a));
  }
  return Status::ok();
}

}  // namespace fw
