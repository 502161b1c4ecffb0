#include "sim/devices/candump_log.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>

#include "sim/devices/can_traffic.h"
#include "sim/io/datasets.h"

namespace sim {
namespace {

TEST(CandumpLog, FormatsAndParsesClassicFdAndErrorFrames) {
  hal::CanFrame f;
  f.id = 0x123;
  f.len = 4;
  f.data[0] = 0xDE; f.data[1] = 0xAD; f.data[2] = 0xBE; f.data[3] = 0xEF;
  EXPECT_EQ(format_candump_line(1700000000.123456, "vcan0", f), "(1700000000.123456) vcan0 123#DEADBEEF");
  hal::CanFrame g;
  g.id = 0x518;
  g.fd = true;
  g.brs = true;
  g.len = 12;
  g.data[11] = 0x42;
  const std::string l = format_candump_line(1.5, "vcan0", g);
  EXPECT_EQ(l, "(1.500000) vcan0 518##1000000000000000000000042");
  CanLogLine p;
  std::string e;
  ASSERT_TRUE(parse_candump_line(l, &p, &e)) << e;
  EXPECT_TRUE(p.frame.fd);
  EXPECT_TRUE(p.frame.brs);
  EXPECT_EQ(p.frame.len, 12);
  EXPECT_EQ(p.frame.data[11], 0x42);
  ASSERT_TRUE(parse_candump_line(format_error_frame_line(2, "vcan1", kCanErrBusOff), &p, &e)) << e;
  EXPECT_TRUE(p.error_frame);
  EXPECT_EQ(p.frame.id, kCanErrBusOff);
  ASSERT_TRUE(parse_candump_line("(1.0) can0 1ABCDEF0#01", &p, &e));
  EXPECT_TRUE(p.frame.extended);
  for (const char* bad : {"", "1.0 vcan0 123#00", "(x) vcan0 123#00", "(1.0) vcan0 12#00", "(1.0) vcan0 123#0",
                          "(1.0) vcan0 123#001122334455667788", "(1.0) vcan0 123##", "(1.0) vcan0 123#R"}) {
    EXPECT_FALSE(parse_candump_line(bad, &p, &e)) << bad;
    EXPECT_FALSE(e.empty());
  }
}

TEST(CanTraffic, RoundTripThroughTheDecoderWithFaults) {
  const Dataset* ds = find_dataset("aces");
  ASSERT_NE(ds, nullptr);
  CarmenLog log;
  std::string err;
  CarmenReadOptions ro;
  ro.max_scans = 120;
  if (!read_carmen_log(data_path(ds->raw_log), ro, &log, &err)) GTEST_SKIP() << "aces log unavailable: " << err;
  for (bool fd : {false, true}) {
    CanTrafficOptions o;
    o.fd = fd;
    o.num_scans = 100;
    o.corrupt_every = 10;
    o.drop_every = 13;
    o.duplicate_every = 17;
    o.bus_off_at = 50;
    o.bus_off_burst = 5;
    std::vector<TimedFrame> frames;
    CanTrafficSummary s;
    ASSERT_TRUE(build_can_traffic(log, o, &frames, &s, &err)) << err;
    EXPECT_EQ(s.scans_sent, 100u);
    EXPECT_EQ(s.error_frames, 5u);
    // Through the text format and back, then decode.
    hal_can::Decoder d;
    size_t scans = 0, odom = 0;
    for (const auto& tf : frames) {
      CanLogLine l;
      ASSERT_TRUE(parse_candump_line(tf.error_frame ? format_error_frame_line(tf.t, "vcan0", tf.frame.id)
                                                    : format_candump_line(tf.t, "vcan0", tf.frame),
                                     &l, &err))
          << err;
      if (l.error_frame) continue;
      const auto k = d.feed(l.frame);
      scans += k == hal_can::Decoded::kScan;
      odom += k == hal_can::Decoded::kOdometry;
    }
    EXPECT_EQ(scans, s.scans_intact);
    EXPECT_EQ(d.stats().scans_dropped, s.scans_corrupted + s.scans_missing_segment + s.scans_duplicated);
    EXPECT_EQ(d.stats().crc_errors, s.scans_corrupted);
    EXPECT_EQ(d.stats().duplicate_segments, s.scans_duplicated);
    EXPECT_EQ(odom, s.odometry_sent);
    EXPECT_GT(odom, 50u);
  }
}

// Issue 13 (same class as the map and log readers): a FIFO blocked the reader forever, /dev/zero
// was read as one endless line.
TEST(CandumpLog, FifoAndDeviceAreRefused) {
  std::vector<CanLogLine> lines;
  std::string err;
  EXPECT_FALSE(read_candump_log("/dev/zero", &lines, &err));
  EXPECT_NE(err.find("/dev/zero: not a regular file (a character device)"), std::string::npos) << err;
  const std::string fifo = ::testing::TempDir() + "/candump_fifo_" + std::to_string(::getpid()) + ".log";
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_FALSE(read_candump_log(fifo, &lines, &err));
  EXPECT_NE(err.find("not a regular file (a FIFO)"), std::string::npos) << err;
  std::remove(fifo.c_str());
}

}  // namespace
}  // namespace sim
