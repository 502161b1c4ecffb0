// MapView over a loaded GlobalMap (firmware/map/global_map.h): same grid convention (row 0 =
// lowest y, origin = outer corner of cell (0,0)), no copy.
#pragma once

#include "firmware/map/global_map.h"
#include "firmware/baselines/mcl/map_view.h"

namespace fw {
namespace mcl {

inline MapView map_view_from_global(const GlobalMap& g) {
  MapView v;
  v.resolution = g.geometry.resolution;
  v.origin_x = g.geometry.origin_x;
  v.origin_y = g.geometry.origin_y;
  v.width = g.geometry.width;
  v.height = g.geometry.height;
  v.occupancy = g.occupancy;
  v.distance = g.distance;
  return v;
}

}  // namespace mcl
}  // namespace fw
