#include "firmware/map/distance_field.h"

#include <cstring>

#include "firmware/map/le_fields.h"

namespace fw {
namespace {

// The two sources (image bytes, a float array) read the same way.
struct LeSource {
  const std::uint8_t* p;
  float operator()(std::size_t i) const { return read_le_f32(p + 4 * i); }
};
struct FloatSource {
  const float* p;
  float operator()(std::size_t i) const { return p[i]; }
};

// Stored cells² of a value in metres: round((d/res)²), saturated. Plan and fill use this one
// function, so a tile is stored exactly when a cell of it reads below the truncation.
std::uint32_t quantise(float metres, double inv_res, std::uint32_t saturation) {
  if (!(metres >= 0.0f)) return saturation;  // NaN never reaches here from a validated image
  const double r = static_cast<double>(metres) * inv_res;
  const double q = r * r + 0.5;
  return q >= static_cast<double>(saturation) ? saturation : static_cast<std::uint32_t>(q);
}

template <typename Source>
Status plan(Source src, std::uint32_t w, std::uint32_t h, float res, float truncation_m, DistanceFieldLayout* out) {
  if (w == 0 || h == 0 || !(res > 0.0f) || !(truncation_m > 0.0f)) {
    return Status::error(Errc::kInvalidArgument,
                         "distance field: need a non-empty grid, resolution > 0 and truncation > 0 "
                         "(got %ux%u, %g m, %g m)",
                         w, h, static_cast<double>(res), static_cast<double>(truncation_m));
  }
  DistanceFieldLayout l;
  l.width = w;
  l.height = h;
  l.resolution = res;
  l.tiles_x = (w + DistanceField::kTileSide - 1) >> DistanceField::kTileLog2;
  l.tiles_y = (h + DistanceField::kTileSide - 1) >> DistanceField::kTileLog2;
  l.saturation_d2 = distance_saturation_d2(res, truncation_m);
  l.truncation_m = std::sqrt(static_cast<float>(l.saturation_d2)) * res;
  const double inv_res = 1.0 / static_cast<double>(res);
  for (std::uint32_t ty = 0; ty < l.tiles_y; ++ty) {
    for (std::uint32_t tx = 0; tx < l.tiles_x; ++tx) {
      bool needed = false;
      const std::uint32_t y1 = (ty + 1) * DistanceField::kTileSide < h ? (ty + 1) * DistanceField::kTileSide : h;
      const std::uint32_t x1 = (tx + 1) * DistanceField::kTileSide < w ? (tx + 1) * DistanceField::kTileSide : w;
      for (std::uint32_t y = ty * DistanceField::kTileSide; y < y1 && !needed; ++y) {
        for (std::uint32_t x = tx * DistanceField::kTileSide; x < x1; ++x) {
          if (quantise(src(static_cast<std::size_t>(y) * w + x), inv_res, l.saturation_d2) < l.saturation_d2) {
            needed = true;
            break;
          }
        }
      }
      if (needed) ++l.stored_tiles;
    }
  }
  *out = l;
  return Status::ok();
}

template <typename Source>
DistanceField fill(const DistanceFieldLayout& l, Source src, std::uint32_t* slots, std::uint16_t* cells,
                   float* table) {
  const double inv_res = 1.0 / static_cast<double>(l.resolution);
  const std::uint32_t sat = l.saturation_d2;
  // The writer's and loader's expression for an integer d² (map_image.cpp), once per value.
  for (std::uint32_t q = 0; q <= sat; ++q) table[q] = std::sqrt(static_cast<float>(q)) * l.resolution;
  std::uint32_t next = 0;
  for (std::uint32_t ty = 0; ty < l.tiles_y; ++ty) {
    for (std::uint32_t tx = 0; tx < l.tiles_x; ++tx) {
      std::uint16_t tile[DistanceField::kTileCells];
      bool needed = false;
      for (std::uint32_t j = 0; j < DistanceField::kTileSide; ++j) {
        for (std::uint32_t i = 0; i < DistanceField::kTileSide; ++i) {
          const std::uint32_t x = tx * DistanceField::kTileSide + i, y = ty * DistanceField::kTileSide + j;
          std::uint32_t q = sat;  // padding beyond the grid edge: never read by at() on the grid
          if (x < l.width && y < l.height) q = quantise(src(static_cast<std::size_t>(y) * l.width + x), inv_res, sat);
          if (q < sat) needed = true;
          tile[(j << DistanceField::kTileLog2) | i] = static_cast<std::uint16_t>(q);
        }
      }
      std::uint32_t& slot = slots[static_cast<std::size_t>(ty) * l.tiles_x + tx];
      if (needed && next < l.stored_tiles) {
        std::memcpy(cells + static_cast<std::size_t>(next) * DistanceField::kTileCells, tile, sizeof(tile));
        slot = next++;
      } else {
        slot = DistanceField::kNoTile;
      }
    }
  }
  return distance_field_view(l, slots, cells, table);
}

}  // namespace

DistanceField distance_field_view(const DistanceFieldLayout& l, const std::uint32_t* slots,
                                  const std::uint16_t* cells, const float* table) {
  DistanceField f;
  f.tile_slot = slots;
  f.d2 = cells;
  f.metres_of_d2 = table;
  f.tiles_x = l.tiles_x;
  f.tiles_y = l.tiles_y;
  f.stored_tiles = l.stored_tiles;
  f.resolution = l.resolution;
  f.saturation_d2 = l.saturation_d2;
  f.truncation_m = l.truncation_m;
  return f;
}

std::uint32_t distance_saturation_d2(float resolution, float truncation_m) {
  const double cells = static_cast<double>(truncation_m) / static_cast<double>(resolution);
  const double q = std::ceil(cells * cells);
  if (!(q >= 1.0)) return 1;
  return q >= static_cast<double>(DistanceField::kMaxSaturationD2) ? DistanceField::kMaxSaturationD2
                                                                    : static_cast<std::uint32_t>(q);
}

Status plan_distance_field(const std::uint8_t* metres_le, std::uint32_t width, std::uint32_t height, float resolution,
                           float truncation_m, DistanceFieldLayout* out) {
  return plan(LeSource{metres_le}, width, height, resolution, truncation_m, out);
}
Status plan_distance_field(const float* metres, std::uint32_t width, std::uint32_t height, float resolution,
                           float truncation_m, DistanceFieldLayout* out) {
  return plan(FloatSource{metres}, width, height, resolution, truncation_m, out);
}

DistanceField fill_distance_field(const DistanceFieldLayout& layout, const std::uint8_t* metres_le,
                                  std::uint32_t* slots, std::uint16_t* cells, float* table) {
  return fill(layout, LeSource{metres_le}, slots, cells, table);
}
DistanceField fill_distance_field(const DistanceFieldLayout& layout, const float* metres, std::uint32_t* slots,
                                  std::uint16_t* cells, float* table) {
  return fill(layout, FloatSource{metres}, slots, cells, table);
}

}  // namespace fw
