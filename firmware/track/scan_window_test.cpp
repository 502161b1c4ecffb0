// ScanWindow: the global job's window follows the scan intervals the sensor context sees.
#include "firmware/track/scan_window.h"

#include <gtest/gtest.h>

namespace fw {
namespace track {
namespace {

constexpr std::uint64_t kMs = 1'000'000;
constexpr std::uint64_t kConfigured = 13'333'333;  // one 75 Hz period

TEST(ScanWindowTest, ConfiguredWindowUntilIntervalsAreSeen) {
  ScanWindow w;
  EXPECT_EQ(w.window_ns(1, kConfigured), kConfigured);
  w.step(5 * kMs);
  EXPECT_EQ(w.median_interval_ns(), 0u);
  EXPECT_EQ(w.window_ns(1, kConfigured), kConfigured);
}

TEST(ScanWindowTest, SlowLaserWidensTheWindowByTheResultDelay) {
  ScanWindow w;
  for (int i = 0; i < 20; ++i) w.step(static_cast<std::uint64_t>(i) * 78 * kMs);
  EXPECT_EQ(w.median_interval_ns(), 78 * kMs);
  EXPECT_EQ(w.window_ns(1, kConfigured), 78 * kMs);
  EXPECT_EQ(w.window_ns(2, 2 * kConfigured), 156 * kMs);
}

TEST(ScanWindowTest, FastSensorContextKeepsTheConfiguredWindow) {
  ScanWindow w;
  for (int i = 0; i < 20; ++i) w.step(static_cast<std::uint64_t>(i) * kMs);
  EXPECT_EQ(w.median_interval_ns(), kMs);
  EXPECT_EQ(w.window_ns(1, kConfigured), kConfigured);
}

TEST(ScanWindowTest, OneStallDoesNotWidenItAndFaultGapsAreLeftOut) {
  ScanWindow w;
  std::uint64_t t = 0;
  for (int i = 0; i < 8; ++i) w.step(t += 25 * kMs);
  w.step(t += 400 * kMs);  // one late scan
  EXPECT_EQ(w.median_interval_ns(), 25 * kMs);
  w.step(t += 3000 * kMs);  // the laser was gone: a fault, not a period
  w.step(t += 25 * kMs);
  EXPECT_EQ(w.median_interval_ns(), 25 * kMs);
  // A clock that stands still or goes back adds nothing.
  w.step(t);
  w.step(t - kMs);
  EXPECT_EQ(w.median_interval_ns(), 25 * kMs);
}

TEST(ScanWindowTest, FollowsANewRateWithinHalfTheIntervalsAndResets) {
  ScanWindow w;
  std::uint64_t t = 0;
  for (int i = 0; i < 8; ++i) w.step(t += 25 * kMs);
  for (std::size_t i = 0; i < ScanWindow::kIntervals / 2 + 1; ++i) w.step(t += 100 * kMs);
  EXPECT_EQ(w.median_interval_ns(), 100 * kMs);
  w.reset();
  EXPECT_EQ(w.median_interval_ns(), 0u);
  EXPECT_EQ(w.window_ns(1, kConfigured), kConfigured);
}

}  // namespace
}  // namespace track
}  // namespace fw
