// Compiled map image: host writer + firmware loader together (the loader is firmware code; its
// tests live here because they need the host writer).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "firmware/base/arena.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/rng.h"
#include "firmware/base/crc32.h"
#include "firmware/map/map_image.h"
#include "firmware/map/map_image_file.h"
#include "sim/map/map_image_writer.h"
#include "tests/alloc_counter.h"

namespace sim {
namespace {

// A 40x30 grid at 0.1 m: border walls, an inner wall with a door, one unknown blob.
OccupancyGrid test_grid() {
  OccupancyGrid g;
  g.geometry.resolution = 0.1f;
  g.geometry.origin_x = -2.0f;
  g.geometry.origin_y = 1.0f;
  g.geometry.width = 40;
  g.geometry.height = 30;
  g.cells.assign(g.geometry.cell_count(), fw::kCellFree);
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      const bool border = x == 0 || y == 0 || x == 39 || y == 29;
      const bool inner = x == 20 && (y < 12 || y > 16);
      if (border || inner) g.cells[g.geometry.index(x, y)] = fw::kCellOccupied;
      if (x > 30 && x < 35 && y > 20 && y < 25) g.cells[g.geometry.index(x, y)] = fw::kCellUnknown;
    }
  }
  return g;
}

std::vector<std::uint8_t> image_of(const OccupancyGrid& g) {
  MapImageWriter w;
  std::string err;
  EXPECT_TRUE(w.set_grid(g, &err)) << err;
  return w.bytes();
}

struct Loaded {
  fw::StartupArena arena;
  fw::GlobalMap map;
  fw::Status status;
};

void load(const std::vector<std::uint8_t>& bytes, Loaded* out) {
  // The loader's peak (its distance table grows with the truncation in cells, not with the image);
  // images too broken for map_image_arena_bytes fail before they allocate.
  const std::size_t need = std::max(bytes.size() + 4096, fw::map_image_arena_bytes(bytes.data(), bytes.size()));
  ASSERT_TRUE(out->arena.init_mapped(need, false, "test").is_ok());
  out->status = fw::load_map_image(bytes.data(), bytes.size(), out->arena, &out->map, "test.mmap");
}

