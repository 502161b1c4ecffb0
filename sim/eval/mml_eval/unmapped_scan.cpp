#include "sim/eval/mml_eval/unmapped_scan.h"

#include <cmath>

namespace sim::mmleval {

UnmappedScan unmapped_scan(const fw::GlobalMap& map, const CarmenScan& scan, const fw::Se2d& pose,
                           const UnmappedScanOptions& opt) {
  UnmappedScan u;
  if (!map.valid()) return u;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  for (std::size_t k = 0; k < scan.ranges.size(); ++k) {
    const float r = scan.ranges[k];
    // As the tracker reads a scan (firmware/scan/scan_points.cpp; to_laser_scan's range_min 0.01 m).
    const float max_r = scan.max_range > 0.0f && scan.max_range < opt.max_range_m ? scan.max_range : opt.max_range_m;
    if (!std::isfinite(r) || r < 0.01f || r >= max_r) continue;
    const double a = scan.angle_min + static_cast<double>(k) * scan.angle_increment;
    const double px = r * std::cos(a), py = r * std::sin(a);
    const float wx = static_cast<float>(pose.x + c * px - s * py), wy = static_cast<float>(pose.y + s * px + c * py);
    ++u.points;
    if (map.distance_at(wx, wy, INFINITY) <= opt.wall_m) {  // a mapped wall explains it
      ++u.explained;
      continue;
    }
    std::int32_t cx = 0, cy = 0;
    if (!map.geometry.world_to_cell(wx, wy, &cx, &cy) || map.cell(cx, cy) == fw::kCellUnknown) ++u.unmapped;
  }
  return u;
}

bool in_unmapped_area(const UnmappedScan& u, const UnmappedScanOptions& opt) {
  return u.points > 0 && u.fraction() > opt.max_fraction;
}

bool reference_off_map(const UnmappedScan& u, const UnmappedScanOptions& opt) {
  return u.points > 0 && !in_unmapped_area(u, opt) && u.explained_fraction() < opt.max_fraction;
}

}  // namespace sim::mmleval
