#include "firmware/app/system.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "firmware/mml/mml_test_util.h"

namespace fw {
namespace {

mml::MmlLocalizerConfig small_mml() {
  mml::MmlLocalizerConfig c = mml::default_mml_config();
  c.mml.matching_iterations = 2000;
  c.mml.table_triples = 100000;
  return c;
}

const mml::testing::OwnedGlobalMap& room_map() {
  static mcl::testing::GridWorld g = mcl::testing::unique_room();
  static mml::testing::OwnedGlobalMap m(g);
  return m;
}

TEST(LocalizationSystemTest, BuildsEveryKnownLocalizerByName) {
  for (const char* name : kLocalizerNames) {
    StartupArena arena;
    ASSERT_TRUE(arena.init_mapped(256u << 20, false, "system-test").is_ok());
    LocalizationSystem sys;
    SystemSpec spec;
    spec.localizer = name;
    const mml::MmlLocalizerConfig mc = small_mml();
    spec.mml = &mc;
    spec.mcl_particles = 2000;
    const Status s = sys.build(spec, room_map().map, nullptr, 0, arena, nullptr);
    ASSERT_TRUE(s.is_ok()) << name << ": " << s.message();
    EXPECT_STREQ(sys.name(), name);
    EXPECT_GT(sys.object_bytes(), 0u);
    // Only the parts the system needs are built.
    EXPECT_EQ(sys.tracked() != nullptr, std::strcmp(name, "mml-track") == 0) << name;
    EXPECT_EQ(sys.mcl() != nullptr, !std::strcmp(name, "mcl") || !std::strcmp(name, "handoff")) << name;
    EXPECT_EQ(sys.mml() != nullptr, std::strcmp(name, "mcl") && std::strcmp(name, "odom")) << name;
    // A second build of the same object is refused.
    EXPECT_FALSE(sys.build(spec, room_map().map, nullptr, 0, arena, nullptr).is_ok());
  }
}

TEST(LocalizationSystemTest, DefaultIsTheTrackedSystem) {
  EXPECT_STREQ(SystemSpec().localizer, "mml-track");
  EXPECT_STREQ(kDefaultLocalizer, "mml-track");
}

TEST(LocalizationSystemTest, ErrorsNameTheProblem) {
  StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(64u << 20, false, "system-test").is_ok());
  {
    LocalizationSystem sys;
    SystemSpec spec;
    spec.localizer = "magic";
    const Status s = sys.build(spec, room_map().map, nullptr, 0, arena, nullptr);
    EXPECT_NE(std::string(s.message()).find("unknown localizer 'magic'"), std::string::npos) << s.message();
  }
  {
    LocalizationSystem sys;
    SystemSpec spec;  // mml-track without a map
    const Status s = sys.build(spec, GlobalMap{}, nullptr, 0, arena, nullptr);
    EXPECT_NE(std::string(s.message()).find("needs a global map"), std::string::npos) << s.message();
  }
  {
    LocalizationSystem sys;
    SystemSpec spec;
    track::TrackOptions bad;
    bad.alert_limit_m = 0.0f;
    spec.track = &bad;
    const mml::MmlLocalizerConfig mc = small_mml();
    spec.mml = &mc;
    const Status s = sys.build(spec, room_map().map, nullptr, 0, arena, nullptr);
    EXPECT_NE(std::string(s.message()).find("alert_limit_m"), std::string::npos) << s.message();
  }
  {
    LocalizationSystem sys;
    SystemSpec spec;
    spec.localizer = "odom";  // needs no map
    EXPECT_TRUE(sys.build(spec, GlobalMap{}, nullptr, 0, arena, nullptr).is_ok());
  }
}

}  // namespace
}  // namespace fw
