#include "firmware/map/nearest_distance_batch.h"

#include <bit>
#include <cstdint>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MMLFW_WIDE_NEAREST_BATCH 1
#endif

namespace fw {

namespace {

void nearest_scalar(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty, float outside,
                    float* d) {
  for (std::size_t i = 0; i < n; ++i) d[i] = map.distance_at(tx + points[i].x(), ty + points[i].y(), outside);
}

// Two loops: the cell coordinates and the bounds test (branch-free, vectorised; off the grid reads
// cell (0, 0) and is masked), then the tiled field's look-ups one point at a time.
__attribute__((always_inline)) inline void nearest_kernel(const GlobalMap& map, const Point2f* points, std::size_t n,
                                                           float tx, float ty, float outside, float* d) {
  const DistanceField f = map.distance;  // a copy: its pointers stay in registers across the stores below
  const float res = map.geometry.resolution, ox = map.geometry.origin_x, oy = map.geometry.origin_y;
  const float w = static_cast<float>(map.geometry.width), h = static_cast<float>(map.geometry.height);
  alignas(32) std::int32_t ix[kDistanceBatch], iy[kDistanceBatch], inside[kDistanceBatch];
  for (std::size_t i = 0; i < n; ++i) {
    float fx = (tx + points[i].x() - ox) / res, fy = (ty + points[i].y() - oy) / res;
    // floor(v) ≥ 0 ⇔ v ≥ 0 and floor(v) < w ⇔ v < w (w an integer); NaN compares false: outside.
    const std::int32_t in = static_cast<std::int32_t>(fx >= 0.0f) & static_cast<std::int32_t>(fy >= 0.0f) &
                            static_cast<std::int32_t>(fx < w) & static_cast<std::int32_t>(fy < h);
    fx = std::bit_cast<float>(std::bit_cast<std::int32_t>(fx) & -in);
    fy = std::bit_cast<float>(std::bit_cast<std::int32_t>(fy) & -in);
    ix[i] = static_cast<std::int32_t>(fx);  // = floor: fx ≥ 0 here
    iy[i] = static_cast<std::int32_t>(fy);
    inside[i] = in;
  }
  for (std::size_t i = 0; i < n; ++i) d[i] = inside[i] != 0 ? f.at(ix[i], iy[i]) : outside;
}

void nearest_portable(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty, float outside,
                      float* d) {
  nearest_kernel(map, points, n, tx, ty, outside, d);
}

#ifdef MMLFW_WIDE_NEAREST_BATCH
__attribute__((target("avx2"))) void nearest_avx2(const GlobalMap& map, const Point2f* points, std::size_t n,
                                                   float tx, float ty, float outside, float* d) {
  nearest_kernel(map, points, n, tx, ty, outside, d);
}
#endif

}  // namespace

void nearest_distance_batch(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty,
                            float outside, float* d, DistanceBatchBuild build) {
  if (n > kDistanceBatch) n = kDistanceBatch;
  switch (build) {
    case DistanceBatchBuild::kScalar:
      nearest_scalar(map, points, n, tx, ty, outside, d);
      return;
    case DistanceBatchBuild::kBest:
#ifdef MMLFW_WIDE_NEAREST_BATCH
      if (wide_distance_batch_available()) {
        nearest_avx2(map, points, n, tx, ty, outside, d);
        return;
      }
#endif
      [[fallthrough]];
    case DistanceBatchBuild::kPortable:
      nearest_portable(map, points, n, tx, ty, outside, d);
      return;
  }
}

}  // namespace fw