std::uint32_t rd32(const std::vector<std::uint8_t>& b, std::size_t at) {
  return b[at] | (b[at + 1] << 8) | (b[at + 2] << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}
void wr32(std::vector<std::uint8_t>* b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
// Recomputes every section CRC and the image CRC (to make a structurally "honest" corrupt image).
void refresh_crcs(std::vector<std::uint8_t>* b) {
  const std::uint32_t n = rd32(*b, 12);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::size_t e = 32 + 32 * i;
    const std::size_t off = rd32(*b, e + 8), size = rd32(*b, e + 16);
    if (off > b->size() || size > b->size() - off) continue;  // deliberately out of bounds
    wr32(b, e + 24, static_cast<std::uint32_t>(::crc32(0, b->data() + off, static_cast<uInt>(size))));
  }
  wr32(b, 28, 0);
  wr32(b, 28, static_cast<std::uint32_t>(::crc32(0, b->data(), static_cast<uInt>(b->size()))));
}
std::size_t section_entry(const std::vector<std::uint8_t>& b, fw::MapSectionType t) {
  const std::uint32_t n = rd32(b, 12);
  for (std::uint32_t i = 0; i < n; ++i) {
    if (rd32(b, 32 + 32 * i) == static_cast<std::uint32_t>(t)) return 32 + 32 * i;
  }
  return 0;
}

TEST(MapImageTest, FirmwareCrcMatchesZlib) {
  fw::RandomStream rng(7, 0);
  std::vector<std::uint8_t> buf(100000);
  for (auto& x : buf) x = static_cast<std::uint8_t>(rng.next_u32());
  for (std::size_t len : {0u, 1u, 3u, 1000u, 99999u, 100000u}) {
    EXPECT_EQ(fw::crc32(buf.data(), len), static_cast<std::uint32_t>(::crc32(0, buf.data(), static_cast<uInt>(len))));
  }
}

TEST(MapImageTest, LoadsWhatTheWriterWrote) {
  fw::MemoryReport::instance().clear();
  const OccupancyGrid g = test_grid();
  const std::vector<std::uint8_t> bytes = image_of(g);
  Loaded l;
  load(bytes, &l);
  ASSERT_TRUE(l.status.is_ok()) << l.status.message();
  const fw::GlobalMap& m = l.map;
  EXPECT_EQ(m.geometry.width, 40u);
  EXPECT_EQ(m.geometry.height, 30u);
  EXPECT_EQ(m.geometry.resolution, 0.1f);
  EXPECT_EQ(m.geometry.origin_x, -2.0f);
  EXPECT_EQ(m.geometry.origin_y, 1.0f);
  std::size_t occ = 0;
  for (std::size_t i = 0; i < g.cells.size(); ++i) {
    EXPECT_EQ(m.cell(static_cast<std::int32_t>(i % m.geometry.width), static_cast<std::int32_t>(i / m.geometry.width)),
              g.cells[i]);
    occ += g.cells[i] == fw::kCellOccupied;
  }
  EXPECT_EQ(m.num_points, occ);
  // Distance field against brute force, exact (same float ops: sqrt(integer) * res).
  float maxd = 0.0f;
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) {
      int best = std::numeric_limits<int>::max();
      for (int yy = 0; yy < 30; ++yy)
        for (int xx = 0; xx < 40; ++xx)
          if (g.cells[g.geometry.index(xx, yy)] == fw::kCellOccupied)
            best = std::min(best, (x - xx) * (x - xx) + (y - yy) * (y - yy));
      const float expect = std::sqrt(static_cast<float>(best)) * 0.1f;
      ASSERT_EQ(m.distance.at(x, y), expect) << x << "," << y;
      maxd = std::max(maxd, expect);
    }
  }
  EXPECT_EQ(m.max_distance_m, maxd);
  // Points are the occupied cell centres and lie in occupied cells.
  for (std::uint32_t i = 0; i < m.num_points; ++i) {
    std::int32_t cx, cy;
    ASSERT_TRUE(m.geometry.world_to_cell(m.points[i].x(), m.points[i].y(), &cx, &cy));
    EXPECT_EQ(m.cell(cx, cy), fw::kCellOccupied);
  }
  EXPECT_NEAR(m.points[0].x(), -1.95f, 1e-6f);
  EXPECT_NEAR(m.points[0].y(), 1.05f, 1e-6f);
  EXPECT_EQ(m.distance_at(-1.95f, 1.05f, -1.0f), 0.0f);
  EXPECT_EQ(m.distance_at(100.0f, 0.0f, -1.0f), -1.0f);
  // Registered with the memory report.
  // Occupancy, the distance tiles (a 40 × 30 map: 3 × 2 tiles, all within the truncation of a wall),
  // points.
  EXPECT_EQ(m.distance.stored_tiles, 6u);
  EXPECT_EQ(fw::MemoryReport::instance().module_bytes("map"),
            m.occupancy.bytes() + 6u * 4u + 6u * 256u * 2u + (m.distance.saturation_d2 + 1u) * 4u +
                m.num_points * sizeof(fw::Point2f));
  fw::MemoryReport::instance().clear();
}

TEST(MapImageTest, ExtraSectionsAreFoundAndCovered) {
  MapImageWriter w;
  std::string err;
  ASSERT_TRUE(w.set_grid(test_grid(), &err)) << err;
  const std::vector<std::uint8_t> table = {1, 2, 3, 4, 5};
  ASSERT_TRUE(w.add_section(fw::MapSectionType::kRelationTable2D, table, 3, &err)) << err;
  EXPECT_FALSE(w.add_section(fw::MapSectionType::kOccupancy, {1}, 1, &err));
  std::vector<std::uint8_t> bytes = w.bytes();
  EXPECT_TRUE(fw::verify_map_image(bytes.data(), bytes.size()).is_ok());
  std::size_t len = 0;
  std::uint32_t ver = 0;
  const std::uint8_t* p = fw::find_section(bytes.data(), bytes.size(), fw::MapSectionType::kRelationTable2D, &len, &ver);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(len, 5u);
  EXPECT_EQ(ver, 3u);
  EXPECT_EQ(std::memcmp(p, table.data(), 5), 0);
  EXPECT_EQ(static_cast<std::size_t>(p - bytes.data()) % fw::kMapSectionAlignment, 0u);
  EXPECT_EQ(fw::find_section(bytes.data(), bytes.size(), fw::MapSectionType::kRelationTable3D, &len), nullptr);
  Loaded l;
  load(bytes, &l);
  EXPECT_TRUE(l.status.is_ok()) << l.status.message();
  // A flipped byte inside the extra section is caught by its CRC.
  bytes[static_cast<std::size_t>(p - bytes.data()) + 2] ^= 0x10;
  const fw::Status st = fw::verify_map_image(bytes.data(), bytes.size(), "x.mmap");
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), "relation table 2D section CRC mismatch"), nullptr) << st.message();
}

