// HokuyoLaser against a scripted SCIP 2.0 device in memory: the start-up handshake and the
// geometry taken from PP (UTM-30LX and URG-04LX answers), error codes below DMIN, time stamps
// that wrap and reset, answers that do not fit the request, a device that falls silent (reset)
// and is asked again, and the start-up description of a device that is not a Hokuyo.
#include "hal_serial/hokuyo_laser.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace hal_serial {
namespace {

class ManualClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override { return t; }
  std::uint64_t t = 1'000'000'000;
};

// A Hokuyo in memory: answers every command line the driver writes (QT, VV, PP, II, BM, MD/ME).
class FakeHokuyo final : public hal::SerialPort {
 public:
  long read(std::uint8_t* buf, std::size_t len) override {
    const std::size_t n = std::min(len, in.size());
    if (n > 0) std::memcpy(buf, in.data(), n);  // an empty container's data() may be null
    in.erase(0, n);
    return static_cast<long>(n);
  }
  long write(const std::uint8_t* buf, std::size_t len) override {
    pending.append(reinterpret_cast<const char*>(buf), len);
    std::size_t nl;
    while ((nl = pending.find('\n')) != std::string::npos) {
      const std::string cmd = pending.substr(0, nl);
      pending.erase(0, nl + 1);
      commands.push_back(cmd);
      if (!silent) answer(cmd);
    }
    return static_cast<long>(len);
  }
  void answer(const std::string& cmd) {
    char buf[1024];
    std::size_t n = 0;
    if (cmd == "PP") {
      std::vector<const char*> l;
      for (const std::string& s : pp) l.push_back(s.c_str());
      n = encode_scip_info("PP", l.data(), l.size(), buf, sizeof(buf));
    } else if (cmd == "VV") {
      const char* l[] = {"VEND:Hokuyo Automatic Co.,Ltd.", "PROD:SOKUIKI Sensor TOP-URG UTM-30LX", "FIRM:1.1.0",
                         "PROT:SCIP 2.0", "SERI:H0000000"};
      n = encode_scip_info("VV", l, 5, buf, sizeof(buf));
    } else if (cmd == "II") {
      const char* l[] = {"MODL:UTM-30LX", "LASR:OFF", "STAT:Stable 000 no error."};
      n = encode_scip_info("II", l, 3, buf, sizeof(buf));
    } else if (cmd == "SCIP2.0") {
      n = encode_scip_status("SCIP2.0", "0E", buf, sizeof(buf));
    } else if (cmd == "BM") {
      n = encode_scip_status("BM", bm_status.c_str(), buf, sizeof(buf));
    } else {
      n = encode_scip_status(cmd.c_str(), "00", buf, sizeof(buf));  // QT, MD..., ME...
      if (cmd.rfind("MD", 0) == 0 || cmd.rfind("ME", 0) == 0) scan_echo = cmd;
    }
    in.append(buf, n);
  }
  void send_scan(std::uint32_t ts, const std::vector<std::uint32_t>& r, const std::string& echo = "") {
    std::vector<char> buf(20000);
    const std::string e = echo.empty() ? scan_echo : echo;
    const bool me = e.rfind("ME", 0) == 0;
    const std::size_t n = encode_scip_scan(e.c_str(), ts, r.data(), me ? r.data() : nullptr, r.size(), 3, buf.data(),
                                           buf.size());
    in.append(buf.data(), n);
  }
  std::string in, pending, scan_echo, bm_status = "00";
  std::vector<std::string> commands;
  std::vector<std::string> pp = {"MODL:UTM-30LX", "DMIN:23", "DMAX:60000", "ARES:1440",
                                 "AMIN:0",        "AMAX:1080", "AFRT:540", "SCAN:2400"};
  bool silent = false;
};

bool poll_until_ready(HokuyoLaser* laser, ManualClock* clock, int rounds = 50) {
  hal::LaserScan s;
  for (int i = 0; i < rounds && !laser->ready(); ++i) {
    laser->poll(&s);
    clock->t += 1'000'000;
  }
  return laser->ready();
}

