// GlobalMap: the read-only global map every localizer (RBSM, pRANSAM, MCL) works against. It is a
// view: the arrays live in the StartupArena the map image was loaded into (firmware/map/map_image.h),
// so the struct is cheap to copy and never owns memory.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "firmware/map/distance_field.h"
#include "firmware/map/grid_geometry.h"
#include "firmware/map/occupancy_tiles.h"

namespace fw {

// Occupancy cell values (ROS nav_msgs/OccupancyGrid convention; 1..99 only appear for maps
// compiled from a ROS `mode: scale` image).
constexpr std::uint8_t kCellFree = 0;
constexpr std::uint8_t kCellOccupied = 100;
constexpr std::uint8_t kCellUnknown = 255;

struct GlobalMap {
  GridGeometry geometry;
  OccupancyTiles occupancy;                 // row 0 = lowest y; 0 free, 100 occupied, 255 unknown; tiles
                                            // with a known cell only (occupancy_tiles.h)
  DistanceField distance;                   // metres from the cell centre to the nearest occupied cell
                                            // centre (exact EDT; 0 on occupied cells), truncated at
                                            // distance.truncation_m (distance_field.h)
  const Point2f* points = nullptr;          // occupied cell centres (world metres), row-major order
  std::uint32_t num_points = 0;
  float max_distance_m = 0.0f;              // largest value of the untruncated field

  bool valid() const { return occupancy.valid() && distance.valid() && geometry.cell_count() > 0; }
  std::uint8_t cell(std::int32_t cx, std::int32_t cy) const { return occupancy.at(cx, cy); }
  // Distance at the cell containing (x, y); outside the grid: `outside` (caller's choice, e.g. max).
  float distance_at(float x, float y, float outside) const {
    std::int32_t cx = 0, cy = 0;
    if (!geometry.world_to_cell(x, y, &cx, &cy)) return outside;
    return distance.at(cx, cy);
  }
  // Bilinear interpolation of the distance field between cell centres (continuous, for gradient-
  // based matching and likelihood fields); optional gradient in metres per metre. Points outside
  // the grid (or NaN) give `outside` and a zero gradient; within half a cell of the border the
  // edge values are extended.
  float distance_bilinear(float x, float y, float outside, float* grad_x = nullptr, float* grad_y = nullptr) const {
    if (grad_x != nullptr) *grad_x = 0.0f;
    if (grad_y != nullptr) *grad_y = 0.0f;
    float gx = 0.0f, gy = 0.0f;
    geometry.world_to_grid(x, y, &gx, &gy);
    const float w = static_cast<float>(geometry.width), h = static_cast<float>(geometry.height);
    if (!(gx >= 0.0f && gy >= 0.0f && gx < w && gy < h)) return outside;
    gx = std::fmin(std::fmax(gx - 0.5f, 0.0f), w - 1.0f);
    gy = std::fmin(std::fmax(gy - 0.5f, 0.0f), h - 1.0f);
    const std::int32_t x0 = static_cast<std::int32_t>(gx), y0 = static_cast<std::int32_t>(gy);
    const std::int32_t x1 = x0 + 1 < static_cast<std::int32_t>(geometry.width) ? x0 + 1 : x0;
    const std::int32_t y1 = y0 + 1 < static_cast<std::int32_t>(geometry.height) ? y0 + 1 : y0;
    const float fx = gx - static_cast<float>(x0), fy = gy - static_cast<float>(y0);
    const float d00 = distance.at(x0, y0), d10 = distance.at(x1, y0);
    const float d01 = distance.at(x0, y1), d11 = distance.at(x1, y1);
    const float a = d00 + fx * (d10 - d00), b = d01 + fx * (d11 - d01);
    if (grad_x != nullptr) *grad_x = ((1.0f - fy) * (d10 - d00) + fy * (d11 - d01)) / geometry.resolution;
    if (grad_y != nullptr) *grad_y = (b - a) / geometry.resolution;
    return a + fy * (b - a);
  }
};

}  // namespace fw