void expect_rejected(const std::vector<std::uint8_t>& bytes, const char* what) {
  Loaded l;
  load(bytes, &l);
  ASSERT_FALSE(l.status.is_ok()) << "accepted: expected '" << what << "'";
  EXPECT_NE(std::strstr(l.status.message(), "test.mmap"), nullptr) << l.status.message();
  EXPECT_NE(std::strstr(l.status.message(), what), nullptr) << "'" << l.status.message() << "' lacks '" << what << "'";
  EXPECT_EQ(l.arena.used(), 0u) << "a rejected image must not consume arena memory";
}

TEST(MapImageTest, FlippedByteAnywhereIsRejected) {
  const std::vector<std::uint8_t> good = image_of(test_grid());
  // Every byte position (step 7 for speed) with a single bit flip must be rejected.
  for (std::size_t i = 0; i < good.size(); i += 7) {
    std::vector<std::uint8_t> b = good;
    b[i] ^= 0x04;
    Loaded l;
    load(b, &l);
    EXPECT_FALSE(l.status.is_ok()) << "flip at byte " << i << " accepted";
  }
  std::vector<std::uint8_t> b = good;
  const std::size_t occ_entry = section_entry(b, fw::MapSectionType::kOccupancy);
  b[rd32(b, occ_entry + 8) + 5] ^= 1;
  expect_rejected(b, "occupancy section CRC mismatch");
  b = good;
  b[good.size() - 1] ^= 0x80;  // inside the last section (points)
  expect_rejected(b, "CRC mismatch");
  b = good;
  b[25] ^= 0;                   // unchanged control
  Loaded ok;
  load(b, &ok);
  EXPECT_TRUE(ok.status.is_ok());
  b[20] ^= 1;  // total size high bytes
  expect_rejected(b, "bytes");
}

TEST(MapImageTest, TruncatedAndPaddedFilesAreRejected) {
  const std::vector<std::uint8_t> good = image_of(test_grid());
  for (std::size_t keep : {std::size_t{0}, std::size_t{10}, std::size_t{31}, std::size_t{32}, std::size_t{100},
                           good.size() / 2, good.size() - 1}) {
    std::vector<std::uint8_t> b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(keep));
    if (keep == 0) b.push_back(0);  // empty buffers: give the loader one byte
    expect_rejected(b, keep < 32 ? "truncated" : "truncated or padded");
  }
  std::vector<std::uint8_t> b = good;
  b.push_back(0);
  expect_rejected(b, "truncated or padded");
}

TEST(MapImageTest, WrongMagicAndVersionAreRejected) {
  const std::vector<std::uint8_t> good = image_of(test_grid());
  std::vector<std::uint8_t> b = good;
  b[0] = 'X';
  expect_rejected(b, "bad magic");
  b = good;
  wr32(&b, 8, 2);
  refresh_crcs(&b);
  expect_rejected(b, "format version 2");
  b = good;
  wr32(&b, section_entry(b, fw::MapSectionType::kDistanceField) + 4, 9);
  refresh_crcs(&b);
  expect_rejected(b, "distance field section version 9");
}

