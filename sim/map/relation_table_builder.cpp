#include "sim/map/relation_table_builder.h"

#include <chrono>
#include <cstring>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/map/global_map.h"
#include "firmware/mml/mml_presets.h"
#include "firmware/pransam/matcher.h"
#include "firmware/pransam/relation_table_io.h"

namespace sim {

bool add_relation_table(MapImageWriter* writer, const RelationTableBuild& build, const std::string& name,
                        RelationTableBuildReport* report, std::string* error) {
  const std::vector<std::uint8_t> image = writer->bytes();
  if (image.empty()) {
    *error = name + ": no map to build a relation table for";
    return false;
  }
  // The table indexes the occupied points in the order the firmware loader produces them.
  fw::StartupArena map_arena;
  fw::GlobalMap map;
  fw::Status s = map_arena.init_mapped(fw::map_image_arena_bytes(image.data(), image.size()) + (std::size_t(4) << 20),
                                       false, "table map");
  if (s.is_ok()) s = fw::load_map_image(image.data(), image.size(), map_arena, &map, name.c_str());
  if (!s.is_ok()) {
    *error = s.message();
    return false;
  }
  const fw::mml::MmlLocalizerConfig cfg =
      fw::mml::fit_contact_field_to_map(fw::mml::mml_preset(build.preset, build.seed), map);
  fw::pransam::MatcherOptions mo = cfg.matcher;
  mo.num_workers = 1;
  mo.allocate_model_table = true;
  const std::size_t arena_bytes = 2 * fw::pransam::kNumSlots * 12 +
                                  fw::pransam::ContactField<2>::arena_bytes(mo.field) +
                                  static_cast<std::size_t>(map.num_points) * 8 + mo.collect_capacity * 64 +
                                  (std::size_t(16) << 20);
  fw::StartupArena arena;
  fw::pransam::Matcher<2> matcher;
  s = arena.init_mapped(arena_bytes, false, "table build");
  if (s.is_ok()) s = matcher.init(mo, arena, nullptr);
  if (s.is_ok()) s = matcher.set_model(map.points, map.num_points, name.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  if (s.is_ok()) s = fw::mml::fill_global_relation_table(cfg, &matcher);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::vector<std::uint8_t> section(fw::pransam::relation_table_section_bytes());
  if (s.is_ok())
    s = fw::pransam::write_relation_table_section(matcher.model_table(), 2, cfg.match.min_height_ratio,
                                                  reinterpret_cast<const float*>(map.points), map.num_points,
                                                  cfg.mml.table_triples, section.data(), section.size());
  if (!s.is_ok()) {
    *error = name + ": relation table: " + s.message();
    return false;
  }
  if (report != nullptr) {
    report->seconds = seconds;
    report->triples = cfg.mml.table_triples;
    report->map_points = map.num_points;
    report->section_bytes = section.size();
  }
  return writer->add_section(fw::MapSectionType::kRelationTable2D, std::move(section),
                             fw::pransam::kRelationTableSectionVersion, error);
}

}  // namespace sim
