// System tests of MML on small synthetic worlds where the answer is known.
#include "firmware/mml/mml_localizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "firmware/mml/mml_test_util.h"

namespace fw {
namespace mml {
namespace {

using testing::GridWorld;
using testing::OwnedGlobalMap;

std::function<void(testing::StepRecord*)> note_hook(const MmlLocalizer* loc) {
  return [loc](testing::StepRecord* r) {
    const InterpretResult& l = loc->last();
    char buf[200];
    std::snprintf(buf, sizeof(buf), "thr %.2f d2 %.1f smed %.1f unk %.2f pts %zu ref %d %.2f", l.omega_thres_next, l.d2,
                  l.sigma_med, l.omega_unknown, loc->local_map_points(), loc->last_refine().accepted,
                  loc->last_refine().inlier_ratio);
    r->note = buf;
  };
}

struct Rig {
  StartupArena arena;
  std::unique_ptr<MmlLocalizer> loc = std::make_unique<MmlLocalizer>();
  Status init(const GlobalMap& map, MmlLocalizerConfig cfg = default_mml_config()) {
    FW_RETURN_IF_ERROR(arena.init_mapped(192u << 20, false, "mml-test"));
    return loc->init(cfg, map, nullptr, 0, arena, nullptr);
  }
};

MmlLocalizerConfig test_config() {
  MmlLocalizerConfig c = default_mml_config();
  c.mml.matching_iterations = 20000;
  c.mml.table_triples = 400000;
  c.mml.min_local_map_points = 100;
  return c;
}

int count(const std::vector<testing::StepRecord>& rec, hal::LocalizationStatus s) {
  int n = 0;
  for (const auto& r : rec) n += r.est.status == s;
  return n;
}

void print_trace(const std::vector<testing::StepRecord>& rec) {
  if (std::getenv("MML_TRACE_OFF")) return;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const auto& r = rec[i];
    if (!r.error.empty()) std::printf("%3zu error: %s\n", i, r.error.c_str());
    std::printf("%3zu %-11s hyp %4u cl %3u r %.2f est (%.2f %.2f %.2f) truth (%.2f %.2f %.2f) %s\n", i,
                hal::status_name(r.est.status), r.est.hypothesis_count, r.est.cluster_count, r.est.rating, r.est.x,
                r.est.y, r.est.theta, r.truth.x, r.truth.y, r.truth.theta, r.note.c_str());
  }
}

// Unique room ⇒ localizes, and every `localized` estimate is right.
TEST(MmlLocalizerTest, UniqueRoomLocalizes) {
  static GridWorld g = mcl::testing::unique_room();
  static OwnedGlobalMap gm(g);
  Rig rig;
  ASSERT_TRUE(rig.init(gm.map, test_config()).is_ok());
  const auto path = testing::waypoint_path({{1.5f, 1.5f}, {1.5f, 6.5f}, {4.5f, 6.5f}, {4.5f, 2.0f}, {10.5f, 3.5f}}, 0.1f);
  const auto rec = testing::drive(rig.loc.get(), g, path, 1, note_hook(rig.loc.get()));
  int first = -1;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const auto& r = rec[i];
    ASSERT_NE(r.est.status, hal::LocalizationStatus::kFault) << i << ": " << r.error;
    if (r.est.status == hal::LocalizationStatus::kLocalized) {
      if (first < 0) first = static_cast<int>(i);
      EXPECT_LT(std::hypot(r.est.x - r.truth.x, r.est.y - r.truth.y), 0.3f) << "step " << i;
    }
  }
  if (first < 0 || ::testing::Test::HasFailure() || std::getenv("MML_TRACE")) print_trace(rec);
  EXPECT_GE(first, 0) << "never localized";
  EXPECT_GT(count(rec, hal::LocalizationStatus::kLocalized), static_cast<int>(rec.size()) / 3);
}

struct OptionRun {
  std::vector<testing::StepRecord> rec;
  int first = -1, localized = 0, wrong = 0;
  double mean_points = 0.0;  // local map points matched per step (after matching started)
};

OptionRun run_unique_room(const MmlLocalizerConfig& cfg, Rig* rig) {
  static GridWorld g = mcl::testing::unique_room();
  static OwnedGlobalMap gm(g);
  OptionRun o;
  EXPECT_TRUE(rig->init(gm.map, cfg).is_ok());
  const auto path = testing::waypoint_path({{1.5f, 1.5f}, {1.5f, 6.5f}, {4.5f, 6.5f}, {4.5f, 2.0f}, {10.5f, 3.5f}}, 0.1f);
  std::size_t sum = 0, n = 0;
  const MmlLocalizer* loc = rig->loc.get();
  auto hook = note_hook(loc);
  o.rec = testing::drive(rig->loc.get(), g, path, 1, [&](testing::StepRecord* r) {
    hook(r);
    if (loc->local_map_points() > 0) { sum += loc->local_map_points(); ++n; }
  });
  for (std::size_t i = 0; i < o.rec.size(); ++i) {
    const auto& r = o.rec[i];
    EXPECT_NE(r.est.status, hal::LocalizationStatus::kFault) << i << ": " << r.error;
    if (r.est.status != hal::LocalizationStatus::kLocalized) continue;
    if (o.first < 0) o.first = static_cast<int>(i);
    ++o.localized;
    o.wrong += std::hypot(r.est.x - r.truth.x, r.est.y - r.truth.y) > 0.3f;
  }
  o.mean_points = n ? static_cast<double>(sum) / n : 0.0;
  return o;
}

// Local map correction (Eq. 5.23–5.27) on: still localizes, never wrong, and corrections happen.
TEST(MmlLocalizerTest, UniqueRoomLocalizesWithLocalMapCorrection) {
  MmlLocalizerConfig c = test_config();
  c.mml.correct_local_map = true;
  Rig rig;
  const OptionRun o = run_unique_room(c, &rig);
  std::printf("correction: first localized at step %d, %d localized, %u fragment corrections\n", o.first,
              o.localized, rig.loc->corrections_applied());
  EXPECT_GE(o.first, 0) << "never localized";
  EXPECT_EQ(o.wrong, 0);
  EXPECT_GT(o.localized, static_cast<int>(o.rec.size()) / 3);
  EXPECT_GT(rig.loc->corrections_applied(), 0u);
  if (::testing::Test::HasFailure() || std::getenv("MML_TRACE")) print_trace(o.rec);
}

// Local map reduction (Eq. 5.28–5.30) on: still localizes, never wrong, and matches fewer points
// than the whole local map.
TEST(MmlLocalizerTest, UniqueRoomLocalizesWithReducedLocalMap) {
  MmlLocalizerConfig c = test_config();
  c.mml.reduce_observations = true;
  Rig rig, full_rig;
  const OptionRun o = run_unique_room(c, &rig);
  const OptionRun full = run_unique_room(test_config(), &full_rig);
  std::printf("reduction: first localized at step %d (full map: %d), %d localized, %u observations accepted, "
              "%.0f points matched per step (full map: %.0f)\n",
              o.first, full.first, o.localized, rig.loc->observations_accepted(), o.mean_points, full.mean_points);
  EXPECT_GE(o.first, 0) << "never localized";
  EXPECT_EQ(o.wrong, 0);
  EXPECT_GT(o.localized, static_cast<int>(o.rec.size()) / 3);
  EXPECT_GE(rig.loc->observations_accepted(), 1u);  // at least the first (t = 0) observation
  EXPECT_LT(o.mean_points, full.mean_points);
  if (::testing::Test::HasFailure() || std::getenv("MML_TRACE")) print_trace(o.rec);
}

// A featureless corridor with both ends alike: the position along it (and the direction) cannot
// be isolated ⇒ never localized.
TEST(MmlLocalizerTest, SymmetricCorridorStaysAmbiguous) {
  static GridWorld g;
  g.w = 600; g.h = 60;
  g.occ.assign(g.w * g.h, 0);
  g.box(0.2f, 0.5f, 29.8f, 2.5f);
  g.finish();
  static OwnedGlobalMap gm(g);
  Rig rig;
  ASSERT_TRUE(rig.init(gm.map, test_config()).is_ok());
  const auto path = testing::waypoint_path({{8.0f, 1.5f}, {20.0f, 1.5f}}, 0.1f);
  const auto rec = testing::drive(rig.loc.get(), g, path, 2, note_hook(rig.loc.get()));
  EXPECT_EQ(count(rec, hal::LocalizationStatus::kLocalized), 0);
  EXPECT_GT(count(rec, hal::LocalizationStatus::kAmbiguous), static_cast<int>(rec.size()) / 2);
  if (::testing::Test::HasFailure()) print_trace(rec);
}

using testing::UnknownWorld;

// Starts in the mapped part, localizes, then drives into the unmapped part ⇒ outside-map there,
// and no `localized` estimate is ever wrong.
TEST(MmlLocalizerTest, UnknownAreaReportsOutsideMap) {
  static UnknownWorld uw;
  static OwnedGlobalMap gm(uw.mapped);
  Rig rig;
  ASSERT_TRUE(rig.init(gm.map, test_config()).is_ok());
  const auto path = testing::waypoint_path(
      {{1.5f, 1.5f}, {1.5f, 6.5f}, {4.5f, 6.5f}, {4.5f, 2.0f}, {8.0f, 2.0f}, {11.0f, 2.6f}, {10.5f, 6.8f}}, 0.1f);
  const auto rec = testing::drive(rig.loc.get(), uw.world, path, 3, note_hook(rig.loc.get()));
  int outside_in_unknown = 0, localized_known = 0, beyond_half_metre = 0;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const auto& r = rec[i];
    if (r.est.status == hal::LocalizationStatus::kLocalized) {
      // Known weakness (see the report): where the mapped part ends, the RBSM local map slips and
      // the estimate can lag by up to ~0.6 m; a gross error (> 1 m) is a failure.
      const float e = std::hypot(r.est.x - r.truth.x, r.est.y - r.truth.y);
      EXPECT_LT(e, 1.0f) << "wrong localized pose at " << i;
      beyond_half_metre += e > 0.5f;
      localized_known += r.truth.x < 6.0f;
    }
    outside_in_unknown += r.est.status == hal::LocalizationStatus::kOutsideMap && r.truth.x > 8.0f;
  }
  EXPECT_GT(localized_known, 20);
  EXPECT_GT(outside_in_unknown, 10);
  std::printf("localized estimates beyond 0.5 m: %d of %zu steps\n", beyond_half_metre, rec.size());
  if (::testing::Test::HasFailure() || std::getenv("MML_TRACE")) print_trace(rec);
}

