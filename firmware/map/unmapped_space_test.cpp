// Known answers for unmapped space (unmapped_space.h): an unknown room inside the building is
// unmapped space; the unknown margin and a notch open to it are outside the map; a pillar smaller
// than the minimum area is not; bad options are refused by name.
#include "firmware/map/unmapped_space.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "firmware/map/distance_field.h"
#include "firmware/map/occupancy_tiles.h"

namespace fw {
namespace {

// 10 × 8 m at 5 cm: unknown margin of 10 cells; a walled building of free cells; inside it a walled
// unknown room (cells 50..90, its unknown inside 51..89) and an unknown pillar (120..129); the
// building's top-right corner is a notch of unknown open to the margin.
struct TestBuilding {
  static constexpr std::uint32_t w = 200, h = 160;
  std::vector<std::uint8_t> occ = std::vector<std::uint8_t>(w * h, kCellUnknown);
  OccupancyTilesLayout tl;
  std::vector<std::uint32_t> tslots;
  std::vector<std::uint8_t> tcells;
  DistanceFieldLayout dl;
  std::vector<std::uint32_t> dslots;
  std::vector<std::uint16_t> dcells;
  std::vector<float> dtable;
  GlobalMap map;

  void set(std::uint32_t x0, std::uint32_t y0, std::uint32_t x1, std::uint32_t y1, std::uint8_t v) {
    for (std::uint32_t y = y0; y <= y1; ++y) {
      for (std::uint32_t x = x0; x <= x1; ++x) occ[y * w + x] = v;
    }
  }
  TestBuilding() {
    set(10, 10, 189, 149, kCellOccupied);
    set(11, 11, 188, 148, kCellFree);
    set(150, 100, 199, 159, kCellUnknown);  // the notch, open to the margin
    set(50, 50, 90, 90, kCellOccupied);
    set(51, 51, 89, 89, kCellUnknown);      // the unmapped room, 1.95 m square
    set(120, 20, 129, 29, kCellUnknown);    // a pillar, 0.5 m square
    build();
  }
  void build() {
    ASSERT_TRUE(plan_occupancy_tiles(occ.data(), w, h, &tl).is_ok());
    tslots.assign(tl.slot_count(), 0);
    tcells.assign(tl.cell_count(), 0);
    std::vector<float> metres(w * h, 1.0f);
    ASSERT_TRUE(plan_distance_field(metres.data(), w, h, 0.05f, 0.3f, &dl).is_ok());
    dslots.assign(dl.slot_count(), 0);
    dcells.assign(dl.cell_count(), 0);
    dtable.assign(dl.table_count(), 0.0f);
    map.geometry.resolution = 0.05f;
    map.geometry.origin_x = -2.0f;
    map.geometry.origin_y = 1.0f;
    map.geometry.width = w;
    map.geometry.height = h;
    map.occupancy = fill_occupancy_tiles(tl, occ.data(), tslots.data(), tcells.data());
    map.distance = fill_distance_field(dl, metres.data(), dslots.data(), dcells.data(), dtable.data());
  }
  // World position of a cell's centre.
  float x(std::uint32_t cx) const { return -2.0f + (static_cast<float>(cx) + 0.5f) * 0.05f; }
  float y(std::uint32_t cy) const { return 1.0f + (static_cast<float>(cy) + 0.5f) * 0.05f; }
};

struct Arena {
  alignas(64) std::uint8_t block[1 << 16];
  StartupArena arena;
  Arena() { EXPECT_TRUE(arena.init(block, sizeof block).is_ok()); }
};

TEST(UnmappedSpaceTest, AnUnknownRoomInsideIsUnmappedTheMarginNotchAndPillarAreNot) {
  TestBuilding b;
  Arena a;
  UnmappedSpace u;
  ASSERT_TRUE(u.build(b.map, UnmappedSpaceOptions{}, a.arena).is_ok());
  EXPECT_FLOAT_EQ(u.block_m(), 0.25f);
  EXPECT_EQ(u.unmapped_blocks(), 49u);  // blocks of cells 55..89 on both axes: 7 × 7 fully unknown
  EXPECT_TRUE(u.contains(b.x(70), b.y(70)));
  EXPECT_TRUE(u.contains(b.x(56), b.y(88)));
  EXPECT_FALSE(u.contains(b.x(52), b.y(70)));   // a block touching the room's wall is not all unknown
  EXPECT_FALSE(u.contains(b.x(125), b.y(25)));  // the pillar: 0.25 m² < 1 m²
  EXPECT_FALSE(u.contains(b.x(175), b.y(140))); // the notch is outside, though walls bound two sides
  EXPECT_FALSE(u.contains(b.x(3), b.y(3)));     // the margin
  EXPECT_FALSE(u.contains(b.x(30), b.y(30)));   // free space
  EXPECT_FALSE(u.contains(-100.0f, 5.0f));      // off the map
}

TEST(UnmappedSpaceTest, AGapToTheOutsideMakesTheRoomOutsideAndASmallMinimumCountsThePillar) {
  TestBuilding b;
  b.set(0, 65, 51, 75, kCellUnknown);  // a corridor of unknown from the margin through both walls
  b.build();
  Arena a;
  UnmappedSpace u;
  ASSERT_TRUE(u.build(b.map, UnmappedSpaceOptions{0.25f, 0.2f}, a.arena).is_ok());
  EXPECT_FALSE(u.contains(b.x(70), b.y(70)));  // reached from the border: outside the map
  EXPECT_TRUE(u.contains(b.x(125), b.y(25)));   // 4 blocks ≥ 0.2 m²
  EXPECT_EQ(u.unmapped_blocks(), 4u);
}

TEST(UnmappedSpaceTest, BadOptionsAreRefusedByName) {
  TestBuilding b;
  Arena a;
  UnmappedSpace u;
  const Status s = u.build(b.map, UnmappedSpaceOptions{0.0f, 1.0f}, a.arena);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("unmapped space"), std::string::npos);
  EXPECT_FALSE(u.build(b.map, UnmappedSpaceOptions{0.25f, 500.0f}, a.arena).is_ok());
  EXPECT_FALSE(u.contains(b.x(70), b.y(70)));  // nothing built
}

}  // namespace
}  // namespace fw
