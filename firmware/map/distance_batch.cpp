#include "firmware/map/distance_batch.h"

#include <bit>

#include "firmware/map/distance_sample.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define MMLFW_WIDE_DISTANCE_BATCH 1
#endif

namespace fw {

namespace {

void sample_scalar(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty, float c, float s,
                   float clip_m, DistanceBatch* out) {
  const DistanceSampler<float> sample(map);
  for (std::size_t i = 0; i < n; ++i) {
    const float px = points[i].x(), py = points[i].y();
    const float qx = tx + c * px - s * py, qy = ty + s * px + c * py;
    float d = 0.0f, gx = 0.0f, gy = 0.0f;
    const bool ok = sample(qx, qy, &d, &gx, &gy);
    out->d[i] = d;
    out->gx[i] = gx;
    out->gy[i] = gy;
    out->jt[i] = gx * (-s * px - c * py) + gy * (c * px - s * py);
    out->use[i] = ok && !(d > clip_m) ? 1 : 0;
  }
}

// Three loops over the batch: the transform, cell coordinates and tile addresses (branch-free,
// vectorised), the 2×2 corner look-up (DistanceField::corners_in_tile, or corners at a tile's edge;
// one point at a time: the tiled field needs scattered
// loads, and AVX2 gathers of all of them were slower than these loads on the AMD EPYC this was
// measured on), the interpolation and the Jacobian column (vectorised). Every value is computed by
// DistanceSampler's expression in its order, so each lane gives the scalar bits.
__attribute__((always_inline)) inline void sample_kernel(const GlobalMap& map, const Point2f* points, std::size_t n,
                                                          float tx, float ty, float c, float s, float clip_m,
                                                          DistanceBatch* out) {
  const DistanceField f = map.distance;  // a copy: its pointers stay in registers across the stores below
  const float inv = 1.0f / map.geometry.resolution, ox = map.geometry.origin_x, oy = map.geometry.origin_y;
  const float max_fx = static_cast<float>(map.geometry.width) - 1.0f;
  const float max_fy = static_cast<float>(map.geometry.height) - 1.0f;
  alignas(32) float px[kDistanceBatch], py[kDistanceBatch], ax[kDistanceBatch], ay[kDistanceBatch];
  alignas(32) std::int32_t ix[kDistanceBatch], iy[kDistanceBatch];
  // The corners in one block (c00 = cs[0], c10 = cs[1], c01 = cs[2], c11 = cs[3]): one base address
  // for the four stores of the look-up loop, where four arrays kept the compiler reloading their
  // addresses from the stack at every point.
  alignas(32) float cs[4][kDistanceBatch];
  float* const c00 = cs[0];
  float* const c10 = cs[1];
  float* const c01 = cs[2];
  float* const c11 = cs[3];
  alignas(32) std::int32_t inside[kDistanceBatch];
  // Where the look-up loop reads a block: its tile and first cell in it (DistanceField::corners_in_tile)
  // and whether it straddles a tile edge (then DistanceField::corners), computed in the vectorised
  // loop so that the scalar one only loads.
  alignas(32) std::uint32_t tile[kDistanceBatch], offset[kDistanceBatch];
  alignas(32) std::int32_t edge[kDistanceBatch];
  constexpr std::uint32_t kLog2 = DistanceField::kTileLog2, kMask = DistanceField::kTileSide - 1;
  for (std::size_t i = 0; i < n; ++i) {
    px[i] = points[i].x();
    py[i] = points[i].y();
  }
  for (std::size_t i = 0; i < n; ++i) {
    const float qx = tx + c * px[i] - s * py[i], qy = ty + s * px[i] + c * py[i];
    float fx = (qx - ox) * inv - 0.5f, fy = (qy - oy) * inv - 0.5f;
    // NaN compares false: outside, as DistanceSampler's !(fx >= 0 && …).
    const std::int32_t in = static_cast<std::int32_t>(fx >= 0.0f) & static_cast<std::int32_t>(fy >= 0.0f) &
                            static_cast<std::int32_t>(fx < max_fx) & static_cast<std::int32_t>(fy < max_fy);
    // Off the grid: +0 (cell (0, 0), read and masked). A bit mask, not a branch, so the loop vectorises.
    fx = std::bit_cast<float>(std::bit_cast<std::int32_t>(fx) & -in);
    fy = std::bit_cast<float>(std::bit_cast<std::int32_t>(fy) & -in);
    ix[i] = static_cast<std::int32_t>(fx);
    iy[i] = static_cast<std::int32_t>(fy);
    ax[i] = fx - static_cast<float>(ix[i]);
    ay[i] = fy - static_cast<float>(iy[i]);
    inside[i] = in;
    const std::uint32_t ux = static_cast<std::uint32_t>(ix[i]), uy = static_cast<std::uint32_t>(iy[i]);
    tile[i] = (uy >> kLog2) * f.tiles_x + (ux >> kLog2);
    offset[i] = ((uy & kMask) << kLog2) | (ux & kMask);
    edge[i] = static_cast<std::int32_t>((ux & kMask) == kMask) | static_cast<std::int32_t>((uy & kMask) == kMask);
  }
  for (std::size_t i = 0; i < n; ++i) {
    float cc[4];
    if (edge[i] == 0) {
      f.corners_in_tile(tile[i], offset[i], cc);
    } else {
      f.corners(ix[i], iy[i], cc);
    }
    c00[i] = cc[0];
    c10[i] = cc[1];
    c01[i] = cc[2];
    c11[i] = cc[3];
  }
  for (std::size_t i = 0; i < n; ++i) {
    const float a = ax[i], b = ay[i], d00 = c00[i], d10 = c10[i], d01 = c01[i], d11 = c11[i];
    const float d = (1 - a) * (1 - b) * d00 + a * (1 - b) * d10 + (1 - a) * b * d01 + a * b * d11;
    const float gx = ((1 - b) * (d10 - d00) + b * (d11 - d01)) * inv;
    const float gy = ((1 - a) * (d01 - d00) + a * (d11 - d10)) * inv;
    out->d[i] = d;
    out->gx[i] = gx;
    out->gy[i] = gy;
    out->jt[i] = gx * (-s * px[i] - c * py[i]) + gy * (c * px[i] - s * py[i]);
    out->use[i] = static_cast<std::uint8_t>(inside[i] & static_cast<std::int32_t>(!(d > clip_m)));
  }
}

void sample_portable(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty, float c, float s,
                     float clip_m, DistanceBatch* out) {
  sample_kernel(map, points, n, tx, ty, c, s, clip_m, out);
}

#ifdef MMLFW_WIDE_DISTANCE_BATCH
__attribute__((target("avx2"))) void sample_avx2(const GlobalMap& map, const Point2f* points, std::size_t n, float tx,
                                                  float ty, float c, float s, float clip_m, DistanceBatch* out) {
  sample_kernel(map, points, n, tx, ty, c, s, clip_m, out);
}
#endif

}  // namespace

bool wide_distance_batch_available() {
#ifdef MMLFW_WIDE_DISTANCE_BATCH
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

void sample_distance_batch(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty, float c,
                           float s, float clip_m, DistanceBatch* out, DistanceBatchBuild build) {
  if (n > kDistanceBatch) n = kDistanceBatch;
  switch (build) {
    case DistanceBatchBuild::kScalar:
      sample_scalar(map, points, n, tx, ty, c, s, clip_m, out);
      return;
    case DistanceBatchBuild::kBest:
#ifdef MMLFW_WIDE_DISTANCE_BATCH
      if (wide_distance_batch_available()) {
        sample_avx2(map, points, n, tx, ty, c, s, clip_m, out);
        return;
      }
#endif
      [[fallthrough]];
    case DistanceBatchBuild::kPortable:
      sample_portable(map, points, n, tx, ty, c, s, clip_m, out);
      return;
  }
}

}  // namespace fw