// Starts inside the unmapped part: must never claim a pose there.
TEST(MmlLocalizerTest, StartInUnknownAreaNeverLocalizes) {
  static UnknownWorld uw;
  static OwnedGlobalMap gm(uw.mapped);
  Rig rig;
  ASSERT_TRUE(rig.init(gm.map, test_config()).is_ok());
  const auto path = testing::waypoint_path({{10.5f, 6.8f}, {10.5f, 2.5f}, {8.0f, 1.0f}, {7.5f, 6.5f}}, 0.1f);
  const auto rec = testing::drive(rig.loc.get(), uw.world, path, 5, note_hook(rig.loc.get()));
  EXPECT_EQ(count(rec, hal::LocalizationStatus::kLocalized), 0);
  EXPECT_GT(count(rec, hal::LocalizationStatus::kOutsideMap), 0);
  if (::testing::Test::HasFailure() || std::getenv("MML_TRACE")) print_trace(rec);
}

// Two rooms of the same layout side by side; the map lacks the left one's inside (unmapped space,
// map/unmapped_space.h) and the robot is switched on there. Its scans match the right room
// perfectly; only "the robot is in the room the map lacks" explains them as well. With that
// hypothesis (points in unmapped space are no evidence against a pose) MML never isolates the twin;
// without it, it does (issue 56, corpus seed 505 #56).
struct TwinInUnmappedSpace {
  GridWorld world, mapped;
  TwinInUnmappedSpace() {
    world.w = 480;
    world.h = 200;
    world.occ.assign(world.w * world.h, 0);
    world.box(0.2f, 0.2f, 23.8f, 9.8f);  // a corridor along the top (y 7.8–9.8 m) joins the rooms
    for (float dx : {0.0f, 12.0f}) {
      world.wall(0.2f + dx, 7.8f, 1.0f + dx, 7.8f);  // the room's wall to the corridor, a door 1–2 m
      world.wall(2.0f + dx, 7.8f, 11.8f + dx, 7.8f);
      world.wall(11.8f + dx, 0.2f, 11.8f + dx, 7.8f);
      world.wall(0.2f + dx, 0.2f, 0.2f + dx, 7.8f);
      world.wall(3.0f + dx, 0.2f, 3.0f + dx, 3.0f);
      world.wall(7.0f + dx, 7.8f, 7.0f + dx, 5.0f);
      world.box(8.5f + dx, 1.5f, 9.5f + dx, 2.2f);
      world.wall(5.0f + dx, 4.0f, 6.5f + dx, 4.0f);
    }
    world.finish();
    mapped = world;
    for (std::uint32_t y = 0; y < mapped.h; ++y)
      for (std::uint32_t x = 0; x < mapped.w; ++x) {
        const float cx = (x + 0.5f) * mapped.res, cy = (y + 0.5f) * mapped.res;
        if (cx > 0.4f && cx < 11.8f && cy > 0.4f && cy < 7.6f) mapped.occ[y * mapped.w + x] = 255;
      }
    mapped.finish();
  }
};

