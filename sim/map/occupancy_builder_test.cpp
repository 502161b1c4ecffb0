#include "sim/map/occupancy_builder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace sim {
namespace {

// Range from (px,py) along angle a to the walls of the axis-aligned room [0,W]x[0,H].
float room_range(double px, double py, double a, double W, double H) {
  double best = 1e9;
  const double c = std::cos(a), s = std::sin(a);
  if (c > 1e-12) best = std::min(best, (W - px) / c);
  if (c < -1e-12) best = std::min(best, -px / c);
  if (s > 1e-12) best = std::min(best, (H - py) / s);
  if (s < -1e-12) best = std::min(best, -py / s);
  return static_cast<float>(best);
}

struct OwnedScan {
  std::vector<float> ranges;
  PosedScan posed;
};

OwnedScan room_scan(double px, double py, double th, double W, double H) {
  OwnedScan o;
  const int n = 361;
  const float amin = static_cast<float>(-M_PI / 2), inc = static_cast<float>(M_PI / 360);
  for (int i = 0; i < n; ++i) o.ranges.push_back(room_range(px, py, th + amin + i * inc, W, H));
  o.posed.pose = fw::Se2d(px, py, th);
  o.posed.angle_min = amin;
  o.posed.angle_increment = inc;
  o.posed.max_range = 80.0f;
  return o;
}

std::vector<PosedScan> views(std::vector<OwnedScan>& owned) {
  std::vector<PosedScan> v;
  for (auto& o : owned) {
    o.posed.ranges = o.ranges.data();
    o.posed.count = o.ranges.size();
    v.push_back(o.posed);
  }
  return v;
}

TEST(OccupancyBuilderTest, RoomWallsOccupiedInsideFreeOutsideUnknown) {
  const double W = 8.0, H = 5.0;
  std::vector<OwnedScan> owned;
  for (int k = 0; k < 12; ++k) owned.push_back(room_scan(1.0 + 0.5 * k, 2.5 + 0.3 * std::sin(k), 0.5 * k, W, H));
  OccupancyBuildOptions o;
  o.resolution = 0.1;
  OccupancyGrid g;
  OccupancyBuildStats st;
  std::string err;
  ASSERT_TRUE(build_occupancy_grid(views(owned), o, &g, &st, &err)) << err;
  EXPECT_EQ(st.scans, 12u);
  EXPECT_EQ(st.beams, 12u * 361u);
  EXPECT_EQ(st.hits, st.beams);
  // Grid covers the room plus the 1 m margin.
  EXPECT_NEAR(g.geometry.origin_x, -1.0f, 0.11f);
  EXPECT_NEAR(g.geometry.size_x(), W + 2.0, 0.35);
  auto at = [&](double x, double y) {
    std::int32_t cx, cy;
    EXPECT_TRUE(g.geometry.world_to_cell(static_cast<float>(x), static_cast<float>(y), &cx, &cy));
    return g.cells[g.geometry.index(cx, cy)];
  };
  // Interior is free, outside unknown.
  for (double x = 0.5; x < 7.5; x += 0.5) {
    for (double y = 0.5; y < 4.5; y += 0.5) EXPECT_EQ(at(x, y), 0) << x << "," << y;
  }
  EXPECT_EQ(at(-0.5, 2.0), 255);
  EXPECT_EQ(at(4.0, 5.6), 255);
  // Walls: along each wall, the cell just inside the boundary is occupied (endpoints land on
  // x = W exactly, which floors into the cell [W, W+res)); count wall cells.
  std::size_t wall_hits = 0, wall_cells = 0;
  for (double x = 0.25; x < 7.8; x += 0.1) {
    ++wall_cells;
    wall_hits += (at(x, 5.0 + 0.01) == 100 || at(x, 5.0 - 0.01) == 100) ? 1 : 0;
  }
  EXPECT_GE(wall_hits, wall_cells * 95 / 100);
  // No occupied cell farther than one cell from a wall.
  for (std::uint32_t cy = 0; cy < g.geometry.height; ++cy) {
    for (std::uint32_t cx = 0; cx < g.geometry.width; ++cx) {
      if (g.cells[g.geometry.index(cx, cy)] != 100) continue;
      const fw::Point2f c = g.geometry.cell_center(cx, cy);
      const double cxw = c.x(), cyw = c.y();
      const double d = std::min({std::abs(cxw), std::abs(cxw - W), std::abs(cyw), std::abs(cyw - H)});
      EXPECT_LE(d, 0.1 + 1e-4) << c.transpose();
    }
  }
}

TEST(OccupancyBuilderTest, TransientObstacleIsErasedByLaterPasses) {
  const double W = 8.0, H = 5.0;
  std::vector<OwnedScan> owned;
  // Scan 0 sees a "person" at (4.05, 2.5) straight ahead; later scans from the same place see the wall.
  owned.push_back(room_scan(1.0, 2.5, 0.0, W, H));
  owned[0].ranges[180] = 3.05f;
  owned[0].ranges[179] = 3.05f;
  for (int k = 0; k < 5; ++k) owned.push_back(room_scan(1.0, 2.5, 0.0, W, H));
  OccupancyBuildOptions o;
  o.resolution = 0.1;
  OccupancyGrid g;
  std::string err;
  ASSERT_TRUE(build_occupancy_grid(views(owned), o, &g, nullptr, &err)) << err;
  std::int32_t cx, cy;
  ASSERT_TRUE(g.geometry.world_to_cell(4.05f, 2.49f, &cx, &cy));
  EXPECT_EQ(g.cells[g.geometry.index(cx, cy)], 0);
  // With only the person scan, it is an obstacle.
  owned.resize(1);
  ASSERT_TRUE(build_occupancy_grid(views(owned), o, &g, nullptr, &err)) << err;
  ASSERT_TRUE(g.geometry.world_to_cell(4.05f, 2.49f, &cx, &cy));
  EXPECT_EQ(g.cells[g.geometry.index(cx, cy)], 100);
}

TEST(OccupancyBuilderTest, NoReturnAndInvalidReadings) {
  std::vector<OwnedScan> owned;
  owned.push_back(room_scan(4.0, 2.5, 0.0, 8.0, 5.0));
  owned[0].ranges[0] = 80.0f;                                      // no return
  owned[0].ranges[1] = std::numeric_limits<float>::quiet_NaN();    // invalid
  owned[0].ranges[2] = 0.0f;                                       // invalid
  owned[0].ranges[3] = 50.0f;                                      // beyond usable range: truncated
  OccupancyBuildOptions o;
  o.max_usable_range = 20.0;
  OccupancyGrid g;
  OccupancyBuildStats st;
  std::string err;
  ASSERT_TRUE(build_occupancy_grid(views(owned), o, &g, &st, &err)) << err;
  EXPECT_EQ(st.invalid, 3u);  // no-return is skipped by default, NaN and 0 are invalid
  EXPECT_EQ(st.truncated, 1u);
  EXPECT_EQ(st.hits, 357u);
  o.free_on_no_return = true;
  ASSERT_TRUE(build_occupancy_grid(views(owned), o, &g, &st, &err)) << err;
  EXPECT_EQ(st.no_return, 1u);
  EXPECT_EQ(st.invalid, 2u);
}

TEST(OccupancyBuilderTest, BadInputIsAnError) {
  OccupancyGrid g;
  std::string err;
  OccupancyBuildOptions o;
  EXPECT_FALSE(build_occupancy_grid({}, o, &g, nullptr, &err));
  EXPECT_NE(err.find("no scans"), std::string::npos);
  std::vector<OwnedScan> owned;
  owned.push_back(room_scan(4.0, 2.5, 0.0, 8.0, 5.0));
  owned[0].posed.pose.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(build_occupancy_grid(views(owned), o, &g, nullptr, &err));
  EXPECT_NE(err.find("non-finite pose"), std::string::npos) << err;
  owned[0].posed.pose.x = 4.0;
  o.resolution = -0.05;
  EXPECT_FALSE(build_occupancy_grid(views(owned), o, &g, nullptr, &err));
  EXPECT_NE(err.find("resolution"), std::string::npos) << err;
  o.resolution = 0.0001;
  o.max_cells = 1000000;
  EXPECT_FALSE(build_occupancy_grid(views(owned), o, &g, nullptr, &err));
  EXPECT_NE(err.find("max_cells"), std::string::npos) << err;
  o.resolution = 0.05;
  for (float& r : owned[0].ranges) r = 0.0f;
  EXPECT_FALSE(build_occupancy_grid(views(owned), o, &g, nullptr, &err));
  EXPECT_NE(err.find("no beam hit"), std::string::npos) << err;
}

}  // namespace
}  // namespace sim
