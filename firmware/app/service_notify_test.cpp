// The watchdog feed rule and the STATUS= text of mmlfw's service notifications.
#include "firmware/app/service_notify.h"

#include <gtest/gtest.h>

#include <string>

namespace fw {
namespace {

constexpr std::uint64_t kMs = 1000000;

TEST(WatchdogFeed, FeedsEveryHalfPeriodWhileStepsKeepTheDeadline) {
  WatchdogFeed w;
  w.start(1000 * kMs, 0, 0, 0);
  EXPECT_EQ(w.check_interval_ns(), 500 * kMs);
  EXPECT_FALSE(w.cycle(100 * kMs, 5, 0));  // not yet half a period
  EXPECT_TRUE(w.cycle(500 * kMs, 30, 2));   // 30 steps, 2 missed: fed
  EXPECT_FALSE(w.cycle(600 * kMs, 35, 2));
  EXPECT_TRUE(w.cycle(1000 * kMs, 60, 2));
  EXPECT_EQ(w.fed(), 2u);
  EXPECT_EQ(w.withheld(), 0u);
}

TEST(WatchdogFeed, NoScansIsNoReasonToRestart) {
  WatchdogFeed w;
  w.start(1000 * kMs, 0, 10, 0);
  EXPECT_TRUE(w.cycle(500 * kMs, 10, 0));  // a silent laser: HEALTH says so, the loop is alive
  EXPECT_TRUE(w.cycle(1000 * kMs, 10, 0));
}

TEST(WatchdogFeed, WithheldWhenEveryStepOfTheWindowMissed) {
  WatchdogFeed w;
  w.start(1000 * kMs, 0, 0, 0);
  EXPECT_FALSE(w.cycle(500 * kMs, 20, 20));  // all 20 late
  EXPECT_EQ(w.withheld(), 1u);
  EXPECT_FALSE(w.cycle(1000 * kMs, 40, 40));  // a whole period without a feed: the manager restarts
  EXPECT_TRUE(w.cycle(1500 * kMs, 60, 59));   // one on time again: fed
  EXPECT_EQ(w.fed(), 1u);
  EXPECT_EQ(w.withheld(), 2u);
}

TEST(WatchdogFeed, AStalledLoopNeverReachesTheCheck) {
  // The rule only runs when the loop cycles: a loop that stops cycling sends nothing. What the
  // test can check here is that a late cycle after a stall does not send several feeds at once.
  WatchdogFeed w;
  w.start(1000 * kMs, 0, 0, 0);
  EXPECT_TRUE(w.cycle(5000 * kMs, 1, 0));
  EXPECT_FALSE(w.cycle(5001 * kMs, 2, 0));
}

TEST(WatchdogFeed, NoWatchdogNoFeed) {
  WatchdogFeed w;
  w.start(0, 0, 0, 0);
  EXPECT_FALSE(w.cycle(10000 * kMs, 100, 0));
}

TEST(ServiceStatus, NamesStatusReasonFaultsAndCounters) {
  hal::PoseEstimate e;
  hal::Health h;
  e.status = hal::LocalizationStatus::kLocalized;
  e.reason = hal::StatusReason::kNone;
  h.scans_processed = 1234;
  h.deadline_misses = 3;
  char buf[192];
  format_service_status(buf, sizeof(buf), e, h);
  EXPECT_EQ(std::string(buf), "STATUS=localized, 1234 scans, 3 deadline misses");
  e.status = hal::LocalizationStatus::kFault;
  e.reason = hal::StatusReason::kFault;
  h.fault_bits = static_cast<std::uint32_t>(hal::HealthFault::kLaserTimeout) |
                 static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected);
  format_service_status(buf, sizeof(buf), e, h);
  EXPECT_EQ(std::string(buf).rfind("STATUS=fault (", 0), 0u) << buf;
  EXPECT_NE(std::string(buf).find("faults laser-timeout laser-disconnected"), std::string::npos) << buf;
}

TEST(ServiceStatus, TruncatesNeverOverflows) {
  hal::PoseEstimate e;
  hal::Health h;
  char buf[12];
  const std::size_t n = format_service_status(buf, sizeof(buf), e, h);
  EXPECT_EQ(n, 11u);
  EXPECT_EQ(std::string(buf), "STATUS=sear");
}

TEST(ServiceStatus, ChangesOnStatusReasonOrFaultsOnly) {
  hal::PoseEstimate a, b;
  EXPECT_FALSE(service_status_changed(a, 0, b, 0));
  b.scan_id = 99;  // counters and poses are no reason to send
  EXPECT_FALSE(service_status_changed(a, 0, b, 0));
  b.status = hal::LocalizationStatus::kLocalized;
  EXPECT_TRUE(service_status_changed(a, 0, b, 0));
  EXPECT_TRUE(service_status_changed(a, 0, a, 1u << 16));
}

TEST(ServiceStatus, AFlappingStatusIsSentAtMostEveryInterval) {
  hal::PoseEstimate sent, now;
  now.status = hal::LocalizationStatus::kLocalized;
  const std::uint64_t t0 = 1000 * kMs;
  EXPECT_FALSE(service_status_due(sent, 0, now, 0, t0 + 10 * kMs, t0));   // changed, but 10 ms after the last
  EXPECT_TRUE(service_status_due(sent, 0, now, 0, t0 + 250 * kMs, t0));   // still changed: sent once due
  EXPECT_FALSE(service_status_due(now, 0, now, 0, t0 + 900 * kMs, t0));   // unchanged: not yet
  EXPECT_TRUE(service_status_due(now, 0, now, 0, t0 + 5000 * kMs, t0));   // unchanged: refreshed (counters)
}

}  // namespace
}  // namespace fw