int wrong_localized(const std::vector<testing::StepRecord>& rec) {
  int n = 0;
  for (const auto& r : rec) {
    n += r.est.status == hal::LocalizationStatus::kLocalized && std::hypot(r.est.x - r.truth.x, r.est.y - r.truth.y) > 0.5f;
  }
  return n;
}

TEST(MmlLocalizerTest, StartInUnmappedTwinOfAMappedRoomNeverIsolatesTheTwin) {
  static TwinInUnmappedSpace tw;
  static OwnedGlobalMap gm(tw.mapped);
  const auto path = testing::waypoint_path({{4.5f, 6.5f}, {4.5f, 2.0f}, {8.0f, 3.0f}, {10.5f, 6.5f}, {1.5f, 6.0f}, {1.5f, 1.5f}}, 0.1f);
  Rig with;
  ASSERT_TRUE(with.init(gm.map, test_config()).is_ok());
  with.loc->set_unmapped_hypothesis(true);
  EXPECT_TRUE(with.loc->unmapped_hypothesis());
  EXPECT_GT(with.loc->unmapped_space().unmapped_blocks(), 1000u);  // the 11 × 7 m room, 0.25 m blocks
  const auto rec = testing::drive(with.loc.get(), tw.world, path, 7, note_hook(with.loc.get()));
  EXPECT_EQ(wrong_localized(rec), 0);
  if (::testing::Test::HasFailure() || std::getenv("MML_TRACE")) print_trace(rec);
  // The witness that the case is real: unknown cells as misses (the dissertation, and MML's default)
  // isolate the twin.
  Rig without;
  ASSERT_TRUE(without.init(gm.map, test_config()).is_ok());
  EXPECT_FALSE(without.loc->unmapped_hypothesis());
  EXPECT_GT(wrong_localized(testing::drive(without.loc.get(), tw.world, path, 7)), 0);
}

