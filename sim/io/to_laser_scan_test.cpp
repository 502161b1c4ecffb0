// to_laser_scan on a record with 0 readings (issue 13: `FLASER 0 0 0 0 0 0 0 1.0 host 1.0` made it
// call memcpy with a null source, undefined behaviour that UBSan reports). The result is an empty
// scan, which the firmware's localization loop drops as malformed and counts.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "firmware/runtime/localization_loop.h"
#include "firmware/runtime/odometry_localizer.h"
#include "hal_sim/sim_sensor_io.h"
#include "hal_sim/stepped_clock.h"
#include "sim/io/carmen_log.h"

namespace sim {
namespace {

TEST(ToLaserScan, ZeroReadingRecordIsAnEmptyScanTheLoopSkips) {
  const std::string text = "FLASER 0 0 0 0 0 0 0 1.0 host 1.0\n";
  CarmenLog log;
  std::string err;
  ASSERT_TRUE(parse_carmen_log("zero.clf", text.data(), text.size(), CarmenReadOptions{}, &log, &err)) << err;
  ASSERT_EQ(log.scans.size(), 1u);
  ASSERT_TRUE(log.scans[0].ranges.empty());
  const hal::LaserScan scan = to_laser_scan(log.scans[0], 1'000'000'000ull);
  EXPECT_EQ(scan.beam_count, 0u);
  EXPECT_TRUE(std::isfinite(scan.angle_min));
  EXPECT_TRUE(std::isfinite(scan.angle_increment));

  static hal_sim::SteppedClock clock;
  static hal_sim::SimLaserSource laser;
  static hal_sim::SimOdometrySource odom;
  static hal_sim::SimPoseSink sink;
  hal::Hal hal;
  hal.clock = &clock;
  hal.laser = &laser;
  hal.odometry = &odom;
  hal.pose_sink = &sink;
  fw::OdometryLocalizer localizer;
  static fw::LocalizationLoop loop;
  ASSERT_TRUE(loop.init(hal, localizer).is_ok());
  hal::Odometry o;
  o.timestamp_ns = 1'000'000'000ull;
  ASSERT_TRUE(odom.push(o));
  ASSERT_TRUE(laser.push(scan));
  clock.set_ns(1'000'000'000ull);
  ASSERT_TRUE(loop.spin_once().is_ok());
  EXPECT_FALSE(loop.stepped());
  EXPECT_EQ(loop.counters().scans_malformed, 1u);
  EXPECT_EQ(loop.health().dropped_scans, 1u);
  hal::PoseEstimate e;
  EXPECT_FALSE(sink.pop(&e));
}

}  // namespace
}  // namespace sim
