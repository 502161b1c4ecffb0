// MapImageFile: the image is read into memory the firmware owns, so a file truncated or replaced on
// disk during or after start-up cannot kill it with SIGBUS (issue 13: `truncate -s 4096 map.mmap`
// while mmlfw ran with a relation table killed it after 34 poses; a truncation during start-up
// killed it in the CRC check). Built from the format description alone (no host writer), so it also
// runs in the cross builds.
#include "firmware/map/map_image_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/crc32.h"
#include "firmware/map/global_map.h"
#include "firmware/map/map_image.h"

namespace fw {
namespace {

void put32(std::vector<std::uint8_t>* b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) (*b)[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void put64(std::vector<std::uint8_t>* b, std::size_t at, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) (*b)[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}
void putf(std::vector<std::uint8_t>* b, std::size_t at, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  put32(b, at, u);
}

// A valid image: 2 x 2 grid at 1 m, every cell occupied (distance field all 0), plus a "relation
// table" stand-in of `table_bytes` (kRelationTable2D, opaque to the loader) so the file spans many
// pages, as a real image with pRANSAM's 6 MB table does.
std::vector<std::uint8_t> image_with_table(std::size_t table_bytes) {
  const std::size_t n_sections = 5;
  std::vector<std::vector<std::uint8_t>> pay(n_sections);
  pay[0].assign(kMapGeometryBytes, 0);
  putf(&pay[0], 0, 1.0f);   // resolution
  putf(&pay[0], 4, 0.0f);   // origin x
  putf(&pay[0], 8, 0.0f);   // origin y
  put32(&pay[0], 12, 2);    // width
  put32(&pay[0], 16, 2);    // height
  put32(&pay[0], 20, 4);    // points
  putf(&pay[0], 24, 0.0f);  // max distance
  pay[1].assign(4, kCellOccupied);
  pay[2].assign(16, 0);     // four 0.0f
  pay[3].assign(32, 0);
  const float centres[8] = {0.5f, 0.5f, 1.5f, 0.5f, 0.5f, 1.5f, 1.5f, 1.5f};
  for (int i = 0; i < 8; ++i) putf(&pay[3], 4 * i, centres[i]);
  pay[4].resize(table_bytes);
  for (std::size_t i = 0; i < table_bytes; ++i) pay[4][i] = static_cast<std::uint8_t>(i * 7 + 3);
  const std::uint32_t types[n_sections] = {1, 2, 3, 4, 16};

  std::size_t off = kMapImageHeaderBytes + n_sections * kMapSectionEntryBytes;
  std::vector<std::size_t> offs;
  for (const auto& p : pay) {
    off = (off + 15) / 16 * 16;
    offs.push_back(off);
    off += p.size();
  }
  std::vector<std::uint8_t> img(off, 0);
  std::memcpy(img.data(), kMapImageMagic, 8);
  put32(&img, 8, kMapImageVersion);
  put32(&img, 12, n_sections);
  put64(&img, 16, img.size());
  for (std::size_t i = 0; i < n_sections; ++i) {
    const std::size_t e = kMapImageHeaderBytes + i * kMapSectionEntryBytes;
    put32(&img, e, types[i]);
    put32(&img, e + 4, 1);
    put64(&img, e + 8, offs[i]);
    put64(&img, e + 16, pay[i].size());
    put32(&img, e + 24, crc32(pay[i].data(), pay[i].size()));
    std::memcpy(img.data() + offs[i], pay[i].data(), pay[i].size());
  }
  put32(&img, 28, crc32(img.data(), img.size()));  // whole image with the CRC field still 0
  return img;
}

class MapImageFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/mmlfw-map-image-file.XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    path_ = dir_ + "/map.mmap";
    ASSERT_TRUE(arena_.init_mapped(1 << 20, false, "map-image-file-test").is_ok());
  }
  void TearDown() override {
    ::unlink(path_.c_str());
    ::rmdir(dir_.c_str());
  }
  void write(const std::vector<std::uint8_t>& bytes, std::size_t len) {
    FILE* f = std::fopen(path_.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    ASSERT_EQ(std::fwrite(bytes.data(), 1, len, f), len);
    std::fclose(f);
  }
  std::string dir_, path_;
  StartupArena arena_;
};

TEST_F(MapImageFileTest, TruncatedOnDiskAfterOpenIsNoSigbusDuringTheLoad) {
  const std::vector<std::uint8_t> img = image_with_table(256 * 1024);
  write(img, img.size());
  MapImageFile file;
  ASSERT_TRUE(file.open(path_.c_str()).is_ok());
  // The reproducer: the image shrinks on disk between open and the CRC check of the load.
  ASSERT_EQ(::truncate(path_.c_str(), 4096), 0);
  GlobalMap map;
  const Status s = load_map_image(file.data(), file.size(), arena_, &map, path_.c_str());
  ASSERT_TRUE(s.is_ok()) << s.message();
  EXPECT_EQ(map.num_points, 4u);
}

TEST_F(MapImageFileTest, RelationTableReadInPlaceSurvivesTruncationAndReplacement) {
  const std::vector<std::uint8_t> img = image_with_table(1 << 20);
  write(img, img.size());
  MapImageFile file;
  ASSERT_TRUE(file.open(path_.c_str()).is_ok());
  GlobalMap map;
  ASSERT_TRUE(load_map_image(file.data(), file.size(), arena_, &map, path_.c_str()).is_ok());
  std::size_t len = 0;
  const std::uint8_t* table = find_section(file.data(), file.size(), MapSectionType::kRelationTable2D, &len);
  ASSERT_NE(table, nullptr);
  ASSERT_EQ(len, std::size_t(1) << 20);
  const std::uint32_t crc_before = crc32(table, len);
  // Only the table's pages are kept after start-up (mmlfw, replay): the rest goes back.
  ASSERT_TRUE(file.retain(table, len).is_ok());
  EXPECT_EQ(file.data(), table);
  EXPECT_EQ(file.size(), len);
  const std::size_t page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  EXPECT_GE(file.mapped_bytes(), len);
  EXPECT_LE(file.mapped_bytes(), len + 2 * page);  // the table's pages, nothing else
  // The running firmware reads the table; meanwhile the file is truncated, then replaced.
  ASSERT_EQ(::truncate(path_.c_str(), 4096), 0);
  EXPECT_EQ(crc32(table, len), crc_before);
  const std::vector<std::uint8_t> other(img.size(), 0xEE);
  write(other, other.size());
  EXPECT_EQ(crc32(table, len), crc_before);
  ASSERT_EQ(::unlink(path_.c_str()), 0);
  EXPECT_EQ(crc32(table, len), crc_before);
  EXPECT_EQ(table[12345], static_cast<std::uint8_t>(12345 * 7 + 3));
  // Ranges outside the image are refused.
  EXPECT_FALSE(file.retain(table + 1, len).is_ok());
}

TEST_F(MapImageFileTest, TruncatedImageOnDiskIsAClearErrorNamingTheFile) {
  const std::vector<std::uint8_t> img = image_with_table(64 * 1024);
  write(img, 4096);  // `truncate -s 4096 map.mmap` before start-up
  MapImageFile file;
  const Status s = file.open(path_.c_str());
  ASSERT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), Errc::kCorruptData);
  EXPECT_NE(std::strstr(s.message(), path_.c_str()), nullptr) << s.message();
  EXPECT_NE(std::strstr(s.message(), "the file has 4096"), nullptr) << s.message();
  EXPECT_EQ(file.data(), nullptr);
  // Shorter than the header, not an image, empty, a directory: named errors too.
  write(img, 20);
  Status t = file.open(path_.c_str());
  EXPECT_NE(std::strstr(t.message(), "truncated: 20 bytes"), nullptr) << t.message();
  std::vector<std::uint8_t> junk(img);
  junk[0] = 'X';
  write(junk, junk.size());
  t = file.open(path_.c_str());
  EXPECT_NE(std::strstr(t.message(), "bad magic"), nullptr) << t.message();
  write(img, 0);
  t = file.open(path_.c_str());
  EXPECT_NE(std::strstr(t.message(), "empty file"), nullptr) << t.message();
  t = file.open(dir_.c_str());
  EXPECT_NE(std::strstr(t.message(), "not a regular file"), nullptr) << t.message();
}

TEST_F(MapImageFileTest, FifoIsRefusedWithoutBlocking) {
  const std::string fifo = dir_ + "/fifo.mmap";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  MapImageFile file;
  const Status s = file.open(fifo.c_str());
  ::unlink(fifo.c_str());
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::strstr(s.message(), "not a regular file"), nullptr) << s.message();
}

}  // namespace
}  // namespace fw