TEST(HokuyoLaser, HandshakeTakesTheGeometryFromPP) {
  FakeHokuyo dev;
  ManualClock clock;
  HokuyoLaser laser;
  laser.init(&dev, &clock, HokuyoOptions{});
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  const std::vector<std::string> want = {"SCIP2.0", "QT", "VV", "PP", "II", "BM", "MD0000108001000"};
  EXPECT_EQ(dev.commands, want);
  EXPECT_STREQ(laser.product(), "SOKUIKI Sensor TOP-URG UTM-30LX");
  std::vector<std::uint32_t> r(1081, 1500);
  r[0] = 10;        // below DMIN: an error code (no echo), not 1 cm
  r[1] = 65000;     // beyond DMAX
  r[540] = 2345;
  dev.send_scan(1000, r);
  hal::LaserScan s;
  ASSERT_TRUE(laser.poll(&s));
  EXPECT_EQ(s.beam_count, 1081u);
  EXPECT_NEAR(s.angle_min, -0.75 * M_PI, 1e-5);  // (0 - 540) steps of 2π/1440
  EXPECT_NEAR(s.angle_increment, 2 * M_PI / 1440, 1e-7);
  EXPECT_NEAR(s.angle_min + 540 * s.angle_increment, 0.0, 1e-5);  // AFRT is straight ahead
  EXPECT_FLOAT_EQ(s.range_max, 60.0f);
  EXPECT_FLOAT_EQ(s.range_min, 0.023f);
  EXPECT_FLOAT_EQ(s.ranges[0], 60.0f);
  EXPECT_FLOAT_EQ(s.ranges[1], 60.0f);
  EXPECT_FLOAT_EQ(s.ranges[540], 2.345f);
  EXPECT_FLOAT_EQ(s.ranges[2], 1.5f);
  EXPECT_EQ(laser.stats().scans, 1u);
}

TEST(HokuyoLaser, Urg04lxGeometryAndIntensityRequest) {
  FakeHokuyo dev;
  dev.pp = {"MODL:URG-04LX", "DMIN:20", "DMAX:5600", "ARES:1024", "AMIN:44", "AMAX:725", "AFRT:384", "SCAN:600"};
  dev.bm_status = "02";  // laser already on: fine
  ManualClock clock;
  HokuyoLaser laser;
  HokuyoOptions o;
  o.intensity = true;
  laser.init(&dev, &clock, o);
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  EXPECT_EQ(dev.commands.back(), "ME0044072501000");
  dev.send_scan(5, std::vector<std::uint32_t>(682, 1000));
  hal::LaserScan s;
  ASSERT_TRUE(laser.poll(&s));
  EXPECT_EQ(s.beam_count, 682u);
  EXPECT_NEAR(s.angle_min, (44.0 - 384.0) * 2 * M_PI / 1024, 1e-5);
  EXPECT_FLOAT_EQ(s.ranges[681], 1.0f);
}

