// GlobalMap: the read-only global map every localizer (RBSM, pRANSAM, MCL) works against. It is a
// view: the arrays live in the StartupArena the map image was loaded into (firmware/map/map_image.h),
// so the struct is cheap to copy and never owns memory.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/map/grid_geometry.h"

namespace fw {

// Occupancy cell values (ROS nav_msgs/OccupancyGrid convention; 1..99 only appear for maps
// compiled from a ROS `mode: scale` image).
constexpr std::uint8_t kCellFree = 0;
constexpr std::uint8_t kCellOccupied = 100;
constexpr std::uint8_t kCellUnknown = 255;

struct GlobalMap {
  GridGeometry geometry;
  const std::uint8_t* occupancy = nullptr;  // width*height, row 0 = lowest y; 0 free, 100 occupied, 255 unknown
  const float* distance_m = nullptr;        // width*height, metres from the cell centre to the nearest
                                            // occupied cell centre (exact EDT; 0 on occupied cells)
  const Point2f* points = nullptr;          // occupied cell centres (world metres), row-major order
  std::uint32_t num_points = 0;
  float max_distance_m = 0.0f;              // largest value in distance_m

  bool valid() const { return occupancy != nullptr && distance_m != nullptr && geometry.cell_count() > 0; }
  std::uint8_t cell(std::int32_t cx, std::int32_t cy) const { return occupancy[geometry.index(cx, cy)]; }
  // Distance at the cell containing (x, y); outside the grid: `outside` (caller's choice, e.g. max).
  float distance_at(float x, float y, float outside) const {
    std::int32_t cx = 0, cy = 0;
    if (!geometry.world_to_cell(x, y, &cx, &cy)) return outside;
    return distance_m[geometry.index(cx, cy)];
  }
};

}  // namespace fw