TEST(MapImageTest, SectionSizeLiesAreRejectedEvenWithValidCrcs) {
  const OccupancyGrid g = test_grid();
  const std::vector<std::uint8_t> good = image_of(g);
  // Section claims to run past the end of the image.
  std::vector<std::uint8_t> b = good;
  std::size_t e = section_entry(b, fw::MapSectionType::kOccupancy);
  wr32(&b, e + 16, static_cast<std::uint32_t>(good.size()));
  refresh_crcs(&b);
  expect_rejected(b, "outside the image");
  // Occupancy section shorter than the geometry says (shrunk by one byte, CRCs honest).
  b = good;
  wr32(&b, e + 16, rd32(b, e + 16) - 1);
  refresh_crcs(&b);
  expect_rejected(b, "occupancy section is 1199 bytes");
  // Geometry lies about the width.
  b = good;
  const std::size_t geo = rd32(b, section_entry(b, fw::MapSectionType::kGeometry) + 8);
  wr32(&b, geo + 12, 41);
  refresh_crcs(&b);
  expect_rejected(b, "geometry 41x30");
  // Geometry lies about the point count.
  b = good;
  wr32(&b, geo + 20, rd32(b, geo + 20) + 1);
  refresh_crcs(&b);
  expect_rejected(b, "occupied points section");
  // Overlapping sections.
  b = good;
  const std::size_t e_dist = section_entry(b, fw::MapSectionType::kDistanceField);
  wr32(&b, e_dist + 8, rd32(b, e + 8));
  refresh_crcs(&b);
  expect_rejected(b, "overlap");
  // Section table count beyond the file.
  b = good;
  wr32(&b, 12, 65);
  refresh_crcs(&b);
  expect_rejected(b, "65 sections");
  // Missing required section (type renamed).
  b = good;
  wr32(&b, section_entry(b, fw::MapSectionType::kOccupiedPoints), static_cast<std::uint32_t>(fw::MapSectionType::kUser));
  refresh_crcs(&b);
  expect_rejected(b, "missing occupied points section");
}

TEST(MapImageTest, BadFloatsAndInconsistentContentsAreRejected) {
  const std::vector<std::uint8_t> good = image_of(test_grid());
  const std::size_t dist = rd32(good, section_entry(good, fw::MapSectionType::kDistanceField) + 8);
  const std::size_t pts = rd32(good, section_entry(good, fw::MapSectionType::kOccupiedPoints) + 8);
  const std::size_t occ = rd32(good, section_entry(good, fw::MapSectionType::kOccupancy) + 8);
  const std::size_t geo = rd32(good, section_entry(good, fw::MapSectionType::kGeometry) + 8);
  auto put_f = [](std::vector<std::uint8_t>* b, std::size_t at, float f) {
    std::uint32_t u;
    std::memcpy(&u, &f, 4);
    wr32(b, at, u);
  };
  std::vector<std::uint8_t> b = good;
  put_f(&b, dist + 4 * 45, std::numeric_limits<float>::quiet_NaN());
  refresh_crcs(&b);
  expect_rejected(b, "NaN");
  b = good;
  put_f(&b, dist + 4 * 45, -1.0f);
  refresh_crcs(&b);
  expect_rejected(b, "negative");
  b = good;
  put_f(&b, dist + 4 * 45, 0.0f);  // cell 45 is free: distance 0 is a lie
  refresh_crcs(&b);
  expect_rejected(b, "not occupied");
  b = good;
  put_f(&b, pts, std::numeric_limits<float>::infinity());
  refresh_crcs(&b);
  expect_rejected(b, "occupied point 0");
  b = good;
  put_f(&b, pts, -1.0f);  // point 0 moved into a free cell
  put_f(&b, pts + 4, 2.0f);
  refresh_crcs(&b);
  expect_rejected(b, "not inside an occupied cell");
  b = good;
  b[occ + 45] = 150;
  refresh_crcs(&b);
  expect_rejected(b, "invalid value 150");
  b = good;
  put_f(&b, geo, std::numeric_limits<float>::quiet_NaN());
  refresh_crcs(&b);
  expect_rejected(b, "resolution");
  b = good;
  put_f(&b, geo, -0.1f);
  refresh_crcs(&b);
  expect_rejected(b, "resolution");
  b = good;
  put_f(&b, geo + 24, 99.0f);
  refresh_crcs(&b);
  expect_rejected(b, "max distance");
}

void put_f32(std::vector<std::uint8_t>* b, std::size_t at, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  wr32(b, at, u);
}
float get_f32(const std::vector<std::uint8_t>& b, std::size_t at) {
  const std::uint32_t u = rd32(b, at);
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}
std::size_t payload(const std::vector<std::uint8_t>& b, fw::MapSectionType t) { return rd32(b, section_entry(b, t) + 8); }
// Keeps the geometry's max distance equal to the field's (so that check does not catch the edit first).
void fix_max_distance(std::vector<std::uint8_t>* b) {
  const std::size_t dist = payload(*b, fw::MapSectionType::kDistanceField);
  const std::size_t cells = rd32(*b, section_entry(*b, fw::MapSectionType::kDistanceField) + 16) / 4;
  float m = 0.0f;
  for (std::size_t i = 0; i < cells; ++i) m = std::max(m, get_f32(*b, dist + 4 * i));
  put_f32(b, payload(*b, fw::MapSectionType::kGeometry) + 24, m);
}