TEST(HokuyoLaser, TimeStampsWrapAndResetAreFollowed) {
  FakeHokuyo dev;
  ManualClock clock;
  HokuyoLaser laser;
  laser.init(&dev, &clock, HokuyoOptions{});
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  const std::vector<std::uint32_t> r(1081, 1000);
  hal::LaserScan s;
  dev.send_scan(0xFFFFE0, r);  // 32 ms before the 24-bit counter wraps
  ASSERT_TRUE(laser.poll(&s));
  const std::uint64_t t0 = s.timestamp_ns;
  EXPECT_LE(t0, clock.t);  // mapped to the host clock, never after receipt
  clock.t += 41'000'000;       // received 41 ms later (4 ms of USB latency more)
  dev.send_scan(0x000005, r);  // taken 37 ms later, after the wrap
  ASSERT_TRUE(laser.poll(&s));
  EXPECT_EQ(laser.stats().timestamp_wraps, 1u);
  EXPECT_EQ(laser.last_sensor_time_ms(), 0x1000005ull);
  // The sensor's interval (+ the 1 µs creep of the offset), not the receipt jitter.
  EXPECT_NEAR(static_cast<double>(s.timestamp_ns - t0), 37e6, 2e3);
  clock.t += 60'000'000'000;
  dev.send_scan(60'005, r);
  ASSERT_TRUE(laser.poll(&s));
  clock.t += 25'000'000;
  dev.send_scan(100, r);  // the sensor restarted its clock
  ASSERT_TRUE(laser.poll(&s));
  EXPECT_EQ(laser.stats().timestamp_resets, 1u);
  EXPECT_LE(s.timestamp_ns, clock.t);
  EXPECT_GT(s.timestamp_ns, clock.t - 1'000'000);
}

TEST(HokuyoLaser, AnswersThatDoNotFitTheRequestAreCounted) {
  FakeHokuyo dev;
  ManualClock clock;
  HokuyoLaser laser;
  laser.init(&dev, &clock, HokuyoOptions{});
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  dev.send_scan(1, std::vector<std::uint32_t>(541, 1000), "MD0000108002000");  // another cluster count
  dev.send_scan(2, std::vector<std::uint32_t>(1000, 1000));                    // 1000 values for 1081 steps
  dev.in += "MD0000108001000\n51b\n\n";  // status 51: hardware trouble (sum of "51" is 'f', not 'b')
  char buf[64];
  const std::size_t n = encode_scip_status("MD0000108001000", "51", buf, sizeof(buf));
  dev.in.append(buf, n);
  dev.send_scan(3, std::vector<std::uint32_t>(1081, 1000));
  hal::LaserScan s;
  bool got = false;
  for (int i = 0; i < 5 && !got; ++i) got = laser.poll(&s);  // at most 8 KiB are read per poll
  ASSERT_TRUE(got);
  EXPECT_EQ(laser.stats().scans, 1u);
  EXPECT_EQ(laser.stats().bad_measurements, 2u);
  EXPECT_EQ(laser.invalid_scans(), 2u);
  EXPECT_EQ(laser.stats().device_errors, 1u);
  EXPECT_EQ(laser.parser_stats().checksum_errors, 1u);
  const SerialLaserCounters c = laser.counters();
  EXPECT_EQ(c.scans, 1u);
  EXPECT_EQ(c.checksum_errors, 1u);
}

TEST(HokuyoLaser, SilentDeviceIsAskedAgain) {
  FakeHokuyo dev;
  ManualClock clock;
  HokuyoLaser laser;
  laser.init(&dev, &clock, HokuyoOptions{});
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  hal::LaserScan s;
  dev.commands.clear();
  clock.t += 1'100'000'000;  // no scan for 1.1 s: the device was reset and forgot MD
  EXPECT_FALSE(laser.poll(&s));
  EXPECT_EQ(laser.stats().device_restarts, 1u);
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  EXPECT_EQ(dev.commands.back(), "MD0000108001000");
  dev.send_scan(9, std::vector<std::uint32_t>(1081, 1000));
  EXPECT_TRUE(laser.poll(&s));
}

TEST(HokuyoLaser, NotAHokuyoIsDescribedWithWhatItSaid) {
  FakeHokuyo dev;
  dev.silent = true;
  ManualClock clock;
  HokuyoLaser laser;
  laser.init(&dev, &clock, HokuyoOptions{});
  ASSERT_TRUE(laser.start());
  dev.in = "RP LIDAR System.\r\nFirmware Ver 1.29\r\n";
  EXPECT_FALSE(poll_until_ready(&laser, &clock, 400));
  EXPECT_GE(laser.stats().retries, 1u);  // QT sent again every answer_timeout_ms
  char d[300];
  laser.describe_handshake(d, sizeof(d));
  EXPECT_NE(std::string(d).find("waiting for the QT answer"), std::string::npos) << d;
  EXPECT_NE(std::string(d).find("Firmware Ver 1.29"), std::string::npos) << d;
}

TEST(HokuyoLaser, BadParametersAreTheFailureNamed) {
  FakeHokuyo dev;
  dev.pp = {"MODL:X", "DMIN:20", "DMAX:10", "ARES:1024", "AMIN:44", "AMAX:725", "AFRT:384"};
  ManualClock clock;
  HokuyoLaser laser;
  laser.init(&dev, &clock, HokuyoOptions{});
  ASSERT_TRUE(laser.start());
  EXPECT_FALSE(poll_until_ready(&laser, &clock, 20));
  char d[300];
  laser.describe_handshake(d, sizeof(d));
  EXPECT_NE(std::string(d).find("geometry impossible"), std::string::npos) << d;
  EXPECT_EQ(laser.state(), HokuyoState::kParameters);
}

}  // namespace
}  // namespace hal_serial
