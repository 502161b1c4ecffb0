// Known answers for the tiled occupancy (occupancy_tiles.h): every lookup equals the dense grid,
// tiles without a known cell are not stored and read unknown, edge tiles are padded with unknown.
#include "firmware/map/occupancy_tiles.h"

#include <gtest/gtest.h>

#include <vector>

#include "firmware/map/global_map.h"

namespace fw {
namespace {

TEST(OccupancyTilesTest, LookupsEqualTheDenseGridAndUnknownTilesAreNotStored) {
  // 50 × 35 cells (4 × 3 tiles, the last column and row partly outside the grid), unknown except a
  // free room with walls in the lower-left tiles and one free cell at the far corner.
  const std::uint32_t w = 50, h = 35;
  std::vector<std::uint8_t> occ(w * h, kCellUnknown);
  for (std::uint32_t y = 2; y < 20; ++y) {
    for (std::uint32_t x = 2; x < 20; ++x) occ[y * w + x] = (x == 2 || y == 2) ? kCellOccupied : kCellFree;
  }
  occ[34 * w + 49] = kCellFree;
  occ[5 * w + 7] = 42;  // a scaled value (ROS `mode: scale`) survives as it is
  OccupancyTilesLayout l;
  ASSERT_TRUE(plan_occupancy_tiles(occ.data(), w, h, &l).is_ok());
  EXPECT_EQ(l.tiles_x, 4u);
  EXPECT_EQ(l.tiles_y, 3u);
  EXPECT_EQ(l.stored_tiles, 5u);  // (0,0), (1,0), (0,1), (1,1) hold the room; (3,2) the corner cell
  EXPECT_EQ(l.bytes(), 12u * 4u + 5u * 256u);  // vs 1750 bytes dense: a tiny map gains nothing
  std::vector<std::uint32_t> slots(l.slot_count());
  std::vector<std::uint8_t> cells(l.cell_count());
  const OccupancyTiles t = fill_occupancy_tiles(l, occ.data(), slots.data(), cells.data());
  ASSERT_TRUE(t.valid());
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      ASSERT_EQ(t.at(static_cast<std::int32_t>(x), static_cast<std::int32_t>(y)), occ[y * w + x]) << x << "," << y;
    }
  }
  EXPECT_EQ(slots[2], OccupancyTiles::kNoTile);  // tile (2, 0): unknown only
  EXPECT_EQ(t.at(40, 5), kCellUnknown);
  EXPECT_EQ(t.at(49, 34), kCellFree);
  EXPECT_EQ(t.at(7, 5), 42);
  // The padding of the corner tile (outside the grid) reads unknown.
  EXPECT_EQ(cells[4 * 256 + (15 << 4) + 15], kCellUnknown);
}

TEST(OccupancyTilesTest, AllUnknownGridStoresNothingAndEmptyGridIsRefused) {
  const std::vector<std::uint8_t> occ(40 * 40, kCellUnknown);
  OccupancyTilesLayout l;
  ASSERT_TRUE(plan_occupancy_tiles(occ.data(), 40, 40, &l).is_ok());
  EXPECT_EQ(l.stored_tiles, 0u);
  std::vector<std::uint32_t> slots(l.slot_count());
  const OccupancyTiles t = fill_occupancy_tiles(l, occ.data(), slots.data(), nullptr);
  EXPECT_EQ(t.at(39, 39), kCellUnknown);
  EXPECT_FALSE(plan_occupancy_tiles(occ.data(), 0, 40, &l).is_ok());
  EXPECT_FALSE(plan_occupancy_tiles(nullptr, 40, 40, &l).is_ok());
}

}  // namespace
}  // namespace fw
