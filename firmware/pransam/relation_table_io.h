// Precomputed relation table as a map-image section (Sec. 5.5.2; MapSectionType::kRelationTable2D /
// kRelationTable3D). The payload is used IN PLACE at run time (sections are 16-byte aligned), so
// the dense slot array is stored as is. A header ties the table to the model point set it indexes
// (count + FNV-1a hash of the points' bytes) so a table built for another map is refused.
//
// Layout (little-endian):
//   0 char[4] "PRTB"   4 u32 version (1)   8 u32 dim (2|3)   12 u32 slots per axis
//  16 f32 extent (m)  20 f32 min_height_ratio  24 u32 model points  28 u32 FNV-1a hash of the model points
//  32 u64 triples inserted   40 u32 filled slots   44 u32 reserved (0)
//  48 slots: (slots per axis)³ × 3 u32 point indices (0xFFFFFFFF = empty)
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "firmware/pransam/relation_table.h"

namespace fw::pransam {

constexpr std::uint32_t kRelationTableSectionVersion = 1;
constexpr std::size_t kRelationTableHeaderBytes = 48;

struct RelationTableSection {
  std::uint32_t dim = 0;
  float extent = 0.0f;
  float min_height_ratio = 0.0f;
  std::uint32_t num_model_points = 0;
  std::uint32_t model_points_hash = 0;
  std::uint64_t triples = 0;
  std::uint32_t filled = 0;
  const Triple* slots = nullptr;  // points into the section bytes
};

constexpr std::size_t relation_table_section_bytes() { return kRelationTableHeaderBytes + kNumSlots * sizeof(Triple); }

// FNV-1a hash of n D-dimensional float points (as stored, x y [z] per point).
std::uint32_t model_points_hash(const float* xyz, std::size_t n, int dim);

// Serialises `table` (filled over the given model points) into out[0, relation_table_section_bytes()).
Status write_relation_table_section(const RelationTable& table, int dim, float min_height_ratio, const float* model_xyz,
                                    std::uint32_t num_model_points, std::uint64_t triples, std::uint8_t* out,
                                    std::size_t capacity);

// Validates a payload against the model points it must index and returns a view of it.
Status parse_relation_table_section(const std::uint8_t* bytes, std::size_t len, int dim, const float* model_xyz,
                                    std::uint32_t num_model_points, RelationTableSection* out,
                                    const char* name = "relation table section");

}  // namespace fw::pransam