TEST(MmlLocalizerTest, DeterministicAndResettable) {
  static GridWorld g = mcl::testing::unique_room();
  static OwnedGlobalMap gm(g);
  Rig a, b;
  ASSERT_TRUE(a.init(gm.map, test_config()).is_ok());
  ASSERT_TRUE(b.init(gm.map, test_config()).is_ok());
  const auto path = testing::waypoint_path({{1.5f, 1.5f}, {1.5f, 6.5f}, {5.5f, 6.5f}}, 0.1f);
  const auto ra = testing::drive(a.loc.get(), g, path, 4);
  const auto rb = testing::drive(b.loc.get(), g, path, 4);
  a.loc->reset();
  const auto rc = testing::drive(a.loc.get(), g, path, 4);
  ASSERT_EQ(ra.size(), rb.size());
  for (std::size_t i = 0; i < ra.size(); ++i) {
    EXPECT_EQ(ra[i].est.status, rb[i].est.status) << i;
    EXPECT_EQ(ra[i].est.x, rb[i].est.x) << i;
    EXPECT_EQ(ra[i].est.x, rc[i].est.x) << i;
    EXPECT_EQ(ra[i].est.hypothesis_count, rc[i].est.hypothesis_count) << i;
  }
}

TEST(MmlLocalizerTest, MalformedConfigRejected) {
  static GridWorld g = mcl::testing::unique_room();
  static OwnedGlobalMap gm(g);
  MmlLocalizerConfig c = test_config();
  c.mml.delta_r = 1.5f;
  Rig rig;
  const Status s = rig.init(gm.map, c);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("delta_r"), std::string::npos) << s.message();
  c = test_config();
  c.mml.max_local_map_points = 100000;
  Rig rig2;
  const Status s2 = rig2.init(gm.map, c);
  EXPECT_FALSE(s2.is_ok());
  EXPECT_NE(std::string(s2.message()).find("max_local_map_points"), std::string::npos) << s2.message();
  GlobalMap empty;
  Rig rig3;
  EXPECT_FALSE(rig3.init(empty, test_config()).is_ok());
}

}  // namespace
}  // namespace mml
}  // namespace fw
