// RplidarLaser against a scripted RPLIDAR in memory: the start-up handshake, revolutions from SCAN
// samples and from legacy express capsules, a device whose health says error (RESET and again),
// the motor stopping (silence → handshake again, the motor switched on again), and the start-up
// description of a device that is not an RPLIDAR.
#include "hal_serial/rplidar_laser.h"

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

class FakeRplidar final : public hal::SerialPort {
 public:
  long read(std::uint8_t* buf, std::size_t len) override {
    const std::size_t n = std::min(len, in.size());
    if (n > 0) std::memcpy(buf, in.data(), n);  // an empty container's data() may be null
    in.erase(in.begin(), in.begin() + static_cast<long>(n));
    return static_cast<long>(n);
  }
  long write(const std::uint8_t* buf, std::size_t len) override {
    out.insert(out.end(), buf, buf + len);
    while (!out.empty()) {
      if (out[0] != 0xA5 || out.size() < 2) {
        out.erase(out.begin());
        continue;
      }
      const std::uint8_t cmd = out[1];
      std::size_t used = 2;
      if (cmd & 0x80) {
        if (out.size() < 3 || out.size() < 4u + out[2]) break;
        used = 4u + out[2];
      }
      out.erase(out.begin(), out.begin() + static_cast<long>(used));
      commands.push_back(cmd);
      if (!silent) answer(cmd);
    }
    return static_cast<long>(len);
  }
  void descriptor(std::uint32_t size, std::uint8_t mode, std::uint8_t type) {
    std::uint8_t d[7];
    encode_rplidar_descriptor(size, mode, type, d);
    in.insert(in.end(), d, d + 7);
  }
  void answer(std::uint8_t cmd) {
    if (cmd == kRplidarCmdGetHealth) {
      descriptor(3, 0, kRplidarAnsHealth);
      in.insert(in.end(), {health, 0x05, 0x00});
      health = kRplidarHealthGood;  // after a RESET it is well again
    } else if (cmd == kRplidarCmdGetInfo) {
      descriptor(20, 0, kRplidarAnsInfo);
      const std::uint8_t info[20] = {0x18, 29, 1, 7};
      in.insert(in.end(), info, info + 20);
    } else if (cmd == kRplidarCmdScan) {
      descriptor(5, 1, kRplidarAnsSample);
    } else if (cmd == kRplidarCmdExpressScan) {
      descriptor(84, 1, kRplidarAnsCapsule);
    } else if (cmd == kRplidarCmdReset) {
      const char banner[] = "RP LIDAR System.\r\nFirmware Ver 1.29 - rtm, HW Ver 7\r\nModel: 24\r\n";
      in.insert(in.end(), banner, banner + sizeof(banner) - 1);
    }
  }
  // One turn of n samples from `phase` degrees; range = 1 m + angle/100.
  void turn(int n, double phase) {
    for (int k = 0; k < n; ++k) {
      RplidarSample s;
      s.start = k == 0;
      s.quality = 40;
      const double deg = std::fmod(phase + k * 360.0 / n, 360.0);
      s.angle_q6 = static_cast<std::uint16_t>(deg * 64);
      s.distance_q2 = static_cast<std::uint16_t>((1.0 + deg / 100.0) * 4000);
      std::uint8_t b[5];
      encode_rplidar_sample(s, b);
      in.insert(in.end(), b, b + 5);
    }
  }
  std::vector<std::uint8_t> in, out, commands;
  std::uint8_t health = kRplidarHealthGood;
  bool silent = false;
};

struct MotorLog {
  int on = 0;
  static bool set(void* c, bool run) {
    if (run) ++static_cast<MotorLog*>(c)->on;
    return false;  // like a pty: no modem lines
  }
};

bool poll_until_ready(RplidarLaser* laser, ManualClock* clock, int rounds = 50) {
  hal::LaserScan s;
  for (int i = 0; i < rounds && !laser->ready(); ++i) {
    laser->poll(&s);
    clock->t += 1'000'000;
  }
  return laser->ready();
}

int poll_scans(RplidarLaser* laser, hal::LaserScan* s, int rounds = 20) {
  int got = 0;
  for (int i = 0; i < rounds; ++i) got += laser->poll(s) ? 1 : 0;
  return got;
}

TEST(RplidarLaser, HandshakeAndRevolutions) {
  FakeRplidar dev;
  ManualClock clock;
  MotorLog motor;
  RplidarLaser laser;
  laser.init(&dev, &clock, RplidarOptions{});
  laser.set_motor_control(&MotorLog::set, &motor);
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  const std::vector<std::uint8_t> want = {kRplidarCmdStop, kRplidarCmdGetHealth, kRplidarCmdGetInfo, kRplidarCmdScan};
  EXPECT_EQ(dev.commands, want);
  EXPECT_EQ(laser.info().model, 0x18);
  EXPECT_EQ(motor.on, 1);
  EXPECT_EQ(laser.stats().motor_control_failed, 1u);  // counted, not fatal
  dev.turn(364, 0.4);
  dev.turn(364, 0.7);
  dev.turn(364, 0.1);
  hal::LaserScan s;
  EXPECT_EQ(poll_scans(&laser, &s) + static_cast<int>(laser.stats().overwritten), 2);
  EXPECT_EQ(s.beam_count, 360u);
  // 90° clockwise = beam at −90°: 1 m + 0.9.
  const std::uint32_t right = static_cast<std::uint32_t>(std::lround((-M_PI / 2 - s.angle_min) / s.angle_increment));
  EXPECT_NEAR(s.ranges[right], 1.9, 0.01);
  EXPECT_EQ(laser.counters().scans, 2u);
}

