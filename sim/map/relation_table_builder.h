// Offline fill of pRANSAM's global relation table R_B (dissertation Sec. 5.5.2, Theorem 2) as a
// kRelationTable2D section of a compiled map image. The table is filled exactly as MmlLocalizer
// fills it at start-up when an image has none (same seed derivation, triple count h, extent and
// collinearity bound of MML configuration `preset`), so a robot started with the section localizes
// identically, minus the start-up fill time.
#pragma once

#include <cstdint>
#include <string>

#include "sim/map/map_image_writer.h"

namespace sim {

struct RelationTableBuild {
  std::uint64_t seed = 1;  // the firmware's `seed` (mmlfw config)
  int preset = 3;          // MML configuration C1..C4 (firmware/mml/mml_presets.h)
};

struct RelationTableBuildReport {
  double seconds = 0.0;
  std::uint64_t triples = 0;
  std::uint32_t map_points = 0;
  std::size_t section_bytes = 0;
};

// `writer` must hold a map (set_map / set_grid). Appends the section; `name` is used in messages.
bool add_relation_table(MapImageWriter* writer, const RelationTableBuild& build, const std::string& name,
                        RelationTableBuildReport* report, std::string* error);

}  // namespace sim
