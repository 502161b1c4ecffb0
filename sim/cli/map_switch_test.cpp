// Several maps (issue 60) at the system level: a robot localized on floor A (small office) rides a
// lift to floor B (large office); SELECT_MAP 1 switches the firmware's MapSet, the tracker drops
// `localized` and MML finds the robot on B — never a `localized` pose wrong on B. Then B's image is
// corrupted on disk and a reload asked for: refused with an error naming the file and the problem,
// B stays active and localizing. The switch and B's steps allocate nothing on the heap.
#include "sim/cli/map_switch_scenario.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "tests/alloc_counter.h"

namespace sim {
namespace {

std::string temp_dir(const char* name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / name;
  std::filesystem::create_directories(d);
  return d.string();
}

void count_begin() { mmlfw_test::AllocCounter::begin(); }
long count_end() { return mmlfw_test::AllocCounter::end(); }

TEST(MapSwitchTest, LiftRideSwitchesMapsAndACorruptReloadKeepsTheMapInUse) {
  MapSwitchOptions o;
  o.dir = temp_dir("mmlfw_map_switch_test");
  o.reload_slot = true;
  // 80, not 40: the first scan that pins A's pose after the refused reload is confirmed as a fix
  // (TrackOptions::repin_needs_confirmation), so 24 of the first 40 were `track-recovering`.
  o.scans_after_corrupt = 80;
  if (mmlfw_test::AllocCounter::available()) {
    o.before_switch = &count_begin;
    o.after_b = &count_end;
  }
  MapSwitchResult r;
  std::string err;
  ASSERT_TRUE(run_map_switch(o, &r, &err)) << err;
  EXPECT_TRUE(r.localized_on_a);
  EXPECT_EQ(r.integrity_failures_a, 0);
  EXPECT_EQ(r.switch_reply, hal::CommandResult::kDone);
  ASSERT_GT(r.scans_to_localized, 0) << "never localized on floor B";
  EXPECT_GT(r.scans_to_localized, 1) << "a switch must drop localized: floor A's track cannot hold on B";
  EXPECT_EQ(r.integrity_failures, 0);
  if (o.after_b != nullptr) EXPECT_EQ(r.allocations, 0) << "heap allocations in the switch and B's steps";
  // The broken file: refused, named, and B still in use.
  EXPECT_EQ(r.corrupt_reply, hal::CommandResult::kMapInvalid);
  EXPECT_NE(r.corrupt_message.find("b.mmap"), std::string::npos) << r.corrupt_message;
  EXPECT_NE(r.corrupt_message.find("CRC"), std::string::npos) << r.corrupt_message;
  EXPECT_NE(r.corrupt_message.find("the loaded map stays"), std::string::npos) << r.corrupt_message;
  EXPECT_EQ(r.active_after_corrupt, 1);
  EXPECT_GT(r.localized_after_corrupt, static_cast<long>(o.scans_after_corrupt / 2)) << "B must go on localizing after the refused reload";
}

// The default global_context = thread: one global thread, created at start-up, serves whichever
// map is active. Back on floor A, a reload of A (no longer `unsupported`) builds A again in the
// spare and the same thread serves it: done, and the robot localizes on A again; then B's image,
// corrupted on disk, is refused (map-invalid) and A stays active and localizing.
TEST(MapSwitchTest, ReloadWithTheGlobalSearchOnItsThread) {
  MapSwitchOptions o;
  o.dir = temp_dir("mmlfw_map_switch_threaded_test");
  o.reload_slot = true;
  o.threaded_global = true;
  o.scans_after_reload = 80;
  o.scans_after_corrupt = 80;
  if (mmlfw_test::AllocCounter::available()) {
    o.before_switch = &count_begin;
    o.after_b = &count_end;
  }
  MapSwitchResult r;
  std::string err;
  ASSERT_TRUE(run_map_switch(o, &r, &err)) << err;
  EXPECT_TRUE(r.localized_on_a);
  EXPECT_EQ(r.integrity_failures_a, 0);
  EXPECT_EQ(r.switch_reply, hal::CommandResult::kDone);
  ASSERT_GT(r.scans_to_localized, 1) << "never localized on floor B after the switch (or never dropped localized)";
  if (o.after_b != nullptr) EXPECT_EQ(r.allocations, 0) << "heap allocations in the switch and B's steps";
  EXPECT_EQ(r.reload_reply, hal::CommandResult::kDone) << "reload with the global search on its thread";
  EXPECT_GT(r.localized_after_reload, 0) << "the robot must localize on A again after A's reload";
  EXPECT_EQ(r.reloads, 1u);
  EXPECT_EQ(r.corrupt_reply, hal::CommandResult::kMapInvalid);
  EXPECT_NE(r.corrupt_message.find("the loaded map stays"), std::string::npos) << r.corrupt_message;
  EXPECT_EQ(r.active_after_corrupt, 0) << "the refused reload of B must leave A in use";
  EXPECT_GT(r.localized_after_corrupt, static_cast<long>(o.scans_after_corrupt / 2));
  EXPECT_EQ(r.integrity_failures, 0);
  EXPECT_GT(r.shared_work_bytes, std::size_t{20} << 20) << "MML's working memory is one block for both maps";
}

}  // namespace
}  // namespace sim
