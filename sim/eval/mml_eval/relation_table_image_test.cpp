// The offline relation table of mml-mapc --relation-table must be the table MmlLocalizer fills at
// start-up: an image with the section and one without give identical pose estimates, step by step.
#include <gtest/gtest.h>

#include <cstring>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "firmware/mml/mml_presets.h"
#include "sim/eval/mml_eval/mml_systems.h"
#include "sim/map/relation_table_builder.h"
#include "sim/world/builtin_worlds.h"
#include "sim/world/raster.h"
#include "sim/world/synthetic_run.h"

namespace {

TEST(RelationTableImage, OfflineSectionLocalizesLikeTheStartupFill) {
  std::string err;
  sim::World world;
  ASSERT_TRUE(sim::make_builtin_world("small-office", &world, &err)) << err;
  sim::OccupancyGrid grid;
  ASSERT_TRUE(sim::rasterize_world(world, sim::RasterOptions(), &grid, &err)) << err;

  sim::MapImageWriter plain_writer;
  ASSERT_TRUE(plain_writer.set_grid(grid, &err)) << err;
  const std::vector<std::uint8_t> plain = plain_writer.bytes();
  sim::MapImageWriter table_writer;
  ASSERT_TRUE(table_writer.set_grid(grid, &err)) << err;
  sim::RelationTableBuild build;
  build.seed = 5;
  sim::RelationTableBuildReport rep;
  ASSERT_TRUE(sim::add_relation_table(&table_writer, build, "small-office", &rep, &err)) << err;
  const std::vector<std::uint8_t> with_table = table_writer.bytes();
  EXPECT_GT(with_table.size(), plain.size() + rep.section_bytes - 1) << "one more section";
  std::size_t len = 0;
  ASSERT_NE(fw::find_section(with_table.data(), with_table.size(), fw::MapSectionType::kRelationTable2D, &len),
            nullptr);
  EXPECT_EQ(fw::find_section(plain.data(), plain.size(), fw::MapSectionType::kRelationTable2D, &len), nullptr);

  fw::StartupArena map_arena;
  fw::GlobalMap map;
  ASSERT_TRUE(map_arena.init_mapped(with_table.size() + (4u << 20), false, "test map").is_ok());
  ASSERT_TRUE(fw::load_map_image(with_table.data(), with_table.size(), map_arena, &map, "with table").is_ok());

  const auto cfg = fw::mml::mml_preset(3, build.seed);
  auto a = sim::mmleval::OwnedLocalizer::make_mml(map, plain, cfg, 1, &err);
  ASSERT_NE(a, nullptr) << err;
  auto b = sim::mmleval::OwnedLocalizer::make_mml(map, with_table, cfg, 1, &err);
  ASSERT_NE(b, nullptr) << err;
  EXPECT_TRUE(a->mml()->using_precomputed_table());
  EXPECT_TRUE(b->mml()->using_precomputed_table());

  sim::SyntheticRun run;
  sim::SyntheticRunOptions ro;
  ro.seed = 3;
  ro.max_scans = 25;
  ASSERT_TRUE(run.init(world, ro, &err)) << err;
  sim::SyntheticFrame f;
  int steps = 0, non_searching = 0;
  while (run.next(&f)) {
    ASSERT_FALSE(f.odometry.empty());
    hal::PoseEstimate pa{}, pb{};
    ASSERT_TRUE(a->step(f.scan, f.odometry.back(), &pa).is_ok());
    ASSERT_TRUE(b->step(f.scan, f.odometry.back(), &pb).is_ok());
    ASSERT_EQ(pa.status, pb.status) << "step " << steps;
    ASSERT_EQ(std::memcmp(&pa.x, &pb.x, sizeof(pa.x)), 0) << "step " << steps;
    ASSERT_EQ(std::memcmp(&pa.y, &pb.y, sizeof(pa.y)), 0) << "step " << steps;
    ASSERT_EQ(std::memcmp(&pa.theta, &pb.theta, sizeof(pa.theta)), 0) << "step " << steps;
    non_searching += pa.status != hal::LocalizationStatus::kSearching;
    ++steps;
  }
  EXPECT_EQ(steps, 25);
  EXPECT_GT(non_searching, 0) << "the run never got past 'searching'; the comparison says little";
}

TEST(RelationTableImage, RefusesAWriterWithoutAMap) {
  sim::MapImageWriter empty;
  std::string err;
  EXPECT_FALSE(sim::add_relation_table(&empty, sim::RelationTableBuild(), "nothing", nullptr, &err));
  EXPECT_NE(err.find("nothing"), std::string::npos) << err;
}

}  // namespace
