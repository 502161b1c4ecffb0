// Zero heap after init: the localization loop over the hal/sim backend with the odometry
// pass-through allocates nothing per scan (pairing, interpolation, publishing, perf counters,
// log lines into the ring).
#include <gtest/gtest.h>

#include <memory>

#include "firmware/runtime/localization_loop.h"
#include "firmware/runtime/odometry_localizer.h"
#include "hal_sim/sim_log_sink.h"
#include "hal_sim/sim_sensor_io.h"
#include "hal_sim/stepped_clock.h"
#include "tests/alloc_counter.h"

namespace {

TEST(LocalizationLoopHeap, NoAllocationPerScan) {
  if (!mmlfw_test::AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable (sanitizer build)";
  auto clock = std::make_unique<hal_sim::SteppedClock>();
  auto laser = std::make_unique<hal_sim::SimLaserSource>();
  auto odom = std::make_unique<hal_sim::SimOdometrySource>();
  auto sink = std::make_unique<hal_sim::SimPoseSink>();
  auto log = std::make_unique<hal_sim::SimLogSink>();
  auto loc = std::make_unique<fw::OdometryLocalizer>();
  auto loop = std::make_unique<fw::LocalizationLoop>();
  hal::Hal hal;
  hal.clock = clock.get();
  hal.laser = laser.get();
  hal.odometry = odom.get();
  hal.pose_sink = sink.get();
  hal.log = log.get();
  ASSERT_TRUE(loop->init(hal, *loc).is_ok());
  hal::LaserScan scan;
  scan.beam_count = 361;
  scan.angle_increment = 0.0087f;
  scan.range_max = 8.0f;
  hal::Odometry o;
  hal::PoseEstimate e;
  mmlfw_test::AllocCounter::begin();
  for (std::uint32_t k = 0; k < 2000; ++k) {
    const std::uint64_t t = 1000000000ull + k * 100000000ull;
    for (int j = 0; j < 3; ++j) {
      o.timestamp_ns = t + static_cast<std::uint64_t>(j) * 40000000ull;
      o.x = 0.01f * static_cast<float>(k * 3 + j);
      odom->push(o);
    }
    if (k % 100 == 7) {  // exercise the warning path (log ring) too
      hal::Odometry late = o;
      late.timestamp_ns = t - 1;
      odom->push(late);
    }
    scan.timestamp_ns = t + 50000000ull;
    scan.scan_id = k;
    laser->push(scan);
    clock->set_ns(t + 80000000ull);
    ASSERT_TRUE(loop->spin_once().is_ok());
    while (sink->pop(&e)) {
    }
  }
  const long allocations = mmlfw_test::AllocCounter::end();
  EXPECT_EQ(allocations, 0) << mmlfw_test::AllocCounter::bytes() << " bytes";
  EXPECT_EQ(loop->health().scans_processed, 2000u);
  EXPECT_EQ(loop->counters().odom_rejected, 20u);
  EXPECT_GT(log->total(), 0u);
}

}  // namespace
