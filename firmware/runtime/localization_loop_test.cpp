#include "firmware/runtime/localization_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "firmware/runtime/odometry_localizer.h"
#include "hal_sim/sim_log_sink.h"
#include "hal_sim/sim_sensor_io.h"
#include "hal_sim/stepped_clock.h"

namespace {

constexpr std::uint64_t kMs = 1000000;

struct Rig {
  hal_sim::SteppedClock clock;
  hal_sim::SimLaserSource laser;
  hal_sim::SimOdometrySource odom;
  hal_sim::SimPoseSink sink;
  hal_sim::SimLogSink log;
  hal::Hal hal;
  fw::OdometryLocalizer localizer;
  fw::LocalizationLoop loop;
  Rig() {
    hal.clock = &clock;
    hal.laser = &laser;
    hal.odometry = &odom;
    hal.pose_sink = &sink;
    hal.log = &log;
  }
  void push_odom(std::uint64_t t, float x, float y, float th) {
    hal::Odometry o;
    o.timestamp_ns = t;
    o.x = x;
    o.y = y;
    o.theta = th;
    odom.push(o);
  }
  void push_scan(std::uint64_t t, std::uint32_t id) {
    hal::LaserScan s;
    s.timestamp_ns = t;
    s.scan_id = id;
    s.beam_count = 181;
    s.angle_increment = 0.0174533f;
    s.range_max = 8.0f;
    laser.push(s);
  }
};

TEST(LocalizationLoop, InitRequiresTheHalParts) {
  fw::LocalizationLoop loop;
  hal::Hal empty;
  fw::OdometryLocalizer loc;
  const fw::Status s = loop.init(empty, loc);
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("clock"), std::string::npos);
  EXPECT_FALSE(loop.spin_once().is_ok());
}

TEST(LocalizationLoop, PairsEachScanWithInterpolatedOdometryAndPublishes) {
  Rig r;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer).is_ok());
  // Odometry at 0, 100, 200 ms driving +x at 1 m/s; scans at 0 and 150 ms.
  r.push_odom(0, 0.0f, 0.0f, 0.0f);
  r.push_odom(100 * kMs, 0.1f, 0.0f, 0.0f);
  r.push_odom(200 * kMs, 0.2f, 0.0f, 0.0f);
  r.push_scan(0, 1);
  r.push_scan(150 * kMs, 2);
  r.clock.set_ns(200 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  ASSERT_TRUE(r.loop.stepped());
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  ASSERT_TRUE(r.loop.stepped());
  EXPECT_NEAR(r.loop.last_odometry().x, 0.15f, 1e-6f);
  EXPECT_EQ(r.loop.last_odometry().timestamp_ns, 150 * kMs);
  hal::PoseEstimate e;
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.scan_id, 1u);
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.scan_id, 2u);
  EXPECT_NEAR(e.x, 0.15f, 1e-6f);
  EXPECT_EQ(e.status, hal::LocalizationStatus::kSearching);
  EXPECT_EQ(r.sink.last_health().scans_processed, 2u);
  EXPECT_EQ(r.loop.counters().scans_interpolated, 2u);
  EXPECT_EQ(r.loop.perf_step().stats().count, 2u);
  EXPECT_EQ(r.loop.perf_total().stats().count, 2u);
  // Nothing pending: a spin is idle.
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_FALSE(r.loop.stepped());
}

