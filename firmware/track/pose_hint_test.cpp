// Issue 60: an operator's pose hint enters mml-track as MML's fix does and must pass the same
// confirmation; a hint the scans contradict is refused, and no hint ever makes a wrong `localized`.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "firmware/track/track_test_util.h"
#include "firmware/track/tracked_localizer.h"

namespace fw {
namespace track {
namespace {

struct HintRig {
  StartupArena arena;
  std::unique_ptr<mml::MmlLocalizer> mml = std::make_unique<mml::MmlLocalizer>();
  std::unique_ptr<TrackedLocalizer> loc = std::make_unique<TrackedLocalizer>();
  Status init(const TrackOptions& options) {
    FW_RETURN_IF_ERROR(arena.init_mapped(192u << 20, false, "hint-test"));
    FW_RETURN_IF_ERROR(mml->init(testing::small_mml_config(), testing::room_map().map, nullptr, 0, arena, nullptr));
    return loc->init(options, testing::room_map().map, mml.get());
  }
};

struct HintRun {
  int first_localized = -1;  // scans after the hint
  int wrong_localized = 0;
  hal::HintStatus status_after_hint = hal::HintStatus::kNone;
};

bool wrong(const hal::PoseEstimate& e, const Se2f& truth) {
  return std::hypot(e.x - truth.x, e.y - truth.y) > 0.5f || std::fabs(wrap_angle(e.theta - truth.theta)) > 0.0872665f;
}

// The room tour; at scan `at` the hint: the truth moved by `offset` (in the map frame), σ as given.
HintRun run_with_hint(const TrackOptions& options, std::size_t at, const Se2f& offset, float sigma_m, float sigma_rad,
                      std::size_t scans = 40) {
  HintRig rig;
  EXPECT_TRUE(rig.init(options).is_ok());
  auto path = testing::room_tour();
  if (path.size() > scans) path.resize(scans);
  HintRun run;
  const auto rec = mml::testing::drive(rig.loc.get(), testing::room(), path, 3, nullptr, [&](std::size_t i, Se2f*) {
    if (i != at) return;
    hal::PoseHint h;
    h.x = path[i].x + offset.x;
    h.y = path[i].y + offset.y;
    h.theta = path[i].theta + offset.theta;
    h.sigma_xy_m = sigma_m;
    h.sigma_theta_rad = sigma_rad;
    EXPECT_TRUE(rig.loc->set_pose_hint(h).is_ok());
    EXPECT_EQ(rig.loc->hint_status(), hal::HintStatus::kPending);
  });
  for (std::size_t i = at; i < rec.size(); ++i) {
    const bool loc = rec[i].est.status == hal::LocalizationStatus::kLocalized;
    if (loc && run.first_localized < 0) run.first_localized = static_cast<int>(i - at);
    if (loc && wrong(rec[i].est, rec[i].truth)) ++run.wrong_localized;
  }
  run.status_after_hint = rig.loc->hint_status();
  return run;
}

TrackOptions fast_hints() {
  TrackOptions o;
  o.hint_awaits_mml = false;
  return o;
}

// A right hint once the robot has scans behind it (the operator's usual case): confirmed on the
// scans before it, as MML's fix, and `localized` within 3 scans. At the very first scan there is no
// past: forward confirmation, recovery_steps (5) scans.
TEST(PoseHintTest, RightHintIsLocalizedWithinThreeScans) {
  HintRun r = run_with_hint(fast_hints(), 10, Se2f(0, 0, 0), 0.1f, 0.05f);
  EXPECT_GE(r.first_localized, 0);
  EXPECT_LE(r.first_localized, 2);
  EXPECT_EQ(r.wrong_localized, 0);
  EXPECT_EQ(r.status_after_hint, hal::HintStatus::kConfirmed);
  r = run_with_hint(fast_hints(), 0, Se2f(0, 0, 0), 0.1f, 0.05f);
  EXPECT_GE(r.first_localized, 0);
  EXPECT_LE(r.first_localized, static_cast<int>(TrackOptions().recovery_steps));
  EXPECT_EQ(r.wrong_localized, 0);
}

// A hint inside its stated uncertainty is found by the confirmation's search and confirmed near the truth.
TEST(PoseHintTest, HintOffWithinItsUncertaintyIsConfirmedNearTheTruth) {
  const HintRun r = run_with_hint(fast_hints(), 0, Se2f(0.3f, -0.2f, 0.1f), 0.3f, 0.1f);
  EXPECT_EQ(r.wrong_localized, 0);
}

// Hints the scans contradict (2 m off, 20° off with a tight σ): refused or found near the truth,
// never `localized` wrong.
TEST(PoseHintTest, WrongHintNeverMakesAWrongLocalized) {
  for (const Se2f& off : {Se2f(2.0f, 0.0f, 0.0f), Se2f(0.0f, 0.5f, 0.0f), Se2f(0.0f, 0.0f, 0.349f)}) {
    const HintRun r = run_with_hint(fast_hints(), 5, off, 0.05f, 0.02f);
    EXPECT_EQ(r.wrong_localized, 0) << off.x << " " << off.y << " " << off.theta;
  }
}

// hint_awaits_mml (the default): a right hint waits for MML to isolate the same pose; nothing wrong.
TEST(PoseHintTest, DefaultHintWaitsForMml) {
  const HintRun r = run_with_hint(TrackOptions(), 0, Se2f(0, 0, 0), 0.1f, 0.05f, 80);
  EXPECT_EQ(r.wrong_localized, 0);
  if (r.first_localized >= 0) EXPECT_EQ(r.status_after_hint, hal::HintStatus::kConfirmed);
}

// A hint that agrees with a `localized` track changes nothing (no interruption); one that contradicts
// it restarts from the hint, never `localized` wrong.
TEST(PoseHintTest, HintAgainstALocalizedTrack) {
  HintRun r = run_with_hint(TrackOptions(), 60, Se2f(0.05f, 0.0f, 0.0f), 0.1f, 0.05f, 70);
  EXPECT_EQ(r.first_localized, 0) << "the track was interrupted";
  EXPECT_EQ(r.status_after_hint, hal::HintStatus::kConfirmed);
  EXPECT_EQ(r.wrong_localized, 0);
  r = run_with_hint(TrackOptions(), 60, Se2f(2.0f, 0.0f, 0.0f), 0.05f, 0.02f, 80);
  EXPECT_EQ(r.wrong_localized, 0);
}

TEST(PoseHintTest, BadHintIsAnErrorNotACrash) {
  HintRig rig;
  ASSERT_TRUE(rig.init(TrackOptions()).is_ok());
  hal::PoseHint h;
  h.x = NAN;
  h.sigma_xy_m = 0.1f;
  h.sigma_theta_rad = 0.1f;
  EXPECT_FALSE(rig.loc->set_pose_hint(h).is_ok());
  h.x = 1.0f;
  h.sigma_xy_m = 0.0f;
  EXPECT_FALSE(rig.loc->set_pose_hint(h).is_ok());
  EXPECT_EQ(rig.loc->hint_status(), hal::HintStatus::kNone);
}

}  // namespace
}  // namespace track
}  // namespace fw
