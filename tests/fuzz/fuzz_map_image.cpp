// libFuzzer target: the compiled map image (firmware/map/map_image.*) and the pRANSAM relation
// table section it may carry (firmware/pransam/relation_table_io.*, Matcher::use_precomputed_table),
// i.e. everything mmlfw does with an image file at start-up. Input: one flags byte, then the image.
// Flag bit 0 makes the harness rewrite every section CRC and the image CRC after the fuzzer's
// mutation, so mutated section contents reach the section validators instead of stopping at a CRC
// mismatch; bit 1 also rewrites total_size. The fuzz preset builds with 8 slots per axis
// (MMLFW_PRANSAM_SLOTS_PER_AXIS) so a relation table section is 6 KB instead of 6 MB.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/crc32.h"
#include "firmware/map/global_map.h"
#include "firmware/map/map_image.h"
#include "firmware/pransam/matcher.h"
#include "firmware/pransam/relation_table_io.h"

namespace {

std::uint32_t get32(const std::uint8_t* p) { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
std::uint64_t get64(const std::uint8_t* p) { std::uint64_t v; std::memcpy(&v, p, 8); return v; }
void put32(std::uint8_t* p, std::uint32_t v) { std::memcpy(p, &v, 4); }
void put64(std::uint8_t* p, std::uint64_t v) { std::memcpy(p, &v, 8); }

// What a writer would have stored for these bytes (little-endian host, as the format).
void fix_crcs(std::vector<std::uint8_t>& img, bool fix_size) {
  if (img.size() < fw::kMapImageHeaderBytes) return;
  if (fix_size) put64(img.data() + 16, img.size());
  const std::uint32_t n = get32(img.data() + 12);
  for (std::uint32_t i = 0; i < n && i < fw::kMaxMapSections; ++i) {
    std::uint8_t* e = img.data() + fw::kMapImageHeaderBytes + i * fw::kMapSectionEntryBytes;
    if (e + fw::kMapSectionEntryBytes > img.data() + img.size()) break;
    const std::uint64_t off = get64(e + 8), len = get64(e + 16);
    if (off <= img.size() && len <= img.size() - off) put32(e + 24, fw::crc32(img.data() + off, len));
  }
  put32(img.data() + 28, 0);
  put32(img.data() + 28, fw::crc32(img.data(), img.size()));
}

struct Fixture {
  std::vector<std::uint8_t> block = std::vector<std::uint8_t>(std::size_t(96) << 20);
  fw::StartupArena arena;
  fw::pransam::Matcher<2> matcher;
  bool matcher_ok = false;
  Fixture() {
    if (!arena.init(block.data(), block.size(), "fuzz arena")) std::abort();
    fw::pransam::MatcherOptions mo;
    mo.num_workers = 1;
    mo.max_model_points = 65536;
    mo.allocate_model_table = false;
    matcher_ok = matcher.init(mo, arena, nullptr).is_ok();
    if (!matcher_ok) std::abort();
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static Fixture* fx = new Fixture;
  if (size < 1) return 0;
  std::vector<std::uint8_t> img(data + 1, data + size);
  if (data[0] & 1) fix_crcs(img, data[0] & 2);
  (void)fw::verify_map_image(img.data(), img.size(), "fuzz.mmap");
  const std::size_t need = fw::map_image_arena_bytes(img.data(), img.size());
  if (need > fx->arena.capacity() - fx->arena.mark()) return 0;  // the firmware's arena would refuse it too
  const std::size_t mark = fx->arena.mark();
  fw::GlobalMap map{};
  const fw::Status st = fw::load_map_image(img.data(), img.size(), fx->arena, &map, "fuzz.mmap");
  if (st) {
    if (!map.valid() || map.num_points == 0) {
      std::fprintf(stderr, "fuzz_map_image: accepted image without a usable map\n");
      std::abort();
    }
    std::size_t len = 0;
    const std::uint8_t* table = fw::find_section(img.data(), img.size(), fw::MapSectionType::kRelationTable2D, &len);
    if (table != nullptr) {
      fw::pransam::RelationTableSection sec;
      // As MmlLocalizer::init: parse against the map's points, then let the matcher check indices.
      if (fw::pransam::parse_relation_table_section(table, len, 2, reinterpret_cast<const float*>(map.points),
                                                    map.num_points, &sec, "fuzz table").is_ok() &&
          fx->matcher.set_model(map.points, map.num_points, "fuzz map").is_ok()) {
        (void)fx->matcher.use_precomputed_table(sec.slots, sec.extent, "fuzz table");
      }
    }
  }
  fx->arena.rewind(mark);
  return 0;
}
