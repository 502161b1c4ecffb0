// mml-sim's registry entry "mml" (and "handoff") reach MML's local map options: --opt correct=0|1,
// reduce=0|1; bad values and unknown keys are refused naming the option.
#include <gtest/gtest.h>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "sim/localizers/localizer_context.h"
#include "sim/eval/mml_eval/mml_systems.h"
#include "sim/map/map_image_writer.h"
#include "sim/world/builtin_worlds.h"
#include "sim/world/raster.h"
#include "sim/world/synthetic_run.h"

namespace {

struct SmallOffice {
  sim::World world;
  std::vector<std::uint8_t> image;
  fw::StartupArena arena;
  fw::GlobalMap map;
  std::string err;
  bool load() {
    sim::OccupancyGrid grid;
    if (!sim::make_builtin_world("small-office", &world, &err) || !sim::rasterize_world(world, sim::RasterOptions(), &grid, &err))
      return false;
    sim::MapImageWriter w;
    if (!w.set_grid(grid, &err)) return false;
    image = w.bytes();
    return arena.init_mapped(image.size() + (4u << 20), false, "test map").is_ok() &&
           fw::load_map_image(image.data(), image.size(), arena, &map, "small-office").is_ok();
  }
  sim::LocalizerContext context() {
    sim::LocalizerContext ctx;
    ctx.global_map = &map;
    ctx.map_image = &image;
    return ctx;
  }
};

// The options the tracker of an mml-track localizer runs with.
const fw::track::TrackOptions& tracker_options(const std::unique_ptr<fw::Localizer>& loc) {
  return static_cast<sim::mmleval::OwnedLocalizer*>(loc.get())->tracked()->tracker().options();
}

TEST(LocalMapOptionsFactory, OptionsReachTheLocalizer) {
  SmallOffice so;
  ASSERT_TRUE(so.load()) << so.err;
  sim::LocalizerContext ctx;
  ctx.global_map = &so.map;
  ctx.map_image = &so.image;
  ctx.options = {{"correct", "1"}, {"reduce", "1"}};
  std::string err;
  auto loc = sim::mmleval::make_mml_localizer(ctx, &err);
  ASSERT_NE(loc, nullptr) << err;
  auto* owned = static_cast<sim::mmleval::OwnedLocalizer*>(loc.get());
  sim::SyntheticRun run;
  sim::SyntheticRunOptions ro;
  ro.seed = 3;
  ro.max_scans = 20;
  ASSERT_TRUE(run.init(so.world, ro, &err)) << err;
  sim::SyntheticFrame f;
  while (run.next(&f)) {
    hal::PoseEstimate est{};
    ASSERT_TRUE(loc->step(f.scan, f.odometry.back(), &est).is_ok());
  }
  // Reduction on: at least the first observation was kept (0 when the option did not arrive).
  EXPECT_GE(owned->mml()->observations_accepted(), 1u);

  ctx.options = {{"reduce", "0"}};
  auto plain = sim::mmleval::make_mml_localizer(ctx, &err);
  ASSERT_NE(plain, nullptr) << err;
  sim::SyntheticRun run2;
  ASSERT_TRUE(run2.init(so.world, ro, &err)) << err;
  while (run2.next(&f)) {
    hal::PoseEstimate est{};
    ASSERT_TRUE(plain->step(f.scan, f.odometry.back(), &est).is_ok());
  }
  EXPECT_EQ(static_cast<sim::mmleval::OwnedLocalizer*>(plain.get())->mml()->observations_accepted(), 0u);
}

TEST(LocalMapOptionsFactory, BadValuesAreRefused) {
  SmallOffice so;
  ASSERT_TRUE(so.load()) << so.err;
  sim::LocalizerContext ctx;
  ctx.global_map = &so.map;
  ctx.map_image = &so.image;
  std::string err;
  ctx.options = {{"correct", "yes"}};
  EXPECT_EQ(sim::mmleval::make_mml_localizer(ctx, &err), nullptr);
  EXPECT_NE(err.find("correct='yes'"), std::string::npos) << err;
  ctx.options = {{"reduce", "2"}};
  EXPECT_EQ(sim::mmleval::make_handoff_localizer(ctx, &err), nullptr);
  EXPECT_NE(err.find("reduce='2'"), std::string::npos) << err;
  ctx.options = {{"corect", "1"}};
  EXPECT_EQ(sim::mmleval::make_mml_localizer(ctx, &err), nullptr);
  EXPECT_NE(err.find("unknown option(s) corect"), std::string::npos) << err;
  EXPECT_NE(err.find("correct, reduce"), std::string::npos) << err;
}

// odom_noise (mml-sim --opt, mml-eval --odom-noise, mmlfw's config key): the four numbers reach the
// tracker of mml-track; malformed values are refused naming the option.
TEST(LocalMapOptionsFactory, OdomNoiseReachesTheTracker) {
  SmallOffice so;
  ASSERT_TRUE(so.load()) << so.err;
  sim::LocalizerContext ctx = so.context();
  ctx.options = {{"odom_noise", "0.1,0.05,0.3,0.25"}};
  std::string err;
  auto loc = sim::mmleval::make_track_localizer(ctx, &err);
  ASSERT_NE(loc, nullptr) << err;
  const fw::track::TrackOptions& o = tracker_options(loc);
  EXPECT_FLOAT_EQ(o.odom_trans_per_m, 0.1f);
  EXPECT_FLOAT_EQ(o.odom_trans_per_rad, 0.05f);
  EXPECT_FLOAT_EQ(o.odom_rot_per_rad, 0.3f);
  EXPECT_FLOAT_EQ(o.odom_rot_per_m, 0.25f);
  for (const char* bad : {"0.1,0.2,0.3", "0.1,0.2,0.3,0.4,", "a,b,c,d", "0.1,0.2,0.3,-1", "0.1,0.2,0.3,10.5"}) {
    ctx.options = {{"odom_noise", bad}};
    EXPECT_EQ(sim::mmleval::make_track_localizer(ctx, &err), nullptr) << bad;
    EXPECT_NE(err.find(std::string("odom_noise='") + bad + "'"), std::string::npos) << err;
    fw::track::TrackOptions untouched;
    EXPECT_FALSE(sim::mmleval::set_odom_noise(bad, &untouched)) << bad;
    EXPECT_FLOAT_EQ(untouched.odom_rot_per_m, 0.2f) << bad;
  }
}

// odom_noise_per_step (mml-sim --opt, mml-eval --odom-noise-per-step, mmlfw's config key): metres
// and degrees per scan step reach the tracker (0 by default); malformed values are refused.
TEST(LocalMapOptionsFactory, OdomNoisePerStepReachesTheTracker) {
  SmallOffice so;
  ASSERT_TRUE(so.load()) << so.err;
  sim::LocalizerContext ctx = so.context();
  std::string err;
  auto plain = sim::mmleval::make_track_localizer(ctx, &err);
  ASSERT_NE(plain, nullptr) << err;
  const fw::track::TrackOptions& d = tracker_options(plain);
  EXPECT_EQ(d.odom_trans_per_step_m, 0.0f);
  EXPECT_EQ(d.odom_rot_per_step_rad, 0.0f);
  ctx.options = {{"odom_noise_per_step", "0.04,4"}};
  auto loc = sim::mmleval::make_track_localizer(ctx, &err);
  ASSERT_NE(loc, nullptr) << err;
  const fw::track::TrackOptions& o = tracker_options(loc);
  EXPECT_FLOAT_EQ(o.odom_trans_per_step_m, 0.04f);
  EXPECT_NEAR(o.odom_rot_per_step_rad, 4.0f * 3.14159265f / 180.0f, 1e-6f);
  for (const char* bad : {"0.04", "0.04,4,1", "x,4", "2,4", "0.04,29", "0.04,-1", "0.04,4,"}) {
    ctx.options = {{"odom_noise_per_step", bad}};
    EXPECT_EQ(sim::mmleval::make_track_localizer(ctx, &err), nullptr) << bad;
    EXPECT_NE(err.find(std::string("odom_noise_per_step='") + bad + "'"), std::string::npos) << err;
    fw::track::TrackOptions untouched;
    EXPECT_FALSE(sim::mmleval::set_odom_noise_per_step(bad, &untouched)) << bad;
    EXPECT_EQ(untouched.odom_trans_per_step_m, 0.0f) << bad;
  }
}

}  // namespace
