#include "sim/io/log_replay.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace sim {
namespace {

std::string flaser(double t, double x) {
  return "FLASER 3 1 2 3 " + std::to_string(x) + " 0 0 " + std::to_string(x) + " 0 0 " + std::to_string(t) + " h " +
         std::to_string(t) + "\n";
}

TEST(LogReplay, SortsByTimeWithOdometryFirstAndStartsAtZero) {
  const std::string text = "ODOM 0 0 0 0.5 0.1 0 10.0 h 0\n" + flaser(10.5, 1) + "ODOM 1 0 0 0 0 0 10.4 h 0\n" +
                           flaser(10.4, 2) + flaser(11.0, 3);
  CarmenLog log;
  std::string err;
  ASSERT_TRUE(parse_carmen_log("m", text.data(), text.size(), {}, &log, &err)) << err;
  const auto ev = make_replay_events(log);
  ASSERT_EQ(ev.size(), 5u);
  EXPECT_EQ(ev[0].kind, ReplayEvent::Kind::kOdometry);
  EXPECT_EQ(ev[0].t_ns, 0u);
  EXPECT_EQ(ev[1].kind, ReplayEvent::Kind::kOdometry);  // 10.4 odometry before the 10.4 scan
  EXPECT_EQ(ev[1].index, 1u);
  EXPECT_EQ(ev[2].kind, ReplayEvent::Kind::kScan);
  EXPECT_EQ(ev[2].index, 1u);
  EXPECT_EQ(ev[2].t_ns, 400000000u);
  EXPECT_EQ(ev[3].index, 0u);
  EXPECT_EQ(ev[4].t_ns, 1000000000u);
  const hal::LaserScan s = event_scan(log, ev[2]);
  EXPECT_EQ(s.scan_id, 1u);
  EXPECT_EQ(s.timestamp_ns, 400000000u);
  const hal::Odometry o = event_odometry(log, ev[0]);
  EXPECT_FLOAT_EQ(o.v, 0.5f);
  EXPECT_FLOAT_EQ(o.omega, 0.1f);

  ReplayOptions keep;
  keep.order = ReplayOptions::Order::kFileClampTime;
  const auto ev2 = make_replay_events(log, keep);
  ASSERT_EQ(ev2.size(), 5u);
  EXPECT_EQ(ev2[1].kind, ReplayEvent::Kind::kScan);
  EXPECT_EQ(ev2[1].index, 0u);
  EXPECT_EQ(ev2[2].t_ns, ev2[1].t_ns);  // 10.4 after 10.5 is clamped
  for (size_t i = 1; i < ev2.size(); ++i) EXPECT_GE(ev2[i].t_ns, ev2[i - 1].t_ns);
}

TEST(LogReplay, OdometryFromScansWhenNoOdomRecords) {
  const std::string text = flaser(0.0, 1) + flaser(0.44, 2);
  CarmenLog log;
  std::string err;
  ASSERT_TRUE(parse_carmen_log("m", text.data(), text.size(), {}, &log, &err)) << err;
  const auto ev = make_replay_events(log);
  ASSERT_EQ(ev.size(), 4u);
  EXPECT_EQ(ev[0].kind, ReplayEvent::Kind::kOdometry);
  EXPECT_TRUE(ev[0].odom_from_scan);
  EXPECT_EQ(ev[1].kind, ReplayEvent::Kind::kScan);
  EXPECT_FLOAT_EQ(event_odometry(log, ev[2]).x, 2.0f);
  ReplayOptions no_odo;
  no_odo.include_odometry = false;
  EXPECT_EQ(make_replay_events(log, no_odo).size(), 2u);
}

// Issue 13: timestamps at the readers' bounds (±1e10 s) span 2e10 s, which overflowed llround
// (undefined behaviour) when converted to replay nanoseconds; the clock is clamped and monotone.
TEST(LogReplay, ExtremeTimestampsAreClampedNotOverflowed) {
  const std::string text = flaser(-1e10, 1) + flaser(1e10, 2) + flaser(1e10, 3);
  CarmenLog log;
  std::string err;
  ASSERT_TRUE(parse_carmen_log("m", text.data(), text.size(), {}, &log, &err)) << err;
  const auto ev = make_replay_events(log);
  ASSERT_EQ(ev.size(), 6u);
  EXPECT_EQ(ev.front().t_ns, 0u);
  EXPECT_EQ(ev.back().t_ns, 9000000000000000000ull);
  for (size_t i = 1; i < ev.size(); ++i) EXPECT_GE(ev[i].t_ns, ev[i - 1].t_ns);
  EXPECT_EQ(seconds_to_ns(1.5), 1500000000ull);
  EXPECT_EQ(seconds_to_ns(-3.0), 0u);
  EXPECT_EQ(seconds_to_ns(std::nan("")), 0u);
  EXPECT_EQ(seconds_to_ns(1e300), 9000000000000000000ull);
  // Beyond the bounds the reader refuses the log (file:line, field).
  const std::string bad = flaser(1, 1) + flaser(1e11, 2);
  EXPECT_FALSE(parse_carmen_log("m", bad.data(), bad.size(), {}, &log, &err));
  EXPECT_NE(err.find("m:2: "), std::string::npos) << err;
  EXPECT_NE(err.find("ipc_timestamp"), std::string::npos) << err;
}

}  // namespace
}  // namespace sim
