// Bilinear sample of the global map's distance field between cell centres, with its gradient
// (metres, per metre). Float for the per-scan pose refiner; double where a finite-difference
// gradient check needs the resolution (local map correction, Eq. 5.26 / App. D).
#pragma once

#include <cstdint>

#include "firmware/map/global_map.h"

namespace fw {

// False off the grid (the outermost half cell included).
template <typename T>
bool sample_distance(const GlobalMap& m, T x, T y, T* d, T* gx, T* gy) {
  const GridGeometry& g = m.geometry;
  const T res = static_cast<T>(g.resolution);
  const T fx = (x - static_cast<T>(g.origin_x)) / res - T(0.5), fy = (y - static_cast<T>(g.origin_y)) / res - T(0.5);
  if (!(fx >= T(0) && fy >= T(0) && fx < static_cast<T>(g.width) - T(1) && fy < static_cast<T>(g.height) - T(1))) {
    return false;
  }
  const std::int32_t ix = static_cast<std::int32_t>(fx), iy = static_cast<std::int32_t>(fy);
  const T ax = fx - static_cast<T>(ix), ay = fy - static_cast<T>(iy);
  float c[4];
  m.distance.corners(ix, iy, c);
  const T d00 = c[0], d10 = c[1], d01 = c[2], d11 = c[3];
  *d = (1 - ax) * (1 - ay) * d00 + ax * (1 - ay) * d10 + (1 - ax) * ay * d01 + ax * ay * d11;
  *gx = ((1 - ay) * (d10 - d00) + ay * (d11 - d01)) / res;
  *gy = ((1 - ax) * (d01 - d00) + ax * (d11 - d10)) / res;
  return true;
}

}  // namespace fw