TEST(LocalizationLoop, ScanWaitsForOdometryThenHoldsOrDrops) {
  Rig r;
  fw::LocalizationLoopOptions opt;
  opt.odom_wait_ns = 50 * kMs;
  opt.max_odom_gap_ns = 100 * kMs;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer, opt).is_ok());
  r.push_odom(0, 0.0f, 0.0f, 0.0f);
  r.push_scan(80 * kMs, 1);
  r.clock.set_ns(90 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_FALSE(r.loop.stepped());
  EXPECT_TRUE(r.loop.scan_pending());
  // Odometry arrives: the scan is interpolated.
  r.push_odom(100 * kMs, 1.0f, 0.0f, 0.0f);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  ASSERT_TRUE(r.loop.stepped());
  EXPECT_NEAR(r.loop.last_odometry().x, 0.8f, 1e-6f);

  // No further odometry: after the wait the newest sample is held (within the gap) ...
  r.push_scan(150 * kMs, 2);
  r.clock.set_ns(160 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_FALSE(r.loop.stepped());
  r.clock.set_ns(200 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  ASSERT_TRUE(r.loop.stepped());
  EXPECT_NEAR(r.loop.last_odometry().x, 1.0f, 1e-6f);
  EXPECT_EQ(r.loop.counters().scans_held, 1u);
  EXPECT_EQ(r.loop.health().timeouts, 1u);
  // ... and a scan too far beyond it is dropped and counted.
  r.push_scan(400 * kMs, 3);
  r.clock.set_ns(500 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_FALSE(r.loop.stepped());
  EXPECT_EQ(r.loop.health().dropped_scans, 1u);
  EXPECT_EQ(r.loop.counters().scans_unpaired, 1u);
  EXPECT_GE(r.log.count(hal::LogLevel::kWarning), 1u);
}

TEST(LocalizationLoop, RejectsBadOdometryAndMalformedScans) {
  Rig r;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer).is_ok());
  r.push_odom(0, 0.0f, 0.0f, 0.0f);
  r.push_odom(100 * kMs, std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f);
  r.push_odom(50 * kMs, 0.5f, 0.0f, 0.0f);
  r.push_odom(20 * kMs, 0.9f, 0.0f, 0.0f);  // older than 50 ms: rejected
  r.push_odom(100 * kMs, 0.1f, 0.0f, 0.0f);
  hal::LaserScan bad;
  bad.timestamp_ns = 60 * kMs;
  bad.beam_count = hal::LaserScan::kMaxBeams + 1;
  r.laser.push(bad);
  r.push_scan(75 * kMs, 7);
  r.clock.set_ns(100 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  ASSERT_TRUE(r.loop.stepped());
  EXPECT_EQ(r.loop.last_estimate().scan_id, 7u);
  EXPECT_EQ(r.loop.counters().odom_rejected, 2u);
  EXPECT_EQ(r.loop.counters().scans_malformed, 1u);
  EXPECT_EQ(r.loop.health().dropped_scans, 1u);
  // Halfway 50 → 100 ms: 0.5 → 0.1 m (samples a jump apart are not interpolated: see below).
  EXPECT_NEAR(r.loop.last_odometry().x, 0.3f, 1e-5f);
}

// The loop's contract when a localizer fails: the error is returned, counted, logged and an
// estimate with status `fault` is still published (a consumer must learn the pose is invalid).
class RejectOddScans final : public fw::Localizer {
 public:
  const char* name() const override { return "reject-odd"; }
  void reset() override {}
  fw::Status step(const hal::LaserScan& scan, const hal::Odometry&, hal::PoseEstimate* out) override {
    if (scan.scan_id % 2 == 1) return fw::Status::error(fw::Errc::kNumerical, "scan %u is odd", scan.scan_id);
    out->scan_id = scan.scan_id;
    out->status = hal::LocalizationStatus::kLocalized;
    return fw::Status::ok();
  }
};

TEST(LocalizationLoop, LocalizerErrorIsReturnedAndPublishedAsFault) {
  Rig r;
  RejectOddScans loc;
  ASSERT_TRUE(r.loop.init(r.hal, loc).is_ok());
  r.push_odom(0, 0.0f, 0.0f, 0.0f);
  r.push_odom(10 * kMs, 0.0f, 0.0f, 0.0f);
  r.push_scan(0, 2);
  r.push_scan(5 * kMs, 3);
  r.clock.set_ns(10 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  const fw::Status s = r.loop.spin_once();
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("scan 3 is odd"), std::string::npos);
  hal::PoseEstimate e;
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.status, hal::LocalizationStatus::kLocalized);
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.status, hal::LocalizationStatus::kFault);
  EXPECT_EQ(e.scan_id, 3u);
  EXPECT_EQ(r.loop.counters().step_errors, 1u);
  EXPECT_EQ(r.log.count(hal::LogLevel::kError), 1u);
}

TEST(LocalizationLoop, DeadlineMissesAreCountedWithThePerfClock) {
  Rig r;
  hal_sim::SteppedClock perf;  // a stepped perf clock makes the measured step time exact
  struct Slow final : fw::Localizer {
    hal_sim::SteppedClock* perf;
    const char* name() const override { return "slow"; }
    void reset() override {}
    fw::Status step(const hal::LaserScan&, const hal::Odometry&, hal::PoseEstimate*) override {
      perf->advance_ns(20 * kMs);
      return fw::Status::ok();
    }
  } slow;
  slow.perf = &perf;
  fw::LocalizationLoopOptions opt;
  opt.perf_clock = &perf;
  opt.step_deadline_ns = 10 * kMs;
  ASSERT_TRUE(r.loop.init(r.hal, slow, opt).is_ok());
  r.push_odom(0, 0.0f, 0.0f, 0.0f);
  r.push_scan(0, 1);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_EQ(r.loop.last_step_ns(), 20 * kMs);
  EXPECT_EQ(r.loop.health().deadline_misses, 1u);
  EXPECT_NEAR(r.loop.perf_step().stats().max_ms, 20.0, 1e-9);
}

}  // namespace

