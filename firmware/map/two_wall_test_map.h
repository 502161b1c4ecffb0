// Test fixture of the batch samplers' tests (distance_batch_test.cpp, nearest_distance_batch_test.cpp).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "firmware/map/distance_field.h"
#include "firmware/map/global_map.h"

namespace fw {

// A 70 × 50-cell map (5 × 4 tiles, the last row and column partly outside the grid) at 5 cm with
// two walls, truncated at 0.3 m: the tiles far from both walls are not stored.
struct TwoWallTestMap {
  DistanceFieldLayout layout;
  std::vector<std::uint32_t> slots;
  std::vector<std::uint16_t> cells;
  std::vector<float> table;
  GlobalMap map;

  TwoWallTestMap() {
    const std::uint32_t w = 70, h = 50;
    const float res = 0.05f;
    std::vector<float> metres(w * h);
    for (std::uint32_t y = 0; y < h; ++y) {
      for (std::uint32_t x = 0; x < w; ++x) {
        // Distance to the wall y = 10 (cells 0..39) and to the wall x = 55 (all rows), exact per cell.
        const float dy = x < 40 ? std::fabs(static_cast<float>(y) - 10.0f) : 1e9f;
        const float dx = std::fabs(static_cast<float>(x) - 55.0f);
        metres[y * w + x] = std::fmin(dx, dy) * res;
      }
    }
    EXPECT_TRUE(plan_distance_field(metres.data(), w, h, res, 0.3f, &layout).is_ok());
    slots.assign(layout.slot_count(), 0);
    cells.assign(layout.cell_count(), 0);
    table.assign(layout.table_count(), 0.0f);
    map.geometry.resolution = res;
    map.geometry.origin_x = -1.3f;
    map.geometry.origin_y = 0.7f;
    map.geometry.width = w;
    map.geometry.height = h;
    map.distance = fill_distance_field(layout, metres.data(), slots.data(), cells.data(), table.data());
  }
};

// Bit equality (the batch builds promise the scalar expression's bits, not only its value).
inline bool same_float_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace fw
