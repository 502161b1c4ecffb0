// Loader test built from the format description in map_image.h alone (no host writer), so it also
// runs in cross builds (armhf/aarch64 under qemu), where sim/ is not built: 32-bit size_t,
// alignment and endianness of the loader are exercised there.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/crc32.h"
#include "firmware/map/map_image.h"

namespace fw {
namespace {

void u32(std::vector<std::uint8_t>* b, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b->push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}
void f32(std::vector<std::uint8_t>* b, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  u32(b, u);
}
void set32(std::vector<std::uint8_t>* b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// Deliberate defects written with honest CRCs (issue 13: the loader used to accept each of them).
enum class Tweak { kNone, kWrongDistance, kDuplicatePoint, kGeometryReserved, kEntryReserved, kFarOrigin };

// 4 x 3 grid at 0.5 m, origin (1, -1); occupied cells (0,0) and (3,2); (1,2) unknown.
std::vector<std::uint8_t> hand_made_image(std::uint32_t version = kMapImageVersion, Tweak tweak = Tweak::kNone) {
  const std::uint32_t w = 4, h = 3;
  std::vector<std::uint8_t> occ(w * h, kCellFree);
  occ[0] = kCellOccupied;
  occ[2 * w + 3] = kCellOccupied;
  occ[2 * w + 1] = kCellUnknown;
  std::vector<std::uint8_t> dist, pts, geo;
  float maxd = 0;
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      const float d2a = static_cast<float>(x * x + y * y);
      const float d2b = static_cast<float>((3 - static_cast<int>(x)) * (3 - static_cast<int>(x)) +
                                           (2 - static_cast<int>(y)) * (2 - static_cast<int>(y)));
      float d = std::sqrt(std::min(d2a, d2b)) * 0.5f;
      // Cell (1,1): 0.707 m from both walls; 0.75 m is plausible, consistent with "0 only on
      // occupied cells" and below the maximum — but not this map's distance.
      if (tweak == Tweak::kWrongDistance && x == 1 && y == 1) d = 0.75f;
      maxd = std::max(maxd, d);
      f32(&dist, d);
    }
  }
  f32(&pts, 1.25f);
  f32(&pts, -0.75f);
  f32(&pts, tweak == Tweak::kDuplicatePoint ? 1.25f : 2.75f);
  f32(&pts, tweak == Tweak::kDuplicatePoint ? -0.75f : 0.25f);
  f32(&geo, 0.5f);
  f32(&geo, tweak == Tweak::kFarOrigin ? -1e38f : 1.0f);
  f32(&geo, -1.0f);
  u32(&geo, w);
  u32(&geo, h);
  u32(&geo, 2);
  f32(&geo, maxd);
  u32(&geo, tweak == Tweak::kGeometryReserved ? 7 : 0);
  const std::vector<std::uint8_t>* payloads[4] = {&geo, &occ, &dist, &pts};
  std::vector<std::uint8_t> img(kMapImageHeaderBytes + 4 * kMapSectionEntryBytes, 0);
  std::memcpy(img.data(), kMapImageMagic, 8);
  set32(&img, 8, version);
  set32(&img, 12, 4);
  for (std::uint32_t i = 0; i < 4; ++i) {
    while (img.size() % 16 != 0) img.push_back(0);
    const std::size_t off = img.size();
    img.insert(img.end(), payloads[i]->begin(), payloads[i]->end());
    const std::size_t e = kMapImageHeaderBytes + i * kMapSectionEntryBytes;
    set32(&img, e, i + 1);  // kGeometry..kOccupiedPoints
    set32(&img, e + 4, 1);
    set32(&img, e + 8, static_cast<std::uint32_t>(off));
    set32(&img, e + 16, static_cast<std::uint32_t>(payloads[i]->size()));
    set32(&img, e + 24, crc32(payloads[i]->data(), payloads[i]->size()));
    if (tweak == Tweak::kEntryReserved && i == 1) set32(&img, e + 28, 1);
  }
  set32(&img, 16, static_cast<std::uint32_t>(img.size()));
  set32(&img, 28, crc32(img.data(), img.size()));
  return img;
}

TEST(MapImageFormatTest, LoadsHandMadeImage) {
  const std::vector<std::uint8_t> img = hand_made_image();
  alignas(16) static unsigned char storage[4096];
  StartupArena arena;
  ASSERT_TRUE(arena.init(storage, sizeof(storage), "test").is_ok());
  GlobalMap m;
  const Status st = load_map_image(img.data(), img.size(), arena, &m, "hand.mmap");
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_EQ(m.geometry.width, 4u);
  EXPECT_EQ(m.geometry.height, 3u);
  EXPECT_EQ(m.geometry.resolution, 0.5f);
  EXPECT_EQ(m.num_points, 2u);
  EXPECT_EQ(m.points[1].x(), 2.75f);
  EXPECT_EQ(m.cell(1, 2), kCellUnknown);
  EXPECT_EQ(m.distance_at(1.25f, -0.75f, -1.0f), 0.0f);
  EXPECT_EQ(m.distance_at(1.75f, -0.75f, -1.0f), 0.5f);
  EXPECT_EQ(m.max_distance_m, 1.0f);  // cells (3,0) and (0,2): 2 cells from the nearest wall
  // Occupancy and distance field as one 16×16 tile each (an index entry + 256 codes; an index entry +
  // 256 uint16: the map has known cells and is within the truncation of a wall everywhere, + the
  // metres of d² = 0..289: 8.5 m is 17 cells of 0.5 m), points.
  EXPECT_EQ(m.occupancy.stored_tiles, 1u);
  EXPECT_EQ(m.distance.stored_tiles, 1u);
  EXPECT_EQ(m.distance.saturation_d2, 289u);
  EXPECT_EQ(arena.used(), (4u + 256u) + (4u + 256u * 2u + 290u * 4u) + 2u * 8u);
}

TEST(MapImageFormatTest, RejectsWrongDistanceDuplicatesReservedFieldsAndFarOrigins) {
  alignas(16) static unsigned char storage[4096];
  struct Case {
    Tweak tweak;
    const char* expect;
  };
  const Case cases[] = {
      {Tweak::kWrongDistance, "distance field cell 5 (x 1, y 1) is 0.75 m, the occupied cells put it at 0.707106"},
      {Tweak::kDuplicatePoint, "occupied point 1 (1.25, -0.75) duplicates point 0"},
      {Tweak::kGeometryReserved, "geometry: reserved field is 0x00000007, must be 0"},
      {Tweak::kEntryReserved, "section 1 (occupancy): reserved field is 0x00000001, must be 0"},
      {Tweak::kFarOrigin, "geometry: the grid reaches more than 2^19 cells"},
  };
  for (const Case& c : cases) {
    const std::vector<std::uint8_t> img = hand_made_image(kMapImageVersion, c.tweak);
    StartupArena arena;
    ASSERT_TRUE(arena.init(storage, sizeof(storage), "test").is_ok());
    GlobalMap m;
    const Status st = load_map_image(img.data(), img.size(), arena, &m, "hand.mmap");
    ASSERT_FALSE(st.is_ok()) << c.expect;
    EXPECT_EQ(st.code(), Errc::kCorruptData);
    EXPECT_NE(std::strstr(st.message(), "hand.mmap: "), nullptr) << st.message();
    EXPECT_NE(std::strstr(st.message(), c.expect), nullptr) << "'" << st.message() << "' lacks '" << c.expect << "'";
    EXPECT_EQ(arena.used(), 0u) << "a rejected image keeps nothing in the arena";
  }
}

TEST(MapImageFormatTest, BilinearDistanceAndGradient) {
  const std::vector<std::uint8_t> img = hand_made_image();
  alignas(16) static unsigned char storage[4096];
  StartupArena arena;
  ASSERT_TRUE(arena.init(storage, sizeof(storage), "test").is_ok());
  GlobalMap m;
  ASSERT_TRUE(load_map_image(img.data(), img.size(), arena, &m, "hand.mmap").is_ok());
  float gx = 0, gy = 0;
  // At a cell centre: the cell value.
  EXPECT_FLOAT_EQ(m.distance_bilinear(1.75f, -0.75f, -1.0f), 0.5f);
  // Halfway between centres of (0,0) [0] and (1,0) [0.5]: 0.25, gradient +1 m/m along x.
  EXPECT_FLOAT_EQ(m.distance_bilinear(1.5f, -0.75f, -1.0f, &gx, &gy), 0.25f);
  EXPECT_FLOAT_EQ(gx, 1.0f);
  // Between (0,0) [0] and (0,1) [0.5] along y.
  EXPECT_FLOAT_EQ(m.distance_bilinear(1.25f, -0.5f, -1.0f, &gx, &gy), 0.25f);
  EXPECT_FLOAT_EQ(gy, 1.0f);
  // Border region (within half a cell of the edge) is clamped; outside gives `outside`.
  EXPECT_FLOAT_EQ(m.distance_bilinear(1.01f, -0.99f, -1.0f), 0.0f);
  EXPECT_EQ(m.distance_bilinear(0.9f, 0.0f, -1.0f, &gx, &gy), -1.0f);
  EXPECT_EQ(gx, 0.0f);
  EXPECT_EQ(m.distance_bilinear(NAN, 0.0f, -2.0f), -2.0f);
}

TEST(MapImageFormatTest, RejectsCorruption) {
  const std::vector<std::uint8_t> good = hand_made_image();
  alignas(16) static unsigned char storage[4096];
  for (std::size_t i = 0; i < good.size(); ++i) {
    std::vector<std::uint8_t> b = good;
    b[i] ^= 0x01;
    StartupArena arena;
    ASSERT_TRUE(arena.init(storage, sizeof(storage), "test").is_ok());
    GlobalMap m;
    EXPECT_FALSE(load_map_image(b.data(), b.size(), arena, &m, "hand.mmap").is_ok()) << "flip at " << i;
    EXPECT_EQ(arena.used(), 0u);
  }
  StartupArena arena;
  ASSERT_TRUE(arena.init(storage, sizeof(storage), "test").is_ok());
  GlobalMap m;
  Status st = load_map_image(good.data(), good.size() - 3, arena, &m, "hand.mmap");
  EXPECT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), "hand.mmap"), nullptr) << st.message();
  const std::vector<std::uint8_t> v2 = hand_made_image(2);
  st = load_map_image(v2.data(), v2.size(), arena, &m, "hand.mmap");
  EXPECT_FALSE(st.is_ok());
  EXPECT_EQ(st.code(), Errc::kUnsupported);
  EXPECT_NE(std::strstr(st.message(), "version 2"), nullptr) << st.message();
  st = load_map_image(nullptr, 0, arena, &m, "hand.mmap");
  EXPECT_FALSE(st.is_ok());
}

}  // namespace
}  // namespace fw