// Issue 13: the loader accepted a distance field that is not the map's (only "0 exactly on occupied
// cells" was checked), with CRCs made honest. It is now recomputed and compared cell by cell.
TEST(MapImageTest, WrongDistanceFieldIsRejected) {
  const OccupancyGrid g = test_grid();
  const std::vector<std::uint8_t> good = image_of(g);
  const std::size_t dist = payload(good, fw::MapSectionType::kDistanceField);
  const std::size_t cell = g.geometry.index(9, 9);  // free, 9 cells from the walls x = 0 and y = 0
  ASSERT_EQ(get_f32(good, dist + 4 * cell), std::sqrt(81.0f) * 0.1f);
  // One cell a little off (still positive and finite).
  std::vector<std::uint8_t> b = good;
  put_f32(&b, dist + 4 * cell, 1.0f);
  fix_max_distance(&b);
  refresh_crcs(&b);
  expect_rejected(b, "distance field cell 369 (x 9, y 9) is 1 m, the occupied cells put it at 0.9");
  // One ulp off.
  b = good;
  put_f32(&b, dist + 4 * cell, std::nextafter(get_f32(good, dist + 4 * cell), 1.0f));
  fix_max_distance(&b);
  refresh_crcs(&b);
  expect_rejected(b, "does not belong to this map");
  // The whole field of another map with the same size and maximum: the same walls shifted by a cell.
  OccupancyGrid shifted = g;
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 40; ++x) shifted.cells[g.geometry.index(x, y)] = g.cells[g.geometry.index(x == 20 ? 21 : x == 21 ? 20 : x, y)];
  }
  const std::vector<std::uint8_t> other = image_of(shifted);
  const std::size_t other_dist = payload(other, fw::MapSectionType::kDistanceField);
  b = good;
  bool differs = false;
  for (std::size_t i = 0; i < g.cells.size(); ++i) {
    if (g.cells[i] == fw::kCellOccupied) continue;  // keep 0 exactly on this map's walls
    const float d = get_f32(other, other_dist + 4 * i);
    if (d == 0.0f) continue;
    differs = differs || d != get_f32(b, dist + 4 * i);
    put_f32(&b, dist + 4 * i, d);
  }
  ASSERT_TRUE(differs);
  fix_max_distance(&b);
  refresh_crcs(&b);
  expect_rejected(b, "does not belong to this map");
}

// Issue 13: duplicated occupied points were accepted (each lay "inside an occupied cell"; only the
// count was compared). Points are one per occupied cell, at its centre, in row-major order.
TEST(MapImageTest, DuplicateMisorderedOrOffCentrePointsAreRejected) {
  const std::vector<std::uint8_t> good = image_of(test_grid());
  const std::size_t pts = payload(good, fw::MapSectionType::kOccupiedPoints);
  std::vector<std::uint8_t> b = good;
  wr32(&b, pts + 8, rd32(b, pts));  // point 1 := point 0 (count unchanged, point 1's cell left without one)
  wr32(&b, pts + 12, rd32(b, pts + 4));
  refresh_crcs(&b);
  expect_rejected(b, "occupied point 1 (-1.95, 1.05) duplicates point 0");
  b = good;
  const std::size_t last = pts + 8 * (rd32(b, payload(b, fw::MapSectionType::kGeometry) + 20) - 1);
  wr32(&b, last, rd32(b, pts));  // the last point repeats the first: not adjacent, out of order
  wr32(&b, last + 4, rd32(b, pts + 4));
  refresh_crcs(&b);
  expect_rejected(b, "out of row-major order");
  b = good;
  for (int k = 0; k < 8; ++k) std::swap(b[pts + k], b[pts + 8 + k]);  // two points swapped
  refresh_crcs(&b);
  expect_rejected(b, "occupied point 1");
  b = good;
  put_f32(&b, pts, get_f32(b, pts) + 0.04f);  // still inside its 0.1 m cell, but not at its centre
  refresh_crcs(&b);
  expect_rejected(b, "is not at the centre (-1.95, 1.05) of its cell");
}