namespace {

// Issue 13: 4 s of laser silence raised no timeout and no fault.
TEST(LocalizationLoop, LaserSilenceRaisesANamedFaultAndAFaultPoseUntilScansReturn) {
  Rig r;
  fw::LocalizationLoopOptions opt;
  opt.laser_timeout_ns = 500 * kMs;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer, opt).is_ok());
  const std::uint32_t kTimeoutBit = static_cast<std::uint32_t>(hal::HealthFault::kLaserTimeout);
  r.push_odom(0, 0.0f, 0.0f, 0.0f);
  r.push_odom(100 * kMs, 0.1f, 0.0f, 0.0f);
  r.push_scan(50 * kMs, 1);
  r.clock.set_ns(100 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  ASSERT_TRUE(r.loop.stepped());
  hal::PoseEstimate e;
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_NE(e.status, hal::LocalizationStatus::kFault);
  // Quiet for less than the timeout: nothing.
  r.clock.set_ns(550 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_EQ(r.loop.health().fault_bits & kTimeoutBit, 0u);
  EXPECT_FALSE(r.sink.pop(&e));
  // 4 s of silence (the reproducer): fault laser-timeout, counted once, a `fault` pose for the
  // last scan and a health frame carrying the bit.
  const std::uint64_t health_frames = r.sink.health_count();
  for (std::uint64_t t = 650; t <= 4100; t += 50) {
    r.clock.set_ns(t * kMs);
    ASSERT_TRUE(r.loop.spin_once().is_ok());
    EXPECT_FALSE(r.loop.stepped());
  }
  EXPECT_TRUE(r.loop.laser_timed_out());
  EXPECT_EQ(r.loop.health().fault_bits & kTimeoutBit, kTimeoutBit);
  EXPECT_EQ(r.loop.health().timeouts, 1u);
  EXPECT_EQ(r.loop.counters().laser_timeouts, 1u);
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.status, hal::LocalizationStatus::kFault);
  EXPECT_EQ(e.scan_id, 1u);
  EXPECT_FALSE(r.sink.pop(&e));  // once per silence, not per spin
  EXPECT_EQ(r.sink.health_count(), health_frames + 1);
  EXPECT_EQ(r.sink.last_health().fault_bits & kTimeoutBit, kTimeoutBit);
  EXPECT_STREQ(hal::health_fault_name(hal::HealthFault::kLaserTimeout), "laser-timeout");
  EXPECT_GE(r.log.count(hal::LogLevel::kWarning), 1u);
  // Scans return: the fault clears with the next pose.
  r.push_odom(4200 * kMs, 0.2f, 0.0f, 0.0f);
  r.push_scan(4150 * kMs, 2);
  r.clock.set_ns(4200 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  ASSERT_TRUE(r.loop.stepped());
  EXPECT_FALSE(r.loop.laser_timed_out());
  EXPECT_EQ(r.loop.health().fault_bits & kTimeoutBit, 0u);
  EXPECT_EQ(r.sink.last_health().fault_bits & kTimeoutBit, 0u);
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.scan_id, 2u);
  EXPECT_NE(e.status, hal::LocalizationStatus::kFault);
}

TEST(LocalizationLoop, LaserThatNeverStartsTimesOutWithoutAPose) {
  Rig r;
  fw::LocalizationLoopOptions opt;
  opt.laser_timeout_ns = 500 * kMs;
  r.clock.set_ns(1000 * kMs);
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer, opt).is_ok());
  r.clock.set_ns(1400 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_FALSE(r.loop.laser_timed_out());
  r.clock.set_ns(1600 * kMs);
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_TRUE(r.loop.laser_timed_out());
  hal::PoseEstimate e;
  EXPECT_FALSE(r.sink.pop(&e));  // nothing was published yet: nothing to flag
  EXPECT_TRUE(r.sink.has_health());
  EXPECT_NE(r.sink.last_health().fault_bits & static_cast<std::uint32_t>(hal::HealthFault::kLaserTimeout), 0u);
  // Off by default (simulators step their clock with the scans).
  Rig q;
  ASSERT_TRUE(q.loop.init(q.hal, q.localizer).is_ok());
  q.clock.set_ns(60'000 * kMs);
  ASSERT_TRUE(q.loop.spin_once().is_ok());
  EXPECT_FALSE(q.loop.laser_timed_out());
  EXPECT_EQ(q.loop.health().fault_bits, 0u);
}

// A laser source with link faults and rejected scans (SickLaser, CanNode::Laser): both reach Health.
class FaultyLaser final : public hal::LaserScanSource {
 public:
  bool poll(hal::LaserScan*) override { return false; }
  std::uint32_t fault_bits() const override { return bits; }
  std::uint32_t invalid_scans() const override { return invalid; }
  std::uint32_t skipped_scans() const override { return skipped; }
  std::uint32_t bits = 0, invalid = 0, skipped = 0;
};

TEST(LocalizationLoop, SourceFaultsAndInvalidScansReachHealth) {
  Rig r;
  FaultyLaser laser;
  r.hal.laser = &laser;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer).is_ok());
  laser.bits = static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected) | 0x1u;  // internal bits are not the source's
  laser.invalid = 3;
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_EQ(r.loop.health().fault_bits, static_cast<std::uint32_t>(hal::HealthFault::kLaserDisconnected));
  EXPECT_EQ(r.loop.health().invalid_scans, 3u);
  laser.bits = 0;
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_EQ(r.loop.health().fault_bits, 0u);
}