TEST(RplidarLaser, ExpressCapsulesBecomeRevolutions) {
  FakeRplidar dev;
  ManualClock clock;
  RplidarLaser laser;
  RplidarOptions o;
  o.mode = RplidarScanMode::kExpress;
  laser.init(&dev, &clock, o);
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  EXPECT_EQ(dev.commands.back(), kRplidarCmdExpressScan);
  // 3 turns of 23 capsules (736 samples a turn, 0.49° apart); 4 m everywhere.
  for (int c = 0; c < 3 * 23 + 1; ++c) {
    RplidarCapsule cap;
    cap.start = c == 0;
    cap.start_angle_q6 = static_cast<std::uint16_t>(std::lround(std::fmod(c * 360.0 / 23.0 + 0.2, 360.0) * 64));
    for (int k = 0; k < 32; ++k) cap.distance_mm[k] = 4000;
    std::uint8_t raw[84];
    encode_rplidar_capsule(cap, raw);
    dev.in.insert(dev.in.end(), raw, raw + 84);
  }
  hal::LaserScan s;
  EXPECT_GE(poll_scans(&laser, &s) + static_cast<int>(laser.stats().overwritten), 2);
  EXPECT_EQ(s.beam_count, 360u);
  for (std::uint32_t j = 0; j < s.beam_count; ++j) ASSERT_NEAR(s.ranges[j], 4.0, 1e-3) << j;
  EXPECT_EQ(laser.parser_stats().checksum_errors, 0u);
}

TEST(RplidarLaser, HealthErrorIsResetAndAskedAgain) {
  FakeRplidar dev;
  dev.health = kRplidarHealthError;
  ManualClock clock;
  RplidarLaser laser;
  laser.init(&dev, &clock, RplidarOptions{});
  ASSERT_TRUE(laser.start());
  EXPECT_EQ(laser.state(), RplidarState::kStopping);  // GET_HEALTH after stop_settle_ms
  EXPECT_EQ(dev.commands.size(), 1u);
  EXPECT_FALSE(poll_until_ready(&laser, &clock, 40));
  EXPECT_EQ(laser.state(), RplidarState::kResetting);
  EXPECT_EQ(laser.stats().health_errors, 1u);
  clock.t += 1'000'000'000;  // the device boots (its banner is skipped)
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  EXPECT_NE(std::find(dev.commands.begin(), dev.commands.end(), kRplidarCmdReset), dev.commands.end());
  dev.turn(300, 0);
  dev.turn(300, 0);
  hal::LaserScan s;
  EXPECT_EQ(poll_scans(&laser, &s), 1);
}

TEST(RplidarLaser, MotorStopIsNoticedAndTheHandshakeRepeated) {
  FakeRplidar dev;
  ManualClock clock;
  MotorLog motor;
  RplidarLaser laser;
  laser.init(&dev, &clock, RplidarOptions{});
  laser.set_motor_control(&MotorLog::set, &motor);
  ASSERT_TRUE(laser.start());
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  dev.turn(360, 0);
  dev.turn(100, 0);  // the motor stops part way through a turn: nothing more comes
  hal::LaserScan s;
  EXPECT_EQ(poll_scans(&laser, &s), 1);
  clock.t += 2'100'000'000;
  dev.commands.clear();
  EXPECT_FALSE(laser.poll(&s));
  EXPECT_EQ(laser.stats().device_restarts, 1u);
  EXPECT_EQ(motor.on, 2);  // switched on again
  ASSERT_TRUE(poll_until_ready(&laser, &clock));
  EXPECT_EQ(dev.commands.front(), kRplidarCmdStop);
  dev.turn(360, 0);
  dev.turn(360, 0);
  EXPECT_EQ(poll_scans(&laser, &s), 1);  // the stalled turn is not handed out
}

TEST(RplidarLaser, NotAnRplidarIsDescribedWithItsBytes) {
  FakeRplidar dev;
  dev.silent = true;
  ManualClock clock;
  RplidarLaser laser;
  laser.init(&dev, &clock, RplidarOptions{});
  ASSERT_TRUE(laser.start());
  const char scip[] = "QT\n00P\n\n";
  dev.in.insert(dev.in.end(), scip, scip + sizeof(scip) - 1);
  EXPECT_FALSE(poll_until_ready(&laser, &clock, 600));
  EXPECT_GE(laser.stats().retries, 1u);
  char d[300];
  laser.describe_handshake(d, sizeof(d));
  EXPECT_NE(std::string(d).find("GET_HEALTH"), std::string::npos) << d;
  EXPECT_NE(std::string(d).find("51 54 0A 30 30 50 0A 0A"), std::string::npos) << d;  // "QT\n00P\n\n"
}

}  // namespace
}  // namespace hal_serial
