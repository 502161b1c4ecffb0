#include "firmware/pransam/relation_table_io.h"

#include <cmath>
#include <cstring>


namespace fw::pransam {

namespace {
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the section is read in place: little-endian only");
void put32(std::uint8_t* p, std::uint32_t v) { std::memcpy(p, &v, 4); }
void put64(std::uint8_t* p, std::uint64_t v) { std::memcpy(p, &v, 8); }
std::uint32_t get32(const std::uint8_t* p) { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
std::uint64_t get64(const std::uint8_t* p) { std::uint64_t v; std::memcpy(&v, p, 8); return v; }
float getf(const std::uint8_t* p) { float v; std::memcpy(&v, p, 4); return v; }
void putf(std::uint8_t* p, float v) { std::memcpy(p, &v, 4); }
}  // namespace

std::uint32_t model_points_hash(const float* xyz, std::size_t n, int dim) {
  // FNV-1a over the bytes: an identity check, not error detection (the map image CRCs do that).
  const std::uint8_t* p = reinterpret_cast<const std::uint8_t*>(xyz);
  const std::size_t bytes = n * static_cast<std::size_t>(dim) * sizeof(float);
  std::uint32_t h = 2166136261u;
  for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 16777619u;
  return h;
}

Status write_relation_table_section(const RelationTable& table, int dim, float min_height_ratio, const float* model_xyz,
                                    std::uint32_t num_model_points, std::uint64_t triples, std::uint8_t* out,
                                    std::size_t capacity) {
  if (!table.valid()) return Status::error(Errc::kNotInitialized, "relation table section: table not allocated");
  if (dim != 2 && dim != 3) return Status::error(Errc::kInvalidArgument, "relation table section: dim %d", dim);
  if (capacity < relation_table_section_bytes()) {
    return Status::error(Errc::kCapacityExceeded, "relation table section: buffer %zu < %zu bytes", capacity,
                         relation_table_section_bytes());
  }
  std::memcpy(out, "PRTB", 4);
  put32(out + 4, kRelationTableSectionVersion);
  put32(out + 8, static_cast<std::uint32_t>(dim));
  put32(out + 12, kSlotsPerAxis);
  putf(out + 16, table.extent());
  putf(out + 20, min_height_ratio);
  put32(out + 24, num_model_points);
  put32(out + 28, model_points_hash(model_xyz, num_model_points, dim));
  put64(out + 32, triples);
  put32(out + 40, static_cast<std::uint32_t>(table.count_filled()));
  put32(out + 44, 0);
  std::memcpy(out + kRelationTableHeaderBytes, table.data(), kNumSlots * sizeof(Triple));
  return Status::ok();
}

Status parse_relation_table_section(const std::uint8_t* bytes, std::size_t len, int dim, const float* model_xyz,
                                    std::uint32_t num_model_points, RelationTableSection* out, const char* name) {
  if (bytes == nullptr || len < kRelationTableHeaderBytes) {
    return Status::error(Errc::kCorruptData, "%s: %zu bytes, shorter than the %zu-byte header", name, len,
                         kRelationTableHeaderBytes);
  }
  if (std::memcmp(bytes, "PRTB", 4) != 0) return Status::error(Errc::kCorruptData, "%s: bad magic", name);
  if (get32(bytes + 4) != kRelationTableSectionVersion) {
    return Status::error(Errc::kUnsupported, "%s: version %u (expected %u)", name, get32(bytes + 4),
                         kRelationTableSectionVersion);
  }
  if (get32(bytes + 8) != static_cast<std::uint32_t>(dim)) {
    return Status::error(Errc::kInvalidArgument, "%s: table is %u-D, matcher is %d-D", name, get32(bytes + 8), dim);
  }
  if (get32(bytes + 12) != kSlotsPerAxis) {
    return Status::error(Errc::kUnsupported, "%s: %u slots per axis, firmware built with %u", name, get32(bytes + 12),
                         kSlotsPerAxis);
  }
  if (len != relation_table_section_bytes()) {
    return Status::error(Errc::kCorruptData, "%s: %zu bytes, expected %zu", name, len, relation_table_section_bytes());
  }
  const float extent = getf(bytes + 16);
  if (!(extent > 0.0f) || !std::isfinite(extent)) {
    return Status::error(Errc::kCorruptData, "%s: extent %g is not positive", name, static_cast<double>(extent));
  }
  const std::uint32_t n = get32(bytes + 24);
  if (n != num_model_points) {
    return Status::error(Errc::kInvalidArgument, "%s: built for %u model points, map has %u", name, n,
                         num_model_points);
  }
  const std::uint32_t hash = model_points_hash(model_xyz, num_model_points, dim);
  if (get32(bytes + 28) != hash) {
    return Status::error(Errc::kInvalidArgument, "%s: model point hash 0x%08x != map's 0x%08x (table of another map)",
                         name, get32(bytes + 28), hash);
  }
  if ((reinterpret_cast<std::uintptr_t>(bytes + kRelationTableHeaderBytes) % alignof(Triple)) != 0) {
    return Status::error(Errc::kInvalidArgument, "%s: payload not 4-byte aligned (cannot be used in place)", name);
  }
  out->dim = static_cast<std::uint32_t>(dim);
  out->extent = extent;
  out->min_height_ratio = getf(bytes + 20);
  out->num_model_points = n;
  out->model_points_hash = hash;
  out->triples = get64(bytes + 32);
  out->filled = get32(bytes + 40);
  out->slots = reinterpret_cast<const Triple*>(bytes + kRelationTableHeaderBytes);
  return Status::ok();
}

}  // namespace fw::pransam