// Issue 13 fault campaign (serial_laser_silence): a SICK stream of 200 scans at 75 Hz reached the
// loop as 185 steps and HEALTH said dropped=0 — the driver keeps only the newest scan between two
// polls and its replaced scans were counted nowhere the robot could see. They are dropped scans.
TEST(LocalizationLoop, ScansTheSourceSkippedAreDroppedInHealth) {
  Rig r;
  FaultyLaser laser;
  r.hal.laser = &laser;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer).is_ok());
  laser.skipped = 15;
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_EQ(r.loop.health().dropped_scans, 15u);
  laser.skipped = 16;
  ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_EQ(r.loop.health().dropped_scans, 16u);
}

// Issue 13 fault campaign (can_out_of_order): two scans swapped on the link made the loop step the
// older one after the newer and the POSE scan ids went backwards. The older one is now dropped and
// counted; a much older scan (the sensor clock jumped back) is followed, not dropped for ever.
TEST(LocalizationLoop, OutOfOrderScanIsDroppedButAClockJumpBackIsFollowed) {
  Rig r;
  fw::LocalizationLoopOptions opt;
  opt.max_odom_gap_ns = 500 * kMs;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer, opt).is_ok());
  for (int i = 0; i <= 10; ++i) r.push_odom(i * 100 * kMs, 0.01f * i, 0.0f, 0.0f);
  r.push_scan(800 * kMs, 3);
  r.push_scan(700 * kMs, 2);  // taken before scan 3, arrives after it
  r.push_scan(900 * kMs, 4);
  r.clock.set_ns(1000 * kMs);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(r.loop.spin_once().is_ok());
  hal::PoseEstimate e;
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.scan_id, 3u);
  ASSERT_TRUE(r.sink.pop(&e));
  EXPECT_EQ(e.scan_id, 4u);
  EXPECT_FALSE(r.sink.pop(&e));
  EXPECT_EQ(r.loop.counters().scans_out_of_order, 1u);
  EXPECT_EQ(r.loop.health().dropped_scans, 1u);
  EXPECT_EQ(r.loop.health().scans_processed, 2u);
  // The sensor clock restarts near zero (900 ms back, beyond the 500 ms odometry gap): followed.
  r.push_odom(5 * kMs, 0.0f, 0.0f, 0.0f);
  r.push_scan(0, 5);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(r.loop.spin_once().is_ok());
  EXPECT_EQ(r.loop.counters().scans_out_of_order, 1u);
  EXPECT_EQ(r.loop.health().dropped_scans + r.loop.health().scans_processed, 4u);
}

// Issue 13 fault campaign (can_odom_jump): a 3 m jump of the wheel odometry between two samples was
// interpolated into two "physical" increments and the tracker stayed `localized` 3 m off. A scan
// between two samples a jump apart takes the nearer sample, so the jump arrives whole.
TEST(LocalizationLoop, NoInterpolationAcrossAnOdometryJump) {
  Rig r;
  ASSERT_TRUE(r.loop.init(r.hal, r.localizer).is_ok());
  r.push_odom(0, 0.0f, 0.0f, 0.0f);
  r.push_odom(100 * kMs, 0.05f, 0.0f, 0.0f);
  r.push_odom(200 * kMs, 3.05f, 0.0f, 0.0f);  // jump
  r.push_odom(300 * kMs, 3.10f, 0.0f, 0.0f);
  r.push_scan(50 * kMs, 1);   // ordinary motion: interpolated
  r.push_scan(130 * kMs, 2);  // nearer the pre-jump sample
  r.push_scan(180 * kMs, 3);  // nearer the post-jump sample
  r.clock.set_ns(400 * kMs);
  const float expect[3] = {0.025f, 0.05f, 3.05f};
  for (float x : expect) {
    ASSERT_TRUE(r.loop.spin_once().is_ok());
    ASSERT_TRUE(r.loop.stepped());
    EXPECT_NEAR(r.loop.last_odometry().x, x, 1e-6f);
  }
  EXPECT_EQ(r.loop.counters().odom_discontinuities, 2u);
}

}  // namespace
