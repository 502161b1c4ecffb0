#include "firmware/map/occupancy_tiles.h"

#include <cstring>

namespace fw {
namespace {

constexpr std::uint32_t kSide = OccupancyTiles::kTileSide;

bool tile_has_known(const std::uint8_t* codes, std::uint32_t w, std::uint32_t h, std::uint32_t tx, std::uint32_t ty) {
  const std::uint32_t y1 = (ty + 1) * kSide < h ? (ty + 1) * kSide : h;
  const std::uint32_t x1 = (tx + 1) * kSide < w ? (tx + 1) * kSide : w;
  for (std::uint32_t y = ty * kSide; y < y1; ++y) {
    for (std::uint32_t x = tx * kSide; x < x1; ++x) {
      if (codes[static_cast<std::size_t>(y) * w + x] != OccupancyTiles::kUnknown) return true;
    }
  }
  return false;
}

}  // namespace

Status plan_occupancy_tiles(const std::uint8_t* codes, std::uint32_t w, std::uint32_t h, OccupancyTilesLayout* out) {
  if (w == 0 || h == 0 || codes == nullptr) {
    return Status::error(Errc::kInvalidArgument, "occupancy tiles: empty grid (%ux%u)", w, h);
  }
  OccupancyTilesLayout l;
  l.width = w;
  l.height = h;
  l.tiles_x = (w + kSide - 1) / kSide;
  l.tiles_y = (h + kSide - 1) / kSide;
  for (std::uint32_t ty = 0; ty < l.tiles_y; ++ty) {
    for (std::uint32_t tx = 0; tx < l.tiles_x; ++tx) l.stored_tiles += tile_has_known(codes, w, h, tx, ty) ? 1 : 0;
  }
  *out = l;
  return Status::ok();
}

OccupancyTiles fill_occupancy_tiles(const OccupancyTilesLayout& l, const std::uint8_t* codes, std::uint32_t* slots,
                                    std::uint8_t* cells) {
  std::uint32_t next = 0;
  for (std::uint32_t ty = 0; ty < l.tiles_y; ++ty) {
    for (std::uint32_t tx = 0; tx < l.tiles_x; ++tx) {
      std::uint32_t& slot = slots[static_cast<std::size_t>(ty) * l.tiles_x + tx];
      if (!tile_has_known(codes, l.width, l.height, tx, ty) || next >= l.stored_tiles) {
        slot = OccupancyTiles::kNoTile;
        continue;
      }
      std::uint8_t* tile = cells + static_cast<std::size_t>(next) * OccupancyTiles::kTileCells;
      std::memset(tile, OccupancyTiles::kUnknown, OccupancyTiles::kTileCells);
      for (std::uint32_t j = 0; j < kSide && ty * kSide + j < l.height; ++j) {
        const std::uint32_t y = ty * kSide + j;
        const std::uint32_t n = (tx + 1) * kSide <= l.width ? kSide : l.width - tx * kSide;
        std::memcpy(tile + j * kSide, codes + static_cast<std::size_t>(y) * l.width + tx * kSide, n);
      }
      slot = next++;
    }
  }
  return occupancy_tiles_view(l, slots, cells);
}

OccupancyTiles occupancy_tiles_view(const OccupancyTilesLayout& l, const std::uint32_t* slots,
                                    const std::uint8_t* cells) {
  OccupancyTiles t;
  t.tile_slot = slots;
  t.cells = cells;
  t.tiles_x = l.tiles_x;
  t.tiles_y = l.tiles_y;
  t.stored_tiles = l.stored_tiles;
  return t;
}

}  // namespace fw
