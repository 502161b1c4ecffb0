// DistanceField: the global map's distance to the nearest occupied cell, truncated and tiled so that
// its memory grows with the mapped area instead of the bounding box (issue 14).
//
// Every consumer only distinguishes distances up to a small clip (tracker and refiner 0.15–0.6 m,
// MCL's likelihood field underflows past ~3 m, its beam model's sphere tracing stops at the beam's
// max range), so the field stores min(d, T) with T the load-time truncation. Values below T are
// exact: the squared distance in cells² (an integer for the exact EDT of occupied cell centres) is
// kept as a uint16, and at() returns sqrt(d²)·resolution — the same float expression the map writer
// and loader use, so a lookup is bit-identical to the float field it replaces. That expression is
// tabulated once per d² ≤ saturation (≤ 256 KiB; 113 KiB at 5 cm and 8.5 m): a table load instead of
// a conversion, a square root and a product on the tracker's and refiner's hot path. 16 × 16-cell tiles
// in which every cell is ≥ T are not stored at all (one index entry says "T everywhere"): most of a
// building's bounding box is unknown space far from any wall.
//
// A view (like GlobalMap): the arrays live in the start-up arena (or a test's vectors).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {

struct DistanceField {
  static constexpr std::uint32_t kTileLog2 = 4;
  static constexpr std::uint32_t kTileSide = 1u << kTileLog2;  // cells per tile side
  static constexpr std::uint32_t kTileCells = kTileSide * kTileSide;
  static constexpr std::uint32_t kNoTile = 0xffffffffu;        // tile_slot: every cell is at T
  static constexpr std::uint32_t kMaxSaturationD2 = 65535;      // uint16 cells²: T ≤ 255.99 cells

  const std::uint32_t* tile_slot = nullptr;  // tiles_x·tiles_y, row-major: stored tile or kNoTile
  const std::uint16_t* d2 = nullptr;         // stored_tiles·256 squared distances (cells²), ≤ saturation_d2
  const float* metres_of_d2 = nullptr;       // saturation_d2 + 1 entries: sqrt(float(q))·resolution
  std::uint32_t tiles_x = 0, tiles_y = 0, stored_tiles = 0;
  float resolution = 0.0f;
  std::uint32_t saturation_d2 = 0;  // cells²; a cell at or beyond it reads truncation_m
  float truncation_m = 0.0f;        // sqrt(saturation_d2)·resolution: the largest value at() returns

  bool valid() const {
    return tile_slot != nullptr && metres_of_d2 != nullptr && tiles_x > 0 && tiles_y > 0 && resolution > 0.0f;
  }
  // Metres at cell (cx, cy), which must lie inside the grid the field was built for.
  float at(std::int32_t cx, std::int32_t cy) const {
    const std::uint32_t x = static_cast<std::uint32_t>(cx), y = static_cast<std::uint32_t>(cy);
    const std::uint32_t slot = tile_slot[(y >> kTileLog2) * tiles_x + (x >> kTileLog2)];
    if (slot == kNoTile) return truncation_m;
    return metres_of_d2[d2[(static_cast<std::size_t>(slot) << (2 * kTileLog2)) | ((y & (kTileSide - 1)) << kTileLog2) |
                           (x & (kTileSide - 1))]];
  }
  // The 2×2 block of an interpolation, (cx, cy) .. (cx+1, cy+1), all inside the grid: out = d00, d10,
  // d01, d11, each exactly at(). One tile look-up when the block lies in one tile (225 of 256 cells):
  // the tracker's and refiner's bilinear samples then cost about what the float field's did.
  void corners(std::int32_t cx, std::int32_t cy, float out[4]) const {
    const std::uint32_t x = static_cast<std::uint32_t>(cx), y = static_cast<std::uint32_t>(cy);
    const std::uint32_t lx = x & (kTileSide - 1), ly = y & (kTileSide - 1);
    if (lx != kTileSide - 1 && ly != kTileSide - 1) {
      corners_in_tile((y >> kTileLog2) * tiles_x + (x >> kTileLog2), (ly << kTileLog2) | lx, out);
      return;
    }
    out[0] = at(cx, cy);
    out[1] = at(cx + 1, cy);
    out[2] = at(cx, cy + 1);
    out[3] = at(cx + 1, cy + 1);
  }
  // corners() of a block inside one tile, from the tile's index (row-major over the tiles) and the
  // block's first cell within it ((ly << kTileLog2) | lx, lx and ly < kTileSide − 1): a batch
  // computes both for many cells at once (distance_batch.cpp).
  void corners_in_tile(std::uint32_t tile, std::uint32_t offset, float out[4]) const {
    const std::uint32_t slot = tile_slot[tile];
    if (slot == kNoTile) {
      out[0] = out[1] = out[2] = out[3] = truncation_m;
      return;
    }
    const std::uint16_t* t = d2 + (static_cast<std::size_t>(slot) << (2 * kTileLog2)) + offset;
    out[0] = metres_of_d2[t[0]];
    out[1] = metres_of_d2[t[1]];
    out[2] = metres_of_d2[t[kTileSide]];
    out[3] = metres_of_d2[t[kTileSide + 1]];
  }
  // Bytes of the three arrays (what the arena holds).
  std::size_t bytes() const {
    return static_cast<std::size_t>(tiles_x) * tiles_y * sizeof(std::uint32_t) +
           static_cast<std::size_t>(stored_tiles) * kTileCells * sizeof(std::uint16_t) +
           (static_cast<std::size_t>(saturation_d2) + 1) * sizeof(float);
  }
};

