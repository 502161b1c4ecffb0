#include "firmware/map/grid_geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace fw {
namespace {

TEST(GridGeometryTest, WorldToCellAndBack) {
  GridGeometry g;
  g.resolution = 0.05f;
  g.origin_x = -10.0f;
  g.origin_y = -5.0f;
  g.width = 400;
  g.height = 200;
  std::int32_t cx = -1, cy = -1;
  ASSERT_TRUE(g.world_to_cell(-10.0f, -5.0f, &cx, &cy));
  EXPECT_EQ(cx, 0);
  EXPECT_EQ(cy, 0);
  ASSERT_TRUE(g.world_to_cell(0.01f, 0.07f, &cx, &cy));
  EXPECT_EQ(cx, 200);
  EXPECT_EQ(cy, 101);
  const Point2f c = g.cell_center(200, 101);
  EXPECT_NEAR(c.x(), 0.025f, 1e-5f);
  EXPECT_NEAR(c.y(), 0.075f, 1e-5f);
  EXPECT_FALSE(g.world_to_cell(-10.01f, 0.0f, &cx, &cy));
  EXPECT_FALSE(g.world_to_cell(10.0f, 0.0f, &cx, &cy));  // x = origin + width*res is outside
  EXPECT_FALSE(g.world_to_cell(0.0f, 5.0f, &cx, &cy));
  EXPECT_FALSE(g.world_to_cell(std::numeric_limits<float>::quiet_NaN(), 0.0f, &cx, &cy));
  EXPECT_FALSE(g.world_to_cell(1e30f, 0.0f, &cx, &cy));
  EXPECT_EQ(g.index(3, 2), 2u * 400u + 3u);
  // Every cell centre maps back to its own cell.
  for (std::int32_t y = 0; y < 200; y += 7) {
    for (std::int32_t x = 0; x < 400; x += 11) {
      const Point2f p = g.cell_center(x, y);
      ASSERT_TRUE(g.world_to_cell(p.x(), p.y(), &cx, &cy));
      EXPECT_EQ(cx, x);
      EXPECT_EQ(cy, y);
    }
  }
}

}  // namespace
}  // namespace fw
