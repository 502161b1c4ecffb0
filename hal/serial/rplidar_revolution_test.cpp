// Revolution assembly and resampling onto the regular grid: nearest slot, the nearer sample wins,
// clockwise angles mirrored, empty slots are no return, partial turns dropped and counted.
#include "hal_serial/rplidar_revolution.h"

#include <gtest/gtest.h>

#include <cmath>

namespace hal_serial {
namespace {

RplidarSample at(double deg, double metres, bool start = false) {
  RplidarSample s;
  s.start = start;
  s.quality = 20;
  s.angle_q6 = static_cast<std::uint16_t>(std::lround(deg * 64.0)) % (360 * 64);
  s.distance_q2 = static_cast<std::uint16_t>(std::lround(metres * 4000.0));
  return s;
}

// The beam of the grid that points at counter-clockwise angle a (rad).
std::uint32_t beam_of(const hal::LaserScan& s, double a) {
  return static_cast<std::uint32_t>(std::lround((a - s.angle_min) / s.angle_increment)) % s.beam_count;
}

TEST(RplidarRevolution, IrregularTurnOnTheOneDegreeGrid) {
  RplidarRevolution rev;
  RplidarRevolutionOptions o;
  o.min_samples = 10;
  rev.init(o);
  hal::LaserScan scan;
  // Leading samples of a turn we did not see begin: dropped.
  EXPECT_FALSE(rev.add(at(200, 1.0), 1, &scan));
  // A turn of 364 samples 0.989° apart, from phase 0.3°: ranges encode the clockwise angle.
  const double step = 360.0 / 364.0;
  for (int k = 0; k < 364; ++k) {
    const double deg = 0.3 + k * step;
    EXPECT_FALSE(rev.add(at(deg, 1.0 + deg / 100.0, k == 0), 1000 + k, &scan));
  }
  ASSERT_TRUE(rev.add(at(0.3, 5.0, true), 99999, &scan));  // the next turn's start closes it
  EXPECT_EQ(scan.beam_count, 360u);
  EXPECT_EQ(scan.timestamp_ns, 1000u);  // receipt of its first sample
  EXPECT_NEAR(scan.angle_min, -M_PI, 1e-6);
  EXPECT_NEAR(scan.angle_increment, M_PI / 180, 1e-7);
  // 90° clockwise (the sensor's right) is −90° in the scan: the range there says 90.
  const hal::LaserScan& s = scan;
  EXPECT_NEAR(s.ranges[beam_of(s, -M_PI / 2)], 1.0 + 90.0 / 100, 0.006);
  EXPECT_NEAR(s.ranges[beam_of(s, M_PI / 2)], 1.0 + 270.0 / 100, 0.006);
  EXPECT_NEAR(s.ranges[beam_of(s, 0.0)], 1.003, 0.006);
  // Every slot within half a step of a sample: 364 samples over 360 slots leave none empty.
  int empty = 0;
  for (std::uint32_t j = 0; j < s.beam_count; ++j) empty += s.ranges[j] >= s.range_max ? 1 : 0;
  EXPECT_EQ(empty, 0);
  EXPECT_EQ(rev.stats().revolutions, 1u);
  EXPECT_EQ(rev.stats().leading, 1u);
  EXPECT_EQ(rev.stats().collisions, 4u);  // 364 samples, 360 slots
}

TEST(RplidarRevolution, EmptySlotsAreNoReturnAndTheNearerSampleWins) {
  RplidarRevolution rev;
  RplidarRevolutionOptions o;
  o.min_samples = 2;
  o.range_max_m = 12.0f;
  rev.init(o);
  hal::LaserScan scan;
  rev.add(at(10.4, 2.0, true), 0, &scan);   // 0.4° from slot "−10°"
  rev.add(at(9.9, 3.0), 0, &scan);          // 0.1°: nearer, wins
  rev.add(at(20.0, 0.0), 0, &scan);         // distance 0: no measurement
  rev.add(at(30.0, 15.0), 0, &scan);        // beyond range_max: clamped
  ASSERT_TRUE(rev.add(at(0, 1, true), 0, &scan));
  EXPECT_FLOAT_EQ(scan.ranges[beam_of(scan, -10 * M_PI / 180)], 3.0f);
  EXPECT_FLOAT_EQ(scan.ranges[beam_of(scan, -20 * M_PI / 180)], 12.0f);
  EXPECT_FLOAT_EQ(scan.ranges[beam_of(scan, -30 * M_PI / 180)], 12.0f);
  EXPECT_EQ(rev.stats().invalid, 1u);
  EXPECT_EQ(rev.stats().collisions, 1u);
}

TEST(RplidarRevolution, PartialAndOverlongTurnsAreDropped) {
  RplidarRevolution rev;
  RplidarRevolutionOptions o;
  o.min_samples = 100;
  o.max_samples = 500;
  rev.init(o);
  hal::LaserScan scan;
  rev.add(at(0, 1, true), 0, &scan);
  for (int k = 1; k < 50; ++k) rev.add(at(k, 1), 0, &scan);  // the motor stalls after 50 samples
  EXPECT_FALSE(rev.add(at(0, 1, true), 0, &scan));
  EXPECT_EQ(rev.stats().partial, 1u);
  for (int k = 1; k < 600; ++k) rev.add(at(k % 360, 1), 0, &scan);  // the start flag never comes
  EXPECT_EQ(rev.stats().overlong, 1u);
  EXPECT_FALSE(rev.add(at(0, 1, true), 0, &scan));  // after an overlong turn: a fresh start
  EXPECT_EQ(rev.stats().revolutions, 0u);
}

}  // namespace
}  // namespace hal_serial