// Issue 13: non-zero reserved fields (geometry word 7, each section entry's last word) and padding
// were ignored: an image from an unknown writer loaded as if it meant nothing.
TEST(MapImageTest, NonZeroReservedFieldsAndPaddingAreRejected) {
  const std::vector<std::uint8_t> good = image_of(test_grid());
  std::vector<std::uint8_t> b = good;
  wr32(&b, payload(b, fw::MapSectionType::kGeometry) + 28, 1);
  refresh_crcs(&b);
  expect_rejected(b, "geometry: reserved field is 0x00000001, must be 0");
  b = good;
  wr32(&b, section_entry(b, fw::MapSectionType::kDistanceField) + 28, 0xdead);
  refresh_crcs(&b);
  expect_rejected(b, "section 2 (distance field): reserved field is 0x0000dead, must be 0");
  // Padding between two sections of 3 and 1 bytes (the map sections happen to need none).
  MapImageWriter w;
  std::string err;
  ASSERT_TRUE(w.set_grid(test_grid(), &err)) << err;
  ASSERT_TRUE(w.add_section(fw::MapSectionType::kRelationTable2D, {1, 2, 3}, 1, &err)) << err;
  ASSERT_TRUE(w.add_section(fw::MapSectionType::kUser, {4}, 1, &err)) << err;
  const std::vector<std::uint8_t> padded = w.bytes();
  b = padded;
  const std::size_t pad = payload(b, fw::MapSectionType::kRelationTable2D) + 3;
  ASSERT_LT(pad, payload(b, fw::MapSectionType::kUser));
  Loaded ok;
  load(b, &ok);
  ASSERT_TRUE(ok.status.is_ok()) << ok.status.message();
  b[pad] = 0x5a;
  refresh_crcs(&b);
  expect_rejected(b, "between sections is 0x5a (padding must be zero)");
  // Header flags (already refused before issue 13; kept here with its siblings).
  b = good;
  wr32(&b, 24, 2);
  refresh_crcs(&b);
  expect_rejected(b, "unknown header flags 0x2");
}

// Issue 13: the geometry of `origin: [-1e38, -1e38, 0]` (every cell centre the same float) loaded.
TEST(MapImageTest, GeometryFloatsCannotResolveIsRejected) {
  const std::vector<std::uint8_t> good = image_of(test_grid());
  const std::size_t geo = payload(good, fw::MapSectionType::kGeometry);
  std::vector<std::uint8_t> b = good;
  put_f32(&b, geo + 4, -1e38f);
  put_f32(&b, geo + 8, -1e38f);
  refresh_crcs(&b);
  expect_rejected(b, "geometry: the grid reaches more than 2^19 cells from the world origin");
  b = good;
  put_f32(&b, geo, 1e-30f);
  refresh_crcs(&b);
  expect_rejected(b, "geometry: resolution is outside [0.0001, 1000] m");
  // The writer refuses such a grid before making an image of it.
  OccupancyGrid g = test_grid();
  g.geometry.origin_x = -1e38f;
  MapImageWriter w;
  std::string err;
  EXPECT_FALSE(w.set_grid(g, &err));
  EXPECT_NE(err.find("cannot resolve the cells"), std::string::npos) << err;
}

TEST(MapImageTest, ArenaBytesCoverThePeakAndScratchIsReleased) {
  const std::vector<std::uint8_t> bytes = image_of(test_grid());
  const std::size_t need = fw::map_image_arena_bytes(bytes.data(), bytes.size());
  ASSERT_GT(need, 0u);
  fw::StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(need, false, "exact").is_ok());
  fw::GlobalMap m;
  const fw::Status st = fw::load_map_image(bytes.data(), bytes.size(), arena, &m, "x.mmap");
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_LE(arena.peak_used(), need);
  EXPECT_GT(arena.peak_used(), arena.used());  // the distance check's scratch came and went
  // Kept: occupancy, distance tile index (3 × 2) and tiles, points; the dense float check is scratch.
  EXPECT_EQ(arena.used(), m.occupancy.bytes() + m.distance.bytes() + m.num_points * sizeof(fw::Point2f));
  EXPECT_EQ(m.distance.bytes(), 6u * 4u + m.distance.stored_tiles * 512u + (m.distance.saturation_d2 + 1u) * 4u);
  EXPECT_EQ(fw::map_image_arena_bytes(bytes.data(), 10), 0u);
  fw::MemoryReport::instance().clear();
}

