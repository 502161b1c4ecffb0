// OccupancyTiles: the global map's occupancy codes stored only in the 16 × 16-cell tiles that hold a
// known cell (issue 14). Most of a building's bounding box is unknown space (fr-clinic: 28 % of its
// 106 000 m² box is mapped); a tile without a known cell is one index entry that reads "unknown".
// Lookups equal the dense grid's cell for cell. A view, like GlobalMap: the arrays live in the
// start-up arena (or a test's vectors).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {

struct OccupancyTiles {
  static constexpr std::uint32_t kTileLog2 = 4;
  static constexpr std::uint32_t kTileSide = 1u << kTileLog2;
  static constexpr std::uint32_t kTileCells = kTileSide * kTileSide;
  static constexpr std::uint32_t kNoTile = 0xffffffffu;  // tile_slot: every cell unknown
  static constexpr std::uint8_t kUnknown = 255;           // = kCellUnknown (global_map.h)

  const std::uint32_t* tile_slot = nullptr;  // tiles_x·tiles_y, row-major: stored tile or kNoTile
  const std::uint8_t* cells = nullptr;       // stored_tiles·256 codes
  std::uint32_t tiles_x = 0, tiles_y = 0, stored_tiles = 0;

  bool valid() const { return tile_slot != nullptr && tiles_x > 0 && tiles_y > 0; }
  // Code of cell (cx, cy), which must lie inside the grid.
  std::uint8_t at(std::int32_t cx, std::int32_t cy) const {
    const std::uint32_t x = static_cast<std::uint32_t>(cx), y = static_cast<std::uint32_t>(cy);
    const std::uint32_t slot = tile_slot[(y >> kTileLog2) * tiles_x + (x >> kTileLog2)];
    if (slot == kNoTile) return kUnknown;
    return cells[(static_cast<std::size_t>(slot) << (2 * kTileLog2)) | ((y & (kTileSide - 1)) << kTileLog2) |
                 (x & (kTileSide - 1))];
  }
  std::size_t bytes() const {
    return static_cast<std::size_t>(tiles_x) * tiles_y * sizeof(std::uint32_t) +
           static_cast<std::size_t>(stored_tiles) * kTileCells;
  }
};

struct OccupancyTilesLayout {
  std::uint32_t width = 0, height = 0;
  std::uint32_t tiles_x = 0, tiles_y = 0, stored_tiles = 0;
  std::size_t slot_count() const { return static_cast<std::size_t>(tiles_x) * tiles_y; }
  std::size_t cell_count() const { return static_cast<std::size_t>(stored_tiles) * OccupancyTiles::kTileCells; }
  std::size_t bytes() const { return slot_count() * sizeof(std::uint32_t) + cell_count(); }
};

// Counts the tiles of a dense w×h grid of codes (row-major, row 0 = lowest y) that hold a known cell.
Status plan_occupancy_tiles(const std::uint8_t* codes, std::uint32_t width, std::uint32_t height,
                            OccupancyTilesLayout* out);
// Fills caller storage (layout.slot_count() slots, layout.cell_count() codes) from the same grid;
// the padding of edge tiles reads unknown.
OccupancyTiles fill_occupancy_tiles(const OccupancyTilesLayout& layout, const std::uint8_t* codes,
                                    std::uint32_t* slots, std::uint8_t* cells);
OccupancyTiles occupancy_tiles_view(const OccupancyTilesLayout& layout, const std::uint32_t* slots,
                                    const std::uint8_t* cells);

}  // namespace fw
