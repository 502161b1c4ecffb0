// Bilinear sample of the global map's distance field between cell centres, with its gradient
// (metres, per metre). Float for the per-scan pose refiner; double where a finite-difference
// gradient check needs the resolution (local map correction, Eq. 5.26 / App. D).
#pragma once

#include <cstdint>

#include "firmware/map/global_map.h"

namespace fw {

// The grid's constants held once for a loop over many end-points (the refiners sample ~10⁵ times per
// scan): the reciprocal of the resolution replaces four divisions per sample by one per loop.
template <typename T>
class DistanceSampler {
 public:
  explicit DistanceSampler(const GlobalMap& m)
      : m_(m),
        inv_(T(1) / static_cast<T>(m.geometry.resolution)),
        ox_(static_cast<T>(m.geometry.origin_x)),
        oy_(static_cast<T>(m.geometry.origin_y)),
        max_fx_(static_cast<T>(m.geometry.width) - T(1)),
        max_fy_(static_cast<T>(m.geometry.height) - T(1)) {}

  // False off the grid (the outermost half cell included).
  bool operator()(T x, T y, T* d, T* gx, T* gy) const {
    const T fx = (x - ox_) * inv_ - T(0.5), fy = (y - oy_) * inv_ - T(0.5);
    if (!(fx >= T(0) && fy >= T(0) && fx < max_fx_ && fy < max_fy_)) return false;
    const std::int32_t ix = static_cast<std::int32_t>(fx), iy = static_cast<std::int32_t>(fy);
    const T ax = fx - static_cast<T>(ix), ay = fy - static_cast<T>(iy);
    float c[4];
    m_.distance.corners(ix, iy, c);
    const T d00 = c[0], d10 = c[1], d01 = c[2], d11 = c[3];
    *d = (1 - ax) * (1 - ay) * d00 + ax * (1 - ay) * d10 + (1 - ax) * ay * d01 + ax * ay * d11;
    *gx = ((1 - ay) * (d10 - d00) + ay * (d11 - d01)) * inv_;
    *gy = ((1 - ax) * (d01 - d00) + ax * (d11 - d10)) * inv_;
    return true;
  }

 private:
  const GlobalMap& m_;
  T inv_, ox_, oy_, max_fx_, max_fy_;
};

// One sample (same arithmetic as DistanceSampler). False off the grid.
template <typename T>
bool sample_distance(const GlobalMap& m, T x, T y, T* d, T* gx, T* gy) {
  return DistanceSampler<T>(m)(x, y, d, gx, gy);
}

}  // namespace fw
