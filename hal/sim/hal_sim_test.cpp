#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include <memory>

#include "hal_sim/sim_hal.h"
#include "hal_sim/sim_log_sink.h"
#include "hal_sim/sim_sensor_io.h"
#include "hal_sim/sim_task_runner.h"
#include "hal_sim/stepped_clock.h"

namespace {

TEST(SimLaserSource, FifoOrderAndOverflowIsDroppedAndCounted) {
  hal_sim::SimLaserSource src;
  hal::LaserScan scan;
  for (std::uint32_t i = 0; i < hal_sim::SimLaserSource::kCapacity + 3; ++i) {
    scan.scan_id = i;
    const bool ok = src.push(scan);
    EXPECT_EQ(ok, i < hal_sim::SimLaserSource::kCapacity) << i;
  }
  EXPECT_EQ(src.stats().dropped, 3u);
  // What the loop puts into HEALTH dropped_scans (the soak accounts for every scan in HEALTH).
  EXPECT_EQ(static_cast<const hal::LaserScanSource&>(src).skipped_scans(), 3u);
  EXPECT_EQ(src.stats().pushed, hal_sim::SimLaserSource::kCapacity);
  hal::LaserScan out;
  for (std::uint32_t i = 0; i < hal_sim::SimLaserSource::kCapacity; ++i) {
    ASSERT_TRUE(src.poll(&out));
    EXPECT_EQ(out.scan_id, i);  // the oldest are kept, the overflow is what is lost
  }
  EXPECT_FALSE(src.poll(&out));
  EXPECT_EQ(src.stats().polled, hal_sim::SimLaserSource::kCapacity);
}

TEST(SimOdometrySource, OverflowCounted) {
  hal_sim::SimOdometrySource src;
  hal::Odometry o;
  for (std::size_t i = 0; i < hal_sim::SimOdometrySource::kCapacity + 10; ++i) {
    o.timestamp_ns = i;
    src.push(o);
  }
  EXPECT_EQ(src.stats().dropped, 10u);
  ASSERT_TRUE(src.poll(&o));
  EXPECT_EQ(o.timestamp_ns, 0u);
}

TEST(SimPoseSink, KeepsNewestWhenHostLagsAndCountsOverwrites) {
  hal_sim::SimPoseSink sink;
  hal::PoseEstimate e;
  for (std::uint32_t i = 0; i < hal_sim::SimPoseSink::kCapacity + 5; ++i) {
    e.scan_id = i;
    sink.publish(e);
  }
  EXPECT_EQ(sink.stats().dropped, 5u);
  ASSERT_TRUE(sink.pop(&e));
  EXPECT_EQ(e.scan_id, 5u);
  hal::Health h;
  h.scans_processed = 7;
  EXPECT_FALSE(sink.has_health());
  sink.publish_health(h);
  EXPECT_TRUE(sink.has_health());
  EXPECT_EQ(sink.last_health().scans_processed, 7u);
}

struct Counter {
  std::vector<int>* trace;
  int id;
};
void record(void* ctx) {
  auto* c = static_cast<Counter*>(ctx);
  c->trace->push_back(c->id);
}

TEST(SimTaskRunner, RunsDueTasksInTableOrderOnThePeriodGrid) {
  hal_sim::SteppedClock clock;
  hal_sim::SimTaskRunner runner(clock);
  std::vector<int> trace;
  Counter a{&trace, 1}, b{&trace, 2}, c{&trace, 3};
  ASSERT_TRUE(runner.add_task("fast", &record, &a, 10));
  ASSERT_TRUE(runner.add_task("slow", &record, &b, 30));
  ASSERT_TRUE(runner.add_task("every", &record, &c, 0));
  for (int step = 0; step < 7; ++step) {  // t = 0, 10, ..., 60
    runner.run_once();
    clock.advance_ns(10);
  }
  EXPECT_EQ(runner.runs(0), 7u);
  EXPECT_EQ(runner.runs(1), 3u);  // t = 0, 30, 60
  EXPECT_EQ(runner.runs(2), 7u);
  const std::vector<int> first = {1, 2, 3, 1, 3, 1, 3, 1, 2, 3};
  EXPECT_EQ(std::vector<int>(trace.begin(), trace.begin() + 10), first);

  // Falling behind: a jump of 5 periods runs the task once and counts the missed activations.
  clock.advance_ns(45);  // now 115: fast was due at 70
  runner.run_once();
  EXPECT_EQ(runner.runs(0), 8u);
  EXPECT_EQ(runner.missed(0), 4u);  // 80, 90, 100, 110 skipped
  clock.set_ns(119);
  runner.run_once();
  EXPECT_EQ(runner.runs(0), 8u);  // next due 120
  clock.set_ns(120);
  runner.run_once();
  EXPECT_EQ(runner.runs(0), 9u);
}

TEST(SimTaskRunner, TableFullIsRefused) {
  hal_sim::SteppedClock clock;
  hal_sim::SimTaskRunner runner(clock);
  std::vector<int> trace;
  Counter a{&trace, 1};
  for (std::size_t i = 0; i < hal_sim::SimTaskRunner::kMaxTasks; ++i) {
    ASSERT_TRUE(runner.add_task("t", &record, &a, 1));
  }
  EXPECT_FALSE(runner.add_task("one too many", &record, &a, 1));
  EXPECT_FALSE(hal_sim::SimTaskRunner(clock).add_task("null", nullptr, nullptr, 1));
}

TEST(SimLogSink, FormatsFiltersAndOverwritesOldest) {
  hal_sim::SimLogSink sink(hal::LogLevel::kInfo);
  sink.log(hal::LogLevel::kDebug, "hidden %d", 1);
  sink.log(hal::LogLevel::kWarning, "scan %u dropped (%s)", 42u, "ring full");
  ASSERT_EQ(sink.size(), 1u);
  EXPECT_STREQ(sink.line(0).text, "scan 42 dropped (ring full)");
  EXPECT_EQ(sink.count(hal::LogLevel::kWarning), 1u);
  for (std::size_t i = 0; i < hal_sim::SimLogSink::kCapacity + 2; ++i) sink.log(hal::LogLevel::kInfo, "line %zu", i);
  EXPECT_EQ(sink.size(), hal_sim::SimLogSink::kCapacity);
  EXPECT_EQ(sink.overwritten(), 3u);
  EXPECT_STREQ(sink.line(0).text, "line 2");
  // Long lines are truncated, never overflowed.
  char big[400];
  std::memset(big, 'x', sizeof(big) - 1);
  big[sizeof(big) - 1] = 0;
  sink.log(hal::LogLevel::kError, "%s", big);
  EXPECT_EQ(std::strlen(sink.line(sink.size() - 1).text), hal_sim::SimLogLine::kMaxChars - 1);
}

TEST(SimHal, WiresEveryBackendIntoTheHal) {
  auto sim = std::make_unique<hal_sim::SimHal>();
  hal::Hal& h = sim->hal;
  ASSERT_NE(h.clock, nullptr);
  sim->clock.set_ns(42);
  EXPECT_EQ(h.clock->now_ns(), 42u);
  hal::Odometry o;
  o.timestamp_ns = 5;
  ASSERT_TRUE(sim->odometry.push(o));
  hal::Odometry got;
  ASSERT_TRUE(h.odometry->poll(&got));
  EXPECT_EQ(got.timestamp_ns, 5u);
  hal::PoseEstimate e;
  e.scan_id = 9;
  h.pose_sink->publish(e);
  ASSERT_TRUE(sim->pose_sink.pop(&e));
  EXPECT_EQ(e.scan_id, 9u);
  h.log->log(hal::LogLevel::kInfo, "x=%d", 3);
  EXPECT_STREQ(sim->log.line(0).text, "x=3");
  std::vector<int> trace;
  Counter c{&trace, 7};
  ASSERT_TRUE(h.tasks->add_task("t", &record, &c, 0));
  h.tasks->run_once();
  EXPECT_EQ(trace, std::vector<int>{7});
}

}  // namespace
