// Test helpers shared by the AntSLAM tests that work on a contact field of drawn walls.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/pransam/contact_field.h"
#include "firmware/scan/scan_points.h"

namespace fw::antslam::field_test {

// Points every 5 cm along the segment a → b.
inline void wall(float ax, float ay, float bx, float by, std::vector<Point2f>* out) {
  const float len = std::hypot(bx - ax, by - ay);
  const int n = static_cast<int>(len / 0.05f);
  for (int i = 0; i <= n; ++i) {
    const float t = static_cast<float>(i) / static_cast<float>(n);
    out->emplace_back(ax + t * (bx - ax), ay + t * (by - ay));
  }
}

// A contact field of `model` with its own arena.
struct Field {
  std::vector<unsigned char> block;
  StartupArena arena;
  pransam::ContactField<2> field;
  explicit Field(const std::vector<Point2f>& model, bool keep_distance = true) {
    pransam::ContactFieldOptions o;
    o.keep_distance = keep_distance;
    block.resize(pransam::ContactField<2>::arena_bytes(o) + 4096);
    EXPECT_TRUE(arena.init(block.data(), block.size(), "test").is_ok());
    EXPECT_TRUE(field.init(o, arena).is_ok());
    EXPECT_TRUE(field.build(model.data(), model.size(), "model").is_ok());
  }
};

}  // namespace fw::antslam::field_test