// Issue 13: a FIFO given as the firmware's map blocked open() forever; /dev/zero and a directory are
// refused the same way (not a regular file), with the path in the message.
TEST(MapImageTest, MapFileThatIsNotARegularFileIsRefusedWithoutBlocking) {
  const std::string fifo =
      (std::filesystem::temp_directory_path() / ("map_image_fifo_" + std::to_string(::getpid()) + ".mmap")).string();
  std::filesystem::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& path : {fifo, std::string("/dev/zero"), std::filesystem::temp_directory_path().string()}) {
    fw::MapImageFile f;
    const fw::Status st = f.open(path.c_str());
    ASSERT_FALSE(st.is_ok()) << path;
    EXPECT_NE(std::strstr(st.message(), path.c_str()), nullptr) << st.message();
    EXPECT_NE(std::strstr(st.message(), "not a regular file"), nullptr) << st.message();
  }
  std::filesystem::remove(fifo);
}

TEST(MapImageTest, LoadingDoesNotTouchTheHeap) {
  if (!mmlfw_test::AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  MapImageWriter w;
  std::string err;
  ASSERT_TRUE(w.set_grid(test_grid(), &err)) << err;
  ASSERT_TRUE(w.add_section(fw::MapSectionType::kRelationTable2D, {9, 9, 9}, 1, &err)) << err;
  const std::string path =
      (std::filesystem::temp_directory_path() / ("map_image_heap_" + std::to_string(::getpid()) + ".mmap")).string();
  ASSERT_TRUE(w.write(path, &err)) << err;
  fw::StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(1 << 20, false, "t").is_ok());
  fw::GlobalMap m;
  fw::MapImageFile file;
  mmlfw_test::AllocCounter::begin();
  const fw::Status open = file.open(path.c_str());
  const fw::Status st = open.is_ok() ? fw::load_map_image(file.data(), file.size(), arena, &m, path.c_str()) : open;
  std::size_t len = 0;
  const std::uint8_t* extra = fw::find_section(file.data(), file.size(), fw::MapSectionType::kRelationTable2D, &len);
  file.close();
  const long allocations = mmlfw_test::AllocCounter::end();
  std::filesystem::remove(path);
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_NE(extra, nullptr);
  EXPECT_EQ(len, 3u);
  EXPECT_EQ(allocations, 0);
}

TEST(MapImageTest, ArenaTooSmallIsAnErrorNotACrash) {
  const std::vector<std::uint8_t> bytes = image_of(test_grid());
  fw::StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(1000, false, "small").is_ok());
  fw::GlobalMap m;
  const fw::Status st = fw::load_map_image(bytes.data(), bytes.size(), arena, &m, "x.mmap");
  ASSERT_FALSE(st.is_ok());
  EXPECT_EQ(st.code(), fw::Errc::kCapacityExceeded);
}

TEST(MapImageTest, WriterRejectsEmptyMapsAndFileRoundTrip) {
  OccupancyGrid g = test_grid();
  for (auto& c : g.cells) c = fw::kCellFree;
  MapImageWriter w;
  std::string err;
  EXPECT_FALSE(w.set_grid(g, &err));
  EXPECT_NE(err.find("no occupied cells"), std::string::npos) << err;

  const std::string path = (std::filesystem::temp_directory_path() / ("map_image_test_" + std::to_string(::getpid()) + ".mmap")).string();
  ASSERT_TRUE(w.set_grid(test_grid(), &err)) << err;
  ASSERT_TRUE(w.write(path, &err)) << err;
  fw::StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(1 << 20, false, "t").is_ok());
  fw::GlobalMap m;
  fw::Status st = fw::load_map_image_file(path.c_str(), arena, &m);
  EXPECT_TRUE(st.is_ok()) << st.message();
  EXPECT_EQ(m.geometry.width, 40u);
  std::filesystem::remove(path);
  st = fw::load_map_image_file(path.c_str(), arena, &m);
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), path.c_str()), nullptr) << st.message();
}

}  // namespace
}  // namespace sim
