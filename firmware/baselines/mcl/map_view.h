// MapView: the read-only grid MCL (and MML's contact test) needs: occupancy and the distance
// image (metres to the nearest occupied cell). Row 0 is the lowest y, as in firmware/map's
// GridGeometry; build one from a loaded GlobalMap with map_view_from_global (global_map_view.h).
#pragma once

#include <cmath>
#include <cstdint>

#include "firmware/map/distance_field.h"
#include "firmware/map/occupancy_tiles.h"

namespace fw {
namespace mcl {

struct MapView {
  float resolution = 0.05f;
  float origin_x = 0.0f, origin_y = 0.0f;  // world coordinates of cell (0,0)'s lower-left corner
  std::uint32_t width = 0, height = 0;
  OccupancyTiles occupancy;                 // 0 free, 100 occupied, 255 unknown
  DistanceField distance;                   // metres to the nearest occupied cell (truncated)

  bool valid() const { return width > 0 && height > 0 && occupancy.valid() && distance.valid() && resolution > 0.0f; }
  bool cell_of(float x, float y, int* cx, int* cy) const {
    const float fx = (x - origin_x) / resolution, fy = (y - origin_y) / resolution;
    if (!(fx >= 0.0f && fy >= 0.0f)) return false;  // also rejects NaN
    *cx = static_cast<int>(fx);
    *cy = static_cast<int>(fy);
    return *cx < static_cast<int>(width) && *cy < static_cast<int>(height);
  }
  // Distance to the nearest obstacle; `outside` when the point is off the grid.
  float distance_at(float x, float y, float outside) const {
    int cx, cy;
    if (!cell_of(x, y, &cx, &cy)) return outside;
    return distance.at(cx, cy);
  }
  std::uint8_t occupancy_at(float x, float y) const {
    int cx, cy;
    if (!cell_of(x, y, &cx, &cy)) return 255;
    return occupancy.at(cx, cy);
  }
  // Expected range along a ray by sphere tracing through the distance image (App. A: ray casting
  // accelerated with the distance image): each step advances by the free distance around the point.
  float raycast(float x, float y, float angle, float max_range) const {
    const float c = std::cos(angle), s = std::sin(angle);
    const float hit = 0.5f * resolution;
    float t = 0.0f;
    while (t < max_range) {
      const float d = distance_at(x + c * t, y + s * t, -1.0f);
      if (d < 0.0f) return max_range;  // left the map: no return
      if (d <= hit) return t;
      t += (d - hit > resolution ? d - hit : resolution);
    }
    return max_range;
  }
};

}  // namespace mcl
}  // namespace fw
