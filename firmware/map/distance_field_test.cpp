// Known answers for the truncated, tiled distance field (distance_field.h) on tiny maps: every
// lookup equals the exact float field below the truncation, the truncation beyond it, and tiles far
// from any wall (most of a bounding box) are not stored.
#include "firmware/map/distance_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "firmware/map/edt.h"
#include "firmware/map/global_map.h"

namespace fw {
namespace {

// Exact field (metres, as the map writer computes it) of the occupied cells of a w×h grid.
std::vector<float> exact_metres(const std::vector<std::uint8_t>& occ, std::uint32_t w, std::uint32_t h, float res) {
  std::vector<float> f(occ.size());
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = occ[i] == kCellOccupied ? 0.0f : kEdtInf;
  const std::size_t n = w > h ? w : h;
  std::vector<int> v(n);
  std::vector<float> z(n + 1), ff(n), d(n);
  const EdtScratch s{v.data(), z.data(), ff.data(), d.data(), n};
  const std::size_t dims[2] = {h, w};
  squared_edt<2>(f.data(), dims, s);
  for (float& x : f) x = std::sqrt(x) * res;
  return f;
}

struct Built {
  DistanceFieldLayout layout;
  std::vector<std::uint32_t> slots;
  std::vector<std::uint16_t> cells;
  std::vector<float> table;
  DistanceField field;
};

Built build(const std::vector<float>& metres, std::uint32_t w, std::uint32_t h, float res, float truncation) {
  Built b;
  const Status st = plan_distance_field(metres.data(), w, h, res, truncation, &b.layout);
  EXPECT_TRUE(st.is_ok()) << st.message();
  b.slots.assign(b.layout.slot_count(), 0);
  b.cells.assign(b.layout.cell_count(), 0);
  b.table.assign(b.layout.table_count(), 0.0f);
  b.field = fill_distance_field(b.layout, metres.data(), b.slots.data(), b.cells.data(), b.table.data());
  return b;
}

TEST(DistanceFieldTest, SaturationIsTheFirstSquaredDistanceAtOrBeyondTheTruncation) {
  EXPECT_EQ(distance_saturation_d2(0.1f, 0.55f), 31u);  // 5.5 cells: 30.25 cells² → 31
  EXPECT_EQ(distance_saturation_d2(0.05f, 0.5f), 100u);  // exactly 10 cells
  EXPECT_EQ(distance_saturation_d2(0.05f, 1000.0f), DistanceField::kMaxSaturationD2);  // uint16 cap
  EXPECT_EQ(distance_saturation_d2(0.05f, 0.001f), 1u);
}

TEST(DistanceFieldTest, LookupsEqualTheExactFieldBelowTheTruncation) {
  // 37 × 21 cells (edge tiles partly outside the grid), a wall and a pillar.
  const std::uint32_t w = 37, h = 21;
  const float res = 0.1f;
  std::vector<std::uint8_t> occ(w * h, kCellUnknown);
  for (std::uint32_t x = 3; x < 30; ++x) occ[5 * w + x] = kCellOccupied;
  occ[15 * w + 33] = kCellOccupied;
  const std::vector<float> exact = exact_metres(occ, w, h, res);
  const Built b = build(exact, w, h, res, 0.55f);
  ASSERT_TRUE(b.field.valid());
  EXPECT_EQ(b.field.saturation_d2, 31u);
  EXPECT_EQ(b.field.truncation_m, std::sqrt(31.0f) * res);
  int below = 0, beyond = 0;
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      const float e = exact[y * w + x];
      const float got = b.field.at(static_cast<std::int32_t>(x), static_cast<std::int32_t>(y));
      if (e < b.field.truncation_m) {
        ASSERT_EQ(got, e) << x << "," << y;  // bit-identical, not just close
        ++below;
      } else {
        ASSERT_EQ(got, b.field.truncation_m) << x << "," << y;
        ++beyond;
      }
    }
  }
  EXPECT_GT(below, 0);
  EXPECT_GT(beyond, 0);
  // corners() (one tile look-up inside a tile, four across a tile edge) equals at() everywhere.
  for (std::int32_t y = 0; y + 1 < static_cast<std::int32_t>(h); ++y) {
    for (std::int32_t x = 0; x + 1 < static_cast<std::int32_t>(w); ++x) {
      float c[4];
      b.field.corners(x, y, c);
      ASSERT_EQ(c[0], b.field.at(x, y)) << x << "," << y;
      ASSERT_EQ(c[1], b.field.at(x + 1, y)) << x << "," << y;
      ASSERT_EQ(c[2], b.field.at(x, y + 1)) << x << "," << y;
      ASSERT_EQ(c[3], b.field.at(x + 1, y + 1)) << x << "," << y;
    }
  }
  // The same map read from little-endian image bytes gives the same field.
  std::vector<std::uint8_t> le(exact.size() * 4);
  for (std::size_t i = 0; i < exact.size(); ++i) {
    std::uint32_t u;
    std::memcpy(&u, &exact[i], 4);
    for (int k = 0; k < 4; ++k) le[4 * i + k] = static_cast<std::uint8_t>(u >> (8 * k));
  }
  DistanceFieldLayout l2;
  ASSERT_TRUE(plan_distance_field(le.data(), w, h, res, 0.55f, &l2).is_ok());
  EXPECT_EQ(l2.stored_tiles, b.layout.stored_tiles);
  std::vector<std::uint32_t> slots(l2.slot_count());
  std::vector<std::uint16_t> cells(l2.cell_count());
  std::vector<float> table(l2.table_count());
  const DistanceField f2 = fill_distance_field(l2, le.data(), slots.data(), cells.data(), table.data());
  EXPECT_EQ(slots, b.slots);
  EXPECT_EQ(cells, b.cells);
  EXPECT_EQ(f2.at(36, 20), b.field.at(36, 20));
}

