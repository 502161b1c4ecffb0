// GlobalContext (issue 14): the schedule is a function of the scan index, not of timing; the
// threaded execution computes exactly what the inline one does when every global step is on time.
#include "firmware/track/global_context.h"

#include <gtest/gtest.h>
#include <time.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "firmware/track/track_test_util.h"
#include "firmware/track/tracked_localizer.h"

namespace fw {
namespace track {
namespace {

struct ScheduledRig {
  StartupArena arena;
  std::unique_ptr<mml::MmlLocalizer> mml = std::make_unique<mml::MmlLocalizer>();
  std::unique_ptr<TrackedLocalizer> loc = std::make_unique<TrackedLocalizer>();
  Status init(const GlobalMap& map, const GlobalScheduleOptions& schedule) {
    FW_RETURN_IF_ERROR(arena.init_mapped(192u << 20, false, "global-context-test"));
    FW_RETURN_IF_ERROR(mml->init(testing::small_mml_config(), map, nullptr, 0, arena, nullptr));
    return loc->init(TrackOptions(), map, mml.get(), schedule);
  }
};

TEST(GlobalContextTest, ScheduleValidation) {
  GlobalScheduleOptions s;
  EXPECT_TRUE(s.validate(false).is_ok());
  EXPECT_FALSE(s.validate(true).is_ok()) << "threaded with no delay would make the sensor context wait";
  s.every_n_scans = 2;
  s.result_delay_scans = 3;
  EXPECT_FALSE(s.validate(false).is_ok()) << "two jobs in flight";
  s.every_n_scans = 0;
  s.result_delay_scans = 0;
  EXPECT_FALSE(s.validate(false).is_ok());
  EXPECT_TRUE(live_global_schedule().validate(true).is_ok());
  EXPECT_EQ(live_global_schedule().every_n_scans, kGlobalContext.period_scans);
  EXPECT_EQ(live_global_schedule(3).result_delay_scans, 3u);
}

// Live schedule executed inline: still localizes on the synthetic room, never wrong; MML consumed
// every period_scans-th scan while it searched.
TEST(GlobalContextTest, LiveScheduleInlineLocalizes) {
  ScheduledRig rig;
  ASSERT_TRUE(rig.init(testing::room_map().map, live_global_schedule()).is_ok());
  const auto path = testing::room_tour();
  const auto rec = mml::testing::drive(rig.loc.get(), testing::room(), path, 1);
  int first = -1, wrong = 0;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    if (rec[i].est.status != hal::LocalizationStatus::kLocalized) continue;
    if (first < 0) first = static_cast<int>(i);
    wrong += std::hypot(rec[i].est.x - rec[i].truth.x, rec[i].est.y - rec[i].truth.y) > 0.5f;
  }
  ASSERT_GE(first, 0) << "never localized";
  EXPECT_EQ(wrong, 0);
  const GlobalContext& gc = rig.loc->global_context();
  EXPECT_GT(gc.jobs(), 0u);
  // MML keeps running after the fix while the track confirms it (TrackOptions::confirm_fix) and the
  // background cross-check runs on, but never on more scans than the schedule gives it.
  EXPECT_LE(gc.jobs(), static_cast<std::uint64_t>(rec.size()) / kGlobalContext.period_scans + 2)
      << "MML ran on more scans than the schedule gives it";
  EXPECT_EQ(gc.overruns(), 0u);
}

// The live schedule's result comes before this scan's offer: on the scan where the tracker confirms
// MML's fix the search is over, so that scan is not handed to MML (its job would be thrown away by
// the reset before MML's next use, and would share the cores with the confirming step). On every
// other scan of the search one job per scan; the poses are those of the step-then-decide order.
TEST(GlobalContextTest, ConfirmedFixScanIsNotOffered) {
  ScheduledRig rig;
  ASSERT_TRUE(rig.init(testing::room_map().map, live_global_schedule()).is_ok());
  const GlobalContext& gc = rig.loc->global_context();
  std::uint64_t jobs_before = 0;
  std::uint32_t fixes_before = 0;
  int fix_scans = 0, searching_scans_without_job = 0;
  mml::testing::drive(rig.loc.get(), testing::room(), testing::room_tour(), 1, [&](mml::testing::StepRecord*) {
    const std::uint64_t jobs = gc.jobs();
    const std::uint32_t fixes = rig.loc->fixes();
    const bool in_search = !rig.loc->tracking();
    if (fixes > fixes_before) {
      ++fix_scans;
      EXPECT_EQ(jobs, jobs_before) << "the scan of a confirmed fix went to MML";
    } else if (in_search && jobs == jobs_before) {
      ++searching_scans_without_job;
    }
    jobs_before = jobs;
    fixes_before = fixes;
  });
  ASSERT_GT(fix_scans, 0) << "never fixed";
  EXPECT_EQ(searching_scans_without_job, 0);
}

// The same schedule on the global thread gives bit-identical poses when every job finishes within
// its window (the hook waits for it, as a fast enough global context would).
TEST(GlobalContextTest, ThreadedEqualsInlineWhenOnTime) {
  const auto path = testing::room_tour();
  ScheduledRig a;
  ASSERT_TRUE(a.init(testing::room_map().map, live_global_schedule()).is_ok());
  const auto ra = mml::testing::drive(a.loc.get(), testing::room(), path, 1);
  ScheduledRig b;
  ASSERT_TRUE(b.init(testing::room_map().map, live_global_schedule()).is_ok());
  ASSERT_TRUE(b.loc->global_context().start_thread(kGlobalContext, false, nullptr).is_ok());
  ASSERT_TRUE(b.loc->global_context().threaded());
  const auto rb = mml::testing::drive(b.loc.get(), testing::room(), path, 1, [&](mml::testing::StepRecord*) {
    while (b.loc->global_context().job_in_flight()) {
      timespec ts{0, 100000};
      nanosleep(&ts, nullptr);
    }
  });
  b.loc->global_context().stop_thread();
  ASSERT_EQ(ra.size(), rb.size());
  int localized = 0;
  for (std::size_t i = 0; i < ra.size(); ++i) {
    EXPECT_EQ(ra[i].est.status, rb[i].est.status) << i;
    EXPECT_EQ(0, std::memcmp(&ra[i].est.x, &rb[i].est.x, sizeof(float))) << i;
    EXPECT_EQ(0, std::memcmp(&ra[i].est.y, &rb[i].est.y, sizeof(float))) << i;
    EXPECT_EQ(0, std::memcmp(&ra[i].est.theta, &rb[i].est.theta, sizeof(float))) << i;
    localized += ra[i].est.status == hal::LocalizationStatus::kLocalized;
  }
  EXPECT_GT(localized, 0);
  EXPECT_EQ(a.loc->global_context().jobs(), b.loc->global_context().jobs());
  EXPECT_EQ(b.loc->global_context().overruns(), 0u);
}

// A global step that does not finish within its window is counted, and the sensor step never
// waits for it: the result is taken at the first step after it finished.
TEST(GlobalContextTest, LateGlobalStepIsCountedNotWaitedFor) {
  const auto path = testing::room_tour();
  ScheduledRig b;
  ASSERT_TRUE(b.init(testing::room_map().map, live_global_schedule()).is_ok());
  ASSERT_TRUE(b.loc->global_context().start_thread(kGlobalContext, false, nullptr).is_ok());
  // Steps back to back with no wait: MML (~ms per step) cannot keep up with a sensor step of µs.
  std::vector<Se2f> short_path(path.begin(), path.begin() + 40);
  const auto rb = mml::testing::drive(b.loc.get(), testing::room(), short_path, 1);
  b.loc->global_context().stop_thread();
  EXPECT_GT(b.loc->global_context().overruns() + b.loc->global_context().skipped_offers(), 0u);
  for (const auto& r : rb) EXPECT_NE(r.est.status, hal::LocalizationStatus::kFault) << r.error;
}

}  // namespace
}  // namespace track
}  // namespace fw
