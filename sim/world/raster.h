// Rasterization of a World into the occupancy grid the localizer is given as its global map
// (sim::OccupancyGrid of sim/io/ros_map.h, firmware GridGeometry conventions: row 0 = lowest y,
// 0 free / 100 occupied / 255 unknown). Walls are marked in every cell a wall segment passes
// through (supersampled at resolution/8); the world's unknown areas are erased to unknown, and so is
// the margin outside the building outline — the map shows the building as a mapping run would,
// without the rooms nobody mapped. Write it with grid_to_ros_map + write_ros_map, compile it with
// sim/map/map_image_writer.h.
#pragma once

#include <string>

#include "sim/io/ros_map.h"
#include "sim/world/world.h"

namespace sim {

struct RasterOptions {
  double resolution = 0;      // 0 = world.default_resolution
  double margin = 1.0;        // m of unknown around the building outline
  bool erase_unknown_areas = true;
};

// False with *err on a bad resolution or margin.
bool rasterize_world(const World& world, const RasterOptions& opt, OccupancyGrid* out, std::string* err);

}  // namespace sim