TEST(DistanceFieldTest, TilesFarFromEveryWallAreNotStored) {
  // 64 × 48 cells of unknown space with one occupied cell at (2, 2); truncation 5 cells: only the
  // first 16 × 16 tile holds a cell closer than that, the other 11 read the truncation.
  const std::uint32_t w = 64, h = 48;
  const float res = 0.05f;
  std::vector<std::uint8_t> occ(w * h, kCellUnknown);
  occ[2 * w + 2] = kCellOccupied;
  const std::vector<float> exact = exact_metres(occ, w, h, res);
  const Built b = build(exact, w, h, res, 0.25f);
  EXPECT_EQ(b.layout.tiles_x, 4u);
  EXPECT_EQ(b.layout.tiles_y, 3u);
  EXPECT_EQ(b.layout.stored_tiles, 1u);
  EXPECT_EQ(b.layout.bytes(), 12u * 4u + 256u * 2u + 26u * 4u);  // vs 64·48·4 = 12288 bytes of floats
  EXPECT_EQ(b.slots[0], 0u);
  for (std::size_t i = 1; i < b.slots.size(); ++i) EXPECT_EQ(b.slots[i], DistanceField::kNoTile);
  EXPECT_EQ(b.field.at(2, 2), 0.0f);
  EXPECT_EQ(b.field.at(5, 6), 0.25f);  // (3, 4) cells: 5 cells, d² = 25 = saturation → truncation
  EXPECT_EQ(b.field.at(4, 3), std::sqrt(5.0f) * res);
  EXPECT_EQ(b.field.at(63, 47), b.field.truncation_m);  // a tile that is not stored
  EXPECT_EQ(b.field.at(20, 2), b.field.truncation_m);
  float c[4];
  b.field.corners(40, 30, c);  // inside a tile that is not stored
  for (float v : c) EXPECT_EQ(v, b.field.truncation_m);
}

TEST(DistanceFieldTest, BilinearSamplesMatchTheFloatFieldWhereAllCornersAreBelowTheTruncation) {
  const std::uint32_t w = 40, h = 30;
  const float res = 0.05f;
  std::vector<std::uint8_t> occ(w * h, kCellFree);
  for (std::uint32_t x = 0; x < w; ++x) occ[10 * w + x] = kCellOccupied;
  for (std::uint32_t y = 0; y < h; ++y) occ[y * w + 25] = kCellOccupied;
  const std::vector<float> exact = exact_metres(occ, w, h, res);
  const Built b = build(exact, w, h, res, 0.4f);
  GlobalMap m;
  m.geometry.resolution = res;
  m.geometry.width = w;
  m.geometry.height = h;
  m.distance = b.field;
  int compared = 0;
  for (float y = 0.03f; y < h * res - 0.03f; y += 0.013f) {
    for (float x = 0.03f; x < w * res - 0.03f; x += 0.017f) {
      // The float field's bilinear sample (the pre-issue-14 code path).
      float gx = (x - m.geometry.origin_x) / res - 0.5f, gy = (y - m.geometry.origin_y) / res - 0.5f;
      gx = std::fmin(std::fmax(gx, 0.0f), w - 1.0f);
      gy = std::fmin(std::fmax(gy, 0.0f), h - 1.0f);
      const int x0 = static_cast<int>(gx), y0 = static_cast<int>(gy);
      const int x1 = x0 + 1 < static_cast<int>(w) ? x0 + 1 : x0, y1 = y0 + 1 < static_cast<int>(h) ? y0 + 1 : y0;
      const float d00 = exact[y0 * w + x0], d10 = exact[y0 * w + x1];
      const float d01 = exact[y1 * w + x0], d11 = exact[y1 * w + x1];
      const float fx = gx - x0, fy = gy - y0;
      const float a = d00 + fx * (d10 - d00), bb = d01 + fx * (d11 - d01);
      const float want = a + fy * (bb - a);
      const float t = b.field.truncation_m;
      if (d00 < t && d10 < t && d01 < t && d11 < t) {
        ASSERT_EQ(m.distance_bilinear(x, y, -1.0f), want) << x << "," << y;
        ++compared;
      } else {
        // A saturated corner reads the truncation, which is ≤ its exact value: never farther.
        EXPECT_LE(m.distance_bilinear(x, y, -1.0f), want + 1e-6f) << x << "," << y;
      }
    }
  }
  EXPECT_GT(compared, 1000);
}

TEST(DistanceFieldTest, RejectsEmptyGridsAndNonPositiveParameters) {
  const std::vector<float> one(1, 0.0f);
  DistanceFieldLayout l;
  EXPECT_FALSE(plan_distance_field(one.data(), 0, 1, 0.05f, 1.0f, &l).is_ok());
  EXPECT_FALSE(plan_distance_field(one.data(), 1, 1, 0.0f, 1.0f, &l).is_ok());
  EXPECT_FALSE(plan_distance_field(one.data(), 1, 1, 0.05f, 0.0f, &l).is_ok());
  EXPECT_TRUE(plan_distance_field(one.data(), 1, 1, 0.05f, 1.0f, &l).is_ok());
  EXPECT_EQ(l.stored_tiles, 1u);
}

}  // namespace
}  // namespace fw
