// NearestDistanceBatch: GlobalMap::distance_at (the distance of the cell an end-point falls in, no
// interpolation) for up to kDistanceBatch translated end-points at once — the inner loop of the
// tracker's correlative pre-search (firmware/track/correlative_search.cpp: up to 6,000 candidates ×
// 90 end-points on a scan in doubt, the longest sensor steps at 75 Hz: fr079 12.4 ms for 5,491
// candidates on the 2-core VM of 2026-12-02, against the 13.3 ms scan period).
//
// The cell coordinates (a subtraction and a division per axis, the bounds test) run in a vectorised
// loop — 4 lanes portable, 8 with AVX2 chosen at run time, as distance_batch.h — and only the tiled
// field's look-ups one point at a time. Each lane does distance_at's IEEE operations in its order
// (x + px, then (x − origin) / resolution; truncation equals floor on the non-negative values the
// bounds test lets through), so every build returns distance_at's bits (nearest_distance_batch_test)
// and the search picks the same candidate as before, on every machine.
#pragma once

#include <cstddef>

#include "firmware/base/se2.h"
#include "firmware/map/distance_batch.h"
#include "firmware/map/global_map.h"

namespace fw {

// d[i] = map.distance_at(tx + points[i].x(), ty + points[i].y(), outside) for i < n (n ≤
// kDistanceBatch; larger n is cut to it). `d` holds ≥ n entries.
void nearest_distance_batch(const GlobalMap& map, const Point2f* points, std::size_t n, float tx, float ty,
                            float outside, float* d, DistanceBatchBuild build = DistanceBatchBuild::kBest);

}  // namespace fw