// Shape of a field before its storage exists: plan (count), allocate, fill.
struct DistanceFieldLayout {
  std::uint32_t width = 0, height = 0;  // grid cells
  std::uint32_t tiles_x = 0, tiles_y = 0, stored_tiles = 0;
  float resolution = 0.0f;
  std::uint32_t saturation_d2 = 0;
  float truncation_m = 0.0f;
  std::size_t slot_count() const { return static_cast<std::size_t>(tiles_x) * tiles_y; }
  std::size_t cell_count() const { return static_cast<std::size_t>(stored_tiles) * DistanceField::kTileCells; }
  std::size_t table_count() const { return static_cast<std::size_t>(saturation_d2) + 1; }
  std::size_t bytes() const {
    return slot_count() * sizeof(std::uint32_t) + cell_count() * sizeof(std::uint16_t) + table_count() * sizeof(float);
  }
};

// Truncation the map loader applies unless told otherwise: the largest distance a consumer of the
// firmware tells apart is MCL's beam model, whose sphere tracing (map_view.h) steps by the distance
// and stops at the 8 m max range; with T ≥ 8 m + half a cell every ray ends exactly as on the exact
// field (a step of T from anywhere passes the max range). Everything else clips below 3 m.
constexpr float kDefaultDistanceTruncationM = 8.5f;

// Saturation (cells², ≥ 1) for a requested truncation: the smallest integer d² whose distance is
// ≥ truncation_m, capped at kMaxSaturationD2.
std::uint32_t distance_saturation_d2(float resolution, float truncation_m);

// Reads the exact field as float metres (`metres`, row-major w×h, row 0 = lowest y: the map image's
// distance section, little-endian IEEE) and counts the tiles holding a value below the truncation.
// Error when the resolution or truncation is not positive or the grid is empty.
Status plan_distance_field(const std::uint8_t* metres_le, std::uint32_t width, std::uint32_t height, float resolution,
                           float truncation_m, DistanceFieldLayout* out);
Status plan_distance_field(const float* metres, std::uint32_t width, std::uint32_t height, float resolution,
                           float truncation_m, DistanceFieldLayout* out);

// The view of a layout over filled storage (e.g. a test's vectors after a copy).
DistanceField distance_field_view(const DistanceFieldLayout& layout, const std::uint32_t* slots,
                                  const std::uint16_t* cells, const float* table);

// Fills caller storage (layout.slot_count() slots, layout.cell_count() cells, layout.table_count()
// table entries) from the same metres
// plan_distance_field() saw and returns the view. Metres are converted back to cells² by rounding
// (d/res)², exact for the EDT's sqrt(integer)·res values below the saturation; cells past the
// truncation and the padding of edge tiles hold the saturation.
DistanceField fill_distance_field(const DistanceFieldLayout& layout, const std::uint8_t* metres_le,
                                  std::uint32_t* slots, std::uint16_t* cells, float* table);
DistanceField fill_distance_field(const DistanceFieldLayout& layout, const float* metres, std::uint32_t* slots,
                                  std::uint16_t* cells, float* table);

}  // namespace fw
